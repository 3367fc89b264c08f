//! What discovery works on: the baseline M ν̇ + D̄ ν = γ with γ = τ − g(η)
//! (thesis eq. 2.7–2.9), and recorded runs on a uniform grid.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::error::DiscoveryError;
use crate::models::LinearVesselModel;
use crate::models::quadratic_damping::QuadraticDamping;
use crate::planning::Dof;
use crate::validation::ValidationRecord;

/// Restoring forces and moments g(η) of the baseline (thesis eq. 1.6):
/// W−B, z_G·W − z_B·B and the tether pitch moment τ_θ, plus the model's
/// constant loads.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Restoring {
    /// W − B (N): weight minus buoyancy.
    pub w_minus_b: f64,
    /// z_G·W − z_B·B (N·m): metacentric restoring of roll and pitch.
    pub zg_w_minus_zb_b: f64,
    /// τ_θ (N·m): tether pitch moment already known to the baseline.
    pub tether_pitch_moment: f64,
    /// Constant load b per DOF [X, Y, Z, K, M, N] (N, N·m) of the baseline's
    /// M ν̇ + D̄ ν + b = τ − g(η) (zero when the model has none).
    #[serde(default)]
    pub constant: [f64; 6],
}

impl Restoring {
    /// g(η) in all six DOFs for η = [x y z φ θ ψ] (thesis eq. 1.6).
    pub fn g(&self, eta: &[f64; 6]) -> [f64; 6] {
        self.g_at(eta[3].sin_cos(), eta[4].sin_cos())
    }

    /// [`Self::g`] from (sin φ, cos φ) and (sin θ, cos θ).
    pub fn g_at(&self, (sp, cp): (f64, f64), (st, ct): (f64, f64)) -> [f64; 6] {
        let w = self.w_minus_b;
        let z = self.zg_w_minus_zb_b;
        let b = &self.constant;
        [
            w * st + b[0],
            -w * ct * sp + b[1],
            -w * ct * cp + b[2],
            z * ct * sp + b[3],
            z * st + self.tether_pitch_moment + b[4],
            b[5],
        ]
    }
}

/// The baseline linear model M ν̇ + D̄ ν = τ − g(η) over the modeled DOFs.
#[derive(Debug, Clone, PartialEq)]
pub struct Baseline {
    /// Modeled DOFs, in the column order of every matrix and record.
    pub dofs: Vec<Dof>,
    /// Mass and added mass M (n × n, invertible).
    pub m: DMatrix<f64>,
    /// Lumped linear damping and Coriolis D̄ (n × n).
    pub d_bar: DMatrix<f64>,
    /// g(η) of the baseline.
    pub restoring: Restoring,
    /// The vehicle's M of the second-order Coriolis–centripetal force
    /// C(δ)δ the baseline carries (see
    /// [`crate::models::coriolis::second_order_force`]); `None`: linear.
    pub coriolis: Option<DMatrix<f64>>,
    /// Diagonal quadratic damping D_q of D_q|δ|δ the baseline carries, with
    /// the speed its sub-model is linearized at (see
    /// [`crate::models::quadratic_damping`]); `None`: linear damping.
    pub quadratic: Option<QuadraticDamping>,
}

impl Baseline {
    /// The baseline of an identified linear model (e.g. from
    /// `estimation::lambda::identify`) with the restoring g(η) its γ was
    /// formed with.
    pub fn from_model(model: &LinearVesselModel, restoring: Restoring) -> Self {
        Baseline {
            dofs: model.dofs().to_vec(),
            m: model.m().clone(),
            d_bar: model.d_bar().clone(),
            restoring,
            coriolis: None,
            quadratic: None,
        }
    }

    /// The forces the baseline knows beside M ν̇ + D̄ ν at pose `eta` and
    /// velocity `nu` (modelled DOFs): g(η) with its constant loads, plus
    /// C(δ)δ and D_q|δ|δ when the baseline carries them.
    pub fn known_force(&self, eta: &[f64; 6], nu: &[f64]) -> Vec<f64> {
        let mut f = self.g(eta);
        if let Some(r) = self.second_order(nu) {
            f.iter_mut().zip(r).for_each(|(a, b)| *a += b);
        }
        if let Some(d) = &self.quadratic {
            let q = d.force(nu, self.index_of(Dof::Surge));
            f.iter_mut().zip(q).for_each(|(a, b)| *a += b);
        }
        f
    }

    /// C(δ)δ at `nu` when the baseline carries it (and models surge).
    pub fn second_order(&self, nu: &[f64]) -> Option<Vec<f64>> {
        let m = self.coriolis.as_ref()?;
        let surge = self.index_of(Dof::Surge)?;
        Some(crate::models::coriolis::second_order_force(
            &self.dofs, m, nu, surge,
        ))
    }

    /// Number of modeled DOFs.
    pub fn n(&self) -> usize {
        self.dofs.len()
    }

    /// Index of `dof` among the modeled DOFs.
    pub fn index_of(&self, dof: Dof) -> Option<usize> {
        self.dofs.iter().position(|&d| d == dof)
    }

    /// g(η) restricted to the modeled DOFs.
    pub fn g(&self, eta: &[f64; 6]) -> Vec<f64> {
        let g = self.restoring.g(eta);
        self.dofs.iter().map(|d| g[d.index()]).collect()
    }

    /// Checks shapes, finiteness and invertibility of M.
    pub fn validate(&self) -> Result<(), DiscoveryError> {
        let n = self.n();
        if n == 0 {
            return Err(DiscoveryError::invalid(
                "baseline.dofs",
                "at least one DOF is needed",
            ));
        }
        for (i, d) in self.dofs.iter().enumerate() {
            if self.dofs[..i].contains(d) {
                return Err(DiscoveryError::invalid(
                    format!("baseline.dofs[{i}]"),
                    format!("{} is listed twice", d.name()),
                ));
            }
        }
        for (name, mat) in [("baseline.m", &self.m), ("baseline.d_bar", &self.d_bar)] {
            if mat.shape() != (n, n) {
                return Err(DiscoveryError::invalid(
                    name,
                    format!("must be {n} × {n}, got {:?}", mat.shape()),
                ));
            }
            if mat.iter().any(|x| !x.is_finite()) {
                return Err(DiscoveryError::invalid(name, "must be finite"));
            }
        }
        // A non-positive diagonal is allowed: an unphysical M (e.g. a roll
        // inertia < 0 where a righting moment was left out) is exactly what
        // discovery is asked to explain; the rows it touches are refitted.
        if self.m.clone().try_inverse().is_none() {
            return Err(DiscoveryError::invalid("baseline.m", "must be invertible"));
        }
        let r = &self.restoring;
        if ![r.w_minus_b, r.zg_w_minus_zb_b, r.tether_pitch_moment]
            .iter()
            .all(|x| x.is_finite())
        {
            return Err(DiscoveryError::invalid(
                "baseline.restoring",
                "must be finite",
            ));
        }
        Ok(())
    }
}

/// A linear model without restoring (g(η) = 0: a surface vessel, or γ = τ);
/// see [`Baseline::from_model`] for one with g(η).
impl From<&LinearVesselModel> for Baseline {
    fn from(model: &LinearVesselModel) -> Self {
        Baseline::from_model(model, Restoring::default())
    }
}

/// One recorded run on a uniform grid t_k = k·h.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Name used in the report (e.g. `DYN-1.5kn-sway-r1`).
    pub name: String,
    /// Sample time h (s).
    pub h: f64,
    /// Commanded τ, N × n, columns in the baseline's DOF order.
    pub tau: DMatrix<f64>,
    /// Measured body velocities ν, N × n.
    pub nu: DMatrix<f64>,
    /// Measured η = [x y z φ θ ψ], N × 6 (zeros where not measured: a DP
    /// vessel has φ = θ = 0).
    pub eta: DMatrix<f64>,
}

impl Record {
    /// A validation record of n DOFs as a discovery record: `u` holds
    /// [τ | η] (n + 6 columns), `y` holds ν; `None` for another shape.
    pub(crate) fn from_validation(n: usize, rec: &ValidationRecord<'_>) -> Option<Record> {
        if rec.u.ncols() != n + 6 || rec.y.ncols() != n || rec.u.nrows() != rec.y.nrows() {
            return None;
        }
        Some(Record {
            name: String::new(),
            h: rec.h,
            tau: rec.u.columns(0, n).into_owned(),
            nu: rec.y.clone_owned(),
            eta: rec.u.columns(n, 6).into_owned(),
        })
    }

    /// Number of samples N.
    pub fn len(&self) -> usize {
        self.nu.nrows()
    }

    /// True when the run holds no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// η at sample k.
    pub fn eta_at(&self, k: usize) -> [f64; 6] {
        std::array::from_fn(|j| self.eta[(k, j)])
    }

    /// The samples `start..end` as a run of its own.
    pub fn slice(&self, start: usize, end: usize, name: String) -> Record {
        let n = end - start;
        Record {
            name,
            h: self.h,
            tau: self.tau.rows(start, n).into_owned(),
            nu: self.nu.rows(start, n).into_owned(),
            eta: self.eta.rows(start, n).into_owned(),
        }
    }

    /// Checks shapes, sample time and finiteness; `field` prefixes messages.
    pub fn validate(
        &self,
        n_dofs: usize,
        min_len: usize,
        field: &str,
    ) -> Result<(), DiscoveryError> {
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(DiscoveryError::invalid(
                format!("{field}.h"),
                "sample time must be finite and > 0",
            ));
        }
        let n = self.len();
        if n < min_len {
            return Err(DiscoveryError::invalid(
                format!("{field}.nu"),
                format!("needs at least {min_len} samples, got {n}"),
            ));
        }
        for (name, mat, cols) in [
            ("tau", &self.tau, n_dofs),
            ("nu", &self.nu, n_dofs),
            ("eta", &self.eta, 6),
        ] {
            if mat.shape() != (n, cols) {
                return Err(DiscoveryError::invalid(
                    format!("{field}.{name}"),
                    format!("must be {n} × {cols}, got {:?}", mat.shape()),
                ));
            }
            if let Some(i) = mat.iter().position(|x| !x.is_finite()) {
                return Err(DiscoveryError::invalid(
                    format!("{field}.{name}"),
                    format!(
                        "non-finite sample at row {}, column {}",
                        i % n.max(1),
                        i / n.max(1)
                    ),
                ));
            }
        }
        Ok(())
    }
}
