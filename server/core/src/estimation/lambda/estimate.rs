//! The result of a λ-filter identification.

use nalgebra::DMatrix;

use super::structure::CouplingMask;
use super::transform::Inversion;
use crate::planning::dof::Dof;

/// How the standard deviations of A, B, M, D̄ were obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UncertaintyMethod {
    /// First-order propagation (delta method) of the posterior covariance of
    /// A_λ, B_λ through the map to (A, B, M, D̄), with the Jacobian by
    /// central differences of the exact map.
    DeltaMethod,
}

/// An identified model M ν̇ + D̄ ν = γ at one operating point.
#[derive(Debug, Clone, PartialEq)]
pub struct LambdaEstimate {
    /// DOFs of the rows/columns, in order.
    pub dofs: Vec<Dof>,
    /// Filter time constant T (s).
    pub t_lambda: f64,
    /// Sample time h (s) of the runs.
    pub h: f64,
    /// Map used from A_λ, B_λ to A, B.
    pub inversion: Inversion,
    /// Free entries of A and B.
    pub mask: CouplingMask,
    /// A_λ of ν = A_λ[λν] + B_λ[λγ].
    pub a_lambda: DMatrix<f64>,
    /// B_λ.
    pub b_lambda: DMatrix<f64>,
    /// A = −M⁻¹D̄.
    pub a: DMatrix<f64>,
    /// B = M⁻¹.
    pub b: DMatrix<f64>,
    /// Mass matrix M = B⁻¹ (rigid body plus added mass).
    pub m: DMatrix<f64>,
    /// Damping (with Coriolis) D̄ = −M·A.
    pub d_bar: DMatrix<f64>,
    /// Posterior covariance of each output row i of [A_λ B_λ] (2n × 2n,
    /// regressor order [λν_0 … λν_{n−1}, λγ_0 … λγ_{n−1}]; zero for fixed
    /// entries). Rows are independent a posteriori.
    pub param_cov: Vec<DMatrix<f64>>,
    /// Standard deviation of every entry of A.
    pub std_a: DMatrix<f64>,
    /// Standard deviation of every entry of B.
    pub std_b: DMatrix<f64>,
    /// Standard deviation of every entry of M.
    pub std_m: DMatrix<f64>,
    /// Standard deviation of every entry of D̄.
    pub std_d_bar: DMatrix<f64>,
    /// Names of the exogenous functions e (columns of `k`, `force`).
    pub exogenous: Vec<String>,
    /// K_λ (n × q), the regression's exogenous block.
    pub k_lambda: DMatrix<f64>,
    /// Force coefficients F (n × q) of M ν̇ + D̄ ν + F e = γ, F = −M·K.
    pub force: DMatrix<f64>,
    /// Standard deviations of `force`.
    pub std_force: DMatrix<f64>,
    /// How the standard deviations were computed.
    pub uncertainty: UncertaintyMethod,
    /// Residual variance of each row's regression (equation error).
    pub residual_variance: Vec<f64>,
    /// Measurement-noise variance R used per row (given or estimated).
    pub noise_variance: Vec<f64>,
    /// Samples used (all runs).
    pub n_samples: usize,
    /// Runs used.
    pub n_runs: usize,
    /// The symmetric-M constraint's effect (`None`: not applied, or no
    /// coupled pair to constrain).
    pub symmetry: Option<super::symmetric::SymmetryFit>,
}
