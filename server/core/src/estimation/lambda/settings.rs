//! Settings of the λ-filter identification and the rigid-body prior.

use nalgebra::DMatrix;

use super::errors_in_variables::RegressorNoise;
use super::filter::FilterInit;
use super::structure::Structure;
use super::transform::Inversion;
use crate::planning::dof::Dof;

/// T must exceed this many sample times: the state-variable filter has to
/// be resolved by the sampling ("T ≫ h"), and the thesis map eq. 2.14–2.15
/// is only first-order accurate in h/T.
pub const MIN_T_OVER_H: f64 = 5.0;

/// The prior of the parameter Kalman filter: a rigid-body guess M₀, D̄₀
/// (e.g. mass and inertia from the CAD model plus strip-theory added mass,
/// and a rough linear damping), mapped to A_λ0, B_λ0, with independent
/// Gaussian uncertainty on every entry.
///
/// Prior standard deviations, dimensionally consistent across DOFs (with
/// B₀ = M₀⁻¹, whose entries satisfy |B_ij| ≤ √(B_ii·B_jj) when M₀ is SPD):
/// σ(A_λ,ij) = `a_lambda_std`·√(B₀_ii / B₀_jj) and
/// σ(B_λ,ij) = `b_lambda_rel_std`·T·√(B₀_ii·B₀_jj).
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// Rigid-body (plus added) mass guess M₀, n × n, invertible with a
    /// positive-diagonal inverse.
    pub m0: DMatrix<f64>,
    /// Damping guess D̄₀, n × n.
    pub d_bar0: DMatrix<f64>,
    /// Dimensionless prior std of A_λ = I + T·A entries (1 ≈ "within the
    /// order of the identity").
    pub a_lambda_std: f64,
    /// Prior std of B_λ entries relative to T·√(B₀_ii·B₀_jj).
    pub b_lambda_rel_std: f64,
}

impl Prior {
    /// The weak rigid-body prior a vessel profile gives (diagonal):
    /// D̄₀,ii = F_max/v_max, M₀,ii = T·D̄₀,ii per DOF of `dofs`.
    pub fn from_profile(profile: &crate::planning::VesselProfile, dofs: &[Dof]) -> Self {
        let d0: Vec<f64> = dofs
            .iter()
            .map(|&d| profile.limit(d).max_force / profile.limit(d).max_velocity)
            .collect();
        let m0: Vec<f64> = dofs
            .iter()
            .zip(&d0)
            .map(|(&d, di)| profile.limit(d).time_constant_s * di)
            .collect();
        let diag = |v: Vec<f64>| DMatrix::from_diagonal(&nalgebra::DVector::from_vec(v));
        Prior::weak(diag(m0), diag(d0))
    }

    /// A weakly informative prior around (M₀, D̄₀): both stds 1.
    pub fn weak(m0: DMatrix<f64>, d_bar0: DMatrix<f64>) -> Self {
        Prior {
            m0,
            d_bar0,
            a_lambda_std: 1.0,
            b_lambda_rel_std: 1.0,
        }
    }
}

/// Everything [`super::identify`] needs besides the runs.
/// Known functions e(t) of each run (its `exogenous` columns) whose force
/// coefficients F in M ν̇ + D̄ ν + F e = γ are estimated with M and D̄:
/// constant loads (e = 1), restoring shapes (sin θ, cos θ sin φ) and the like.
#[derive(Debug, Clone, PartialEq)]
pub struct Exogenous {
    /// Name of each function (column), for messages and reports.
    pub names: Vec<String>,
    /// `pattern[(i, j)]`: function j can act on DOF i (F_ij is estimated).
    pub pattern: DMatrix<bool>,
    /// Prior standard deviation of F_ij per DOF row i (N or N·m per unit
    /// of e_j): a weak prior, wide against the forces the data carry.
    pub force_std: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct LambdaSettings {
    /// The DOFs of the columns of ν and γ, in order.
    pub dofs: Vec<Dof>,
    /// Filter time constant T (s) of λ(s) = 1/(1+sT); of the order of the
    /// vessel's time constants and ≥ [`MIN_T_OVER_H`]·h.
    pub t_lambda: f64,
    /// Diagonal or coupled (masked) model.
    pub structure: Structure,
    /// Rigid-body prior of the parameter Kalman filter.
    pub prior: Prior,
    /// Measurement-noise variance of ν per DOF; `None` estimates it from the
    /// residuals.
    pub noise_variance: Option<Vec<f64>>,
    /// Random-walk variance per sample of every parameter, as a fraction of
    /// its prior variance (0: constant parameters, the fast exact path).
    pub random_walk: f64,
    /// Map from A_λ, B_λ back to A, B.
    pub inversion: Inversion,
    /// Initial state of the λ filters of each run.
    pub filter_init: FilterInit,
    /// Estimate (and marginalize) each run's initial transient a^k·e₀.
    pub estimate_transient: bool,
    /// Report the autocorrelation-robust (Newey–West sandwich) posterior
    /// covariance instead of the white-noise one (constant parameters only;
    /// see `robust`): the λ regression's equation error is coloured.
    pub robust_covariance: bool,
    /// Exogenous functions estimated with M and D̄ (none by default).
    pub exogenous: Option<Exogenous>,
    /// Re-estimate the rows under M = Mᵀ (generalized least squares over
    /// their joint posterior, see `symmetric`); off by default.
    pub symmetric_inertia: bool,
    /// S (n × n) such that M + S, not the fitted M, is the symmetric one:
    /// a fit to logged commands that miss a faster controller's c·K_ν ν̇
    /// returns M − c K_ν (see `identification::intersample`).
    pub inertia_offset: Option<DMatrix<f64>>,
    /// Covariance of the errors in the regressor signals [ν, γ, e], taken
    /// out of the Gram matrix (bias-compensated least squares, see
    /// `errors_in_variables`; the constant-parameter path only). `None`:
    /// the regressors are taken as exact.
    pub regressor_noise: Option<RegressorNoise>,
    /// With the Coriolis linearization at the grid speed (see
    /// `identification::lambda_coriolis`), also take the second-order
    /// C(δ)δ (δ = ν − (u₀, 0, …)) of the fitted M to the known side, for a
    /// model that carries it: off-grid surge speeds in the data (a DP
    /// vessel drifting in a current) then do not bias D̄. Off by default.
    pub second_order_coriolis: bool,
}

impl LambdaSettings {
    /// Settings with the defaults: noise estimated, constant parameters,
    /// exact inversion, filters started at the first sample, transients
    /// estimated, robust covariance, rows fitted freely (M not constrained).
    pub fn new(dofs: Vec<Dof>, t_lambda: f64, structure: Structure, prior: Prior) -> Self {
        LambdaSettings {
            dofs,
            t_lambda,
            structure,
            prior,
            noise_variance: None,
            random_walk: 0.0,
            inversion: Inversion::Exact,
            filter_init: FilterInit::FirstSample,
            estimate_transient: true,
            robust_covariance: true,
            exogenous: None,
            symmetric_inertia: false,
            inertia_offset: None,
            regressor_noise: None,
            second_order_coriolis: false,
        }
    }
}
