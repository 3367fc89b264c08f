//! What a simulated sea trial leaves behind: the logged signals at the
//! record rate, plus the noise-free truth the estimators are scored against.

use nalgebra::DMatrix;

use crate::logs::schema::{TIME_COLUMN, pose_column};
use crate::planning::dof::Dof;

/// One simulated run, one row per record sample t_k = k h.
#[derive(Debug, Clone, PartialEq)]
pub struct RovRecord {
    /// Time t_k (s).
    pub t: Vec<f64>,
    /// τ as commanded and logged (N × 6, τ_X … τ_N).
    pub tau_commanded: DMatrix<f64>,
    /// τ acting on the hull at t_k after delay, dead zone, saturation and
    /// lag (N × 6).
    pub tau_applied: DMatrix<f64>,
    /// Measured ν over ground (N × 6, u v w p q r), with noise.
    pub nu: DMatrix<f64>,
    /// Measured η (N × 6, x y z φ θ ψ), with noise.
    pub eta: DMatrix<f64>,
    /// Noise-free ν.
    pub nu_true: DMatrix<f64>,
    /// Noise-free η.
    pub eta_true: DMatrix<f64>,
    /// Ocean current V_c in NED (N × 3, m/s).
    pub current_ned: DMatrix<f64>,
}

impl RovRecord {
    pub(crate) fn zeros(n: usize, h: f64) -> Self {
        RovRecord {
            t: (0..n).map(|k| k as f64 * h).collect(),
            tau_commanded: DMatrix::zeros(n, 6),
            tau_applied: DMatrix::zeros(n, 6),
            nu: DMatrix::zeros(n, 6),
            eta: DMatrix::zeros(n, 6),
            nu_true: DMatrix::zeros(n, 6),
            eta_true: DMatrix::zeros(n, 6),
            current_ned: DMatrix::zeros(n, 3),
        }
    }

    /// Number of samples N.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// No samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The log as the service ingests it: header
    /// `t,tau_X,…,tau_N,u,v,w,p,q,r,x,y,z,phi,theta,psi` (crate::logs::schema),
    /// commanded τ and measured ν, η; numbers in Rust's shortest round-trip
    /// form, so parsing gives back the same f64.
    pub fn to_csv(&self) -> String {
        let mut header: Vec<&str> = vec![TIME_COLUMN];
        header.extend(Dof::ALL.iter().map(|d| d.force_column()));
        header.extend(Dof::ALL.iter().map(|d| d.velocity_symbol()));
        header.extend(Dof::ALL.iter().map(|d| pose_column(*d)));
        let mut out = header.join(",");
        out.push('\n');
        for k in 0..self.len() {
            let mut row = vec![self.t[k].to_string()];
            for m in [&self.tau_commanded, &self.nu, &self.eta] {
                row.extend((0..6).map(|i| m[(k, i)].to_string()));
            }
            out.push_str(&row.join(","));
            out.push('\n');
        }
        out
    }
}
