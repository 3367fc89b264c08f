//! The identified model as the service stores and serves it: matrices as
//! row-major nested arrays (what a control engineer pastes into MATLAB or
//! NumPy), every estimate with its standard deviation, and a flat parameter
//! table for display and CSV export.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::planning::dof::Dof;

/// A matrix as rows of numbers.
pub type Matrix = Vec<Vec<f64>>;

/// Row-major nested arrays of a nalgebra matrix.
pub fn to_rows(m: &DMatrix<f64>) -> Matrix {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}

/// The nalgebra matrix of row-major nested arrays (`None` when ragged).
pub fn from_rows(rows: &Matrix) -> Option<DMatrix<f64>> {
    let n = rows.len();
    let m = rows.first().map_or(0, Vec::len);
    if rows.iter().any(|r| r.len() != m) {
        return None;
    }
    Some(DMatrix::from_fn(n, m, |i, j| rows[i][j]))
}

/// What kind of model a document holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// LPV model scheduled on forward speed: one M ν̇ + D̄ ν = γ per grid point.
    Lpv,
    /// DP ship low-frequency model: M, A_h = −D M⁻¹, thrust coefficients K.
    DpShip,
    /// Discrete-time innovation-form state space (subspace identification).
    StateSpace,
}

/// How it was identified.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Continuous-time Kalman-filter identification through λ(s) = 1/(1+sT).
    LambdaKf,
    /// State-augmented EKF in parallel over N runs, staged SI1→SI2→SI3.
    ParallelEkf,
    /// N4SID subspace identification.
    N4sid,
    /// A baseline augmented by missing-physics discovery.
    Discovery,
}

impl Method {
    /// The snake_case name used in the API and the database.
    pub fn name(self) -> &'static str {
        match self {
            Method::LambdaKf => "lambda_kf",
            Method::ParallelEkf => "parallel_ekf",
            Method::N4sid => "n4sid",
            Method::Discovery => "discovery",
        }
    }
}

/// One estimated parameter for tables and CSV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ParameterRow {
    /// Group: `M`, `D̄`, `A`, `B`, `g(η)`, `θ″`, …
    pub group: String,
    /// Symbol in the papers' notation, e.g. `M[surge,pitch]`, `θ″3`, `W−B`.
    pub symbol: String,
    /// LPV grid speed (m/s) the parameter belongs to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// Estimate.
    pub value: f64,
    /// Standard deviation, when the method gives one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// SI unit (or `-` for non-dimensional).
    pub unit: String,
}

/// Estimated restoring forces and tether moment (thesis eq. 2.1–2.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct RestoringDoc {
    /// Named parameters with standard deviations (W−B, z_G·W−z_B·B, tether moment…).
    pub parameters: Vec<ParameterRow>,
    /// Static runs and segments used.
    pub evidence: Vec<String>,
    /// The parameters g(η) is evaluated with (γ = τ − g(η) on new runs).
    pub params: crate::estimation::restoring::RestoringParams,
}

/// One LPV sub-model: M ν̇ + D̄ ν = γ at a forward speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LpvPoint {
    /// Grid forward speed (m/s).
    pub speed_mps: f64,
    /// Inertia M (kg, kg·m, kg·m²).
    pub m: Matrix,
    /// Std of M's entries.
    pub m_std: Matrix,
    /// Damping D̄ (kg/s, …).
    pub d_bar: Matrix,
    /// Std of D̄'s entries.
    pub d_bar_std: Matrix,
    /// A = −M⁻¹D̄ (1/s).
    pub a: Matrix,
    /// Std of A's entries.
    pub a_std: Matrix,
    /// B = M⁻¹.
    pub b: Matrix,
    /// Std of B's entries.
    pub b_std: Matrix,
    /// Constant load b of M ν̇ + D̄ ν + b = γ per DOF (N, N·m): tether,
    /// the heave part of W − B, and the offset of the damping's
    /// linearization about this speed. Absent in models without it (zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<Vec<f64>>,
    /// Std of `load`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_std: Option<Vec<f64>>,
    /// Samples used.
    pub n_samples: usize,
    /// Runs used.
    pub run_ids: Vec<String>,
    /// F (n × 2, N or N·m per unit) of a current fixed in NED on the
    /// heading shapes [cos ψ, sin ψ]: the force D̄ ν_c = −F·[cos ψ, sin ψ]ᵀ
    /// the current puts on this point's damping, F = −D̄_{:,uv}·Q(V) of its
    /// own D̄ (see `LpvDoc::current`; the model itself steps ν_r). Absent
    /// without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current_force: Option<Matrix>,
    /// Physics added at this speed by missing-physics discovery; the point's
    /// `m`, `d_bar` are then the refitted ones and the model is driven by
    /// (τ, η) instead of γ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub augmentation: Option<PointAugmentation>,
}

/// Terms added to an LPV sub-model by discovery (see
/// [`crate::discrepancy::AugmentedModel`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PointAugmentation {
    /// The M a Coriolis term's C(ν) is built from and a current's
    /// M ν̇_c acts through (the refitted M when such a term was fitted).
    pub m_ref: Matrix,
    /// The D̄ through which a current acts (refitted likewise).
    pub d_ref: Matrix,
    /// The added terms with coefficients, covariances and shapes.
    pub terms: Vec<crate::discrepancy::ModelTerm>,
}

/// An LPV model on forward speed (thesis eq. 2.16–2.18).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LpvDoc {
    /// State-variable filter time constant T of λ(s) = 1/(1+sT) (s).
    pub t_lambda_s: f64,
    /// `diagonal` or `coupled`.
    pub structure: String,
    /// Free entries of A (and B) for a coupled structure, by DOF index.
    pub coupling: Vec<Vec<bool>>,
    /// Sub-models by ascending speed.
    pub points: Vec<LpvPoint>,
    /// The controller behind the logs when it ran faster than the log: M
    /// and D̄ of the points are the vehicle's, and predictions on such logs
    /// add the commands the log does not show (see `intersample`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logged_controller: Option<LoggedController>,
    /// The speeds the model extends to beyond its grid (interpolated
    /// scheduling): there D̄ is extrapolated linearly in forward speed from
    /// the two end sub-models, the load quadratically through the three end
    /// ones, and M is the end one's. Absent: it holds its end sub-models
    /// (thesis).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extension: Option<SpeedExtension>,
    /// The sub-models are driven by γ − C(δ)δ: the second-order Coriolis–
    /// centripetal force of one vehicle M (the points' M pooled per entry
    /// by inverse variance; each point's own M if that pool is not positive
    /// definite), with δ = ν except the forward speed u the model is
    /// scheduled on (C(ν) of Fossen 2011, eq. 6.43).
    /// Absent or false: the linear sub-models alone (thesis).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub coriolis_second_order: bool,
    /// Diagonal quadratic damping D_q per DOF (N·s²/m², N·m·s²/rad²), one
    /// for the campaign: every sub-model is driven by γ − D_q|δ|δ, δ = ν
    /// except the surge velocity u: entry 0 is X_|u|u, and the sub-model at
    /// grid speed u₀ (whose D̄ and load hold the tangent of X_|u|u|u|u)
    /// is driven by X_|u|u(|u|u − |u₀|u₀ − 2|u₀|(u − u₀)), the rest of it.
    /// 0 where the data did not determine an entry. Absent: linear damping
    /// only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_damping: Option<Vec<f64>>,
    /// Std of `quadratic_damping`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_damping_std: Option<Vec<f64>>,
    /// A current fixed in NED (horizontal models of surface vessels), one
    /// for the campaign: the damping acts on ν − ν_c(ψ), and predictions
    /// integrate ψ from the model's yaw rate (inputs: the forces, then
    /// `psi` in rad). Absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current: Option<NedCurrentDoc>,
}

/// A current of constant speed and direction in NED.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct NedCurrentDoc {
    /// Speed V_c (m/s).
    pub speed_mps: f64,
    /// Std of `speed_mps` (m/s).
    pub speed_std_mps: f64,
    /// Direction β_c the current flows towards (degrees from north towards
    /// east, in [0, 360)).
    pub direction_deg: f64,
    /// Std of `direction_deg` (degrees).
    pub direction_std_deg: f64,
    /// North and east components [V_N, V_E] (m/s).
    pub ned_mps: [f64; 2],
    /// How it was estimated.
    pub evidence: String,
}

/// Speeds (m/s) an LPV model extends to beyond its grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SpeedExtension {
    /// Lowest forward speed modelled (m/s), ≤ the lowest grid speed.
    pub from_mps: f64,
    /// Highest forward speed modelled (m/s), ≥ the highest grid speed.
    pub to_mps: f64,
}

impl From<crate::models::Extension> for SpeedExtension {
    fn from(e: crate::models::Extension) -> Self {
        SpeedExtension {
            from_mps: e.from_mps,
            to_mps: e.to_mps,
        }
    }
}

impl From<SpeedExtension> for crate::models::Extension {
    fn from(e: SpeedExtension) -> Self {
        crate::models::Extension {
            from_mps: e.from_mps,
            to_mps: e.to_mps,
        }
    }
}

impl SpeedExtension {
    /// How to evaluate the model beyond a grid of `lowest`…`highest` m/s,
    /// in words for an export's notes.
    pub fn describe(&self, lowest: f64, highest: f64) -> String {
        let mut sides = Vec::new();
        if self.from_mps < lowest {
            sides.push(format!(
                "below {lowest:.2} m/s down to {:.2} m/s from the three lowest grid points",
                self.from_mps
            ));
        }
        if self.to_mps > highest {
            sides.push(format!(
                "above {highest:.2} m/s up to {:.2} m/s from the three highest",
                self.to_mps
            ));
        }
        format!(
            "Beyond the grid the model extrapolates {}: D̄ linearly in forward speed from the two end points, the load b quadratically (Lagrange) through three, M that of the end point; past that speed it holds the extrapolated point, elsewhere the end grid point.",
            sides.join(" and ")
        )
    }
}

/// A feedback controller r times faster than its log, as read from the log:
/// between log samples it adds c·(K_ν ν̇ + K_η η̇) on average,
/// c = h (r − 1)/(2r).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LoggedController {
    /// Controller rate (Hz).
    pub rate_hz: f64,
    /// Log sample time h (s).
    pub log_h_s: f64,
    /// c = h (r − 1)/(2r) (s).
    pub c_s: f64,
    /// K_ν = ∂τ/∂ν (n × n, rows: forces in DOF order); rows the law did not
    /// explain are zero.
    pub k_nu: Matrix,
    /// K_η on (φ, θ) (n × 2), likewise.
    pub k_attitude: Matrix,
}

/// A DP ship's low-frequency model in momentum form (Fossen et al. 1995,
/// eq. 35–52): ḣ = −C_h(h)h + A_h·h + T·K·u + b_h, h = M·ν, η̇ = J(ψ)ν.
///
/// M, T, A_h, K, D, A and B are in the paper's non-dimensional Bis system of
/// the ship's length L: lengths in L, time in √(L/g), mass in the
/// displacement mass m, forces in m·g, moments in m·g·L; the thruster
/// commands u are normalized (|u| ≤ 1). `a_si`, `b_si` are the same
/// state-space model for ν in m/s, m/s, rad/s and time in s (they need no
/// mass). The SI D is m·√(g/L)·D″ (surge, sway), with L and L² on the yaw
/// row/column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DpShipDoc {
    /// Units of M, T, A_h, K, D, A, B: `Bis`.
    pub units: String,
    /// Ship length L (m), the Bis length unit.
    pub length_m: f64,
    /// Bis time unit √(L/g) (s).
    pub time_unit_s: f64,
    /// Inertia M″ (known a priori, eq. 30).
    pub m: Matrix,
    /// Thruster configuration T″ (3 × r, one column per input channel, eq.
    /// 29; diag(1, 1, 1/L)/F_ref for a vessel that logs forces τ).
    pub t_config: Matrix,
    /// A″_h = −D″ M″⁻¹ (eq. 39, 48).
    pub a_h: Matrix,
    /// Std of A″_h's entries (0 where structurally zero).
    pub a_h_std: Matrix,
    /// Thrust coefficients K″ (diagonal, eq. 49), one per column of T″;
    /// columns of one coefficient group carry the same value.
    pub k: Vec<f64>,
    /// Std of K″.
    pub k_std: Vec<f64>,
    /// θ″1 … θ″9 (eq. 46–47): A″_h, then K″ of coefficient groups 1–4
    /// (0 for a group the layout does not have).
    pub theta: Vec<f64>,
    /// Their standard deviations.
    pub theta_std: Vec<f64>,
    /// D″ = −A″_h M″.
    pub d: Matrix,
    /// A″ = M″⁻¹A″_h M″ (eq. 51, C_h = 0).
    pub a: Matrix,
    /// B″ = M″⁻¹ T″ K″ (eq. 52).
    pub b: Matrix,
    /// A in SI: ν̇ = A·ν + B·u, ν in m/s, m/s, rad/s (1/s).
    pub a_si: Matrix,
    /// B in SI (m/s², m/s², rad/s² per unit command).
    pub b_si: Matrix,
    /// The state estimator's noise model (Bis, per sample), used to
    /// estimate momentum and bias when the model predicts k steps ahead.
    pub noise: DpNoiseDoc,
    /// The prediction-error refinement after the staged EKF, when it was
    /// attempted (absent with `refine: false` and in models stored before
    /// it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refinement: Option<DpRefinementDoc>,
}

/// What the prediction-error refinement after the staged EKF did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DpRefinementDoc {
    /// The refined θ″ and std replaced the EKF's (`theta`, `theta_std`
    /// of the document are the refined ones).
    pub applied: bool,
    /// Why not, when not applied.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The staged EKF's θ″1 … θ″9, the refinement's start.
    pub ekf_theta: Vec<f64>,
    /// Their std as the EKF reported them.
    pub ekf_theta_std: Vec<f64>,
    /// Accepted Levenberg–Marquardt steps (0 when it did not run).
    pub iterations: u32,
    /// χ²/(N − p) of the innovations at the refined θ″ (≈ 1 when the
    /// stated noise is right), when it ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variance_ratio: Option<f64>,
    /// Per θ″, the factor on the Cramér–Rao std (≥ 1) the residuals asked
    /// for (empty when it did not run).
    #[serde(default)]
    pub std_inflation: Vec<f64>,
    /// Change of the held-out runs' negative log-likelihood from the EKF's
    /// θ″ to the refined ones (negative: predicted better), when computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held_out_nll_change: Option<f64>,
}

/// Noise model of the momentum/bias estimator (Bis units, per sample).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct DpNoiseDoc {
    /// Measurement variances of x, y, ψ.
    pub r: Vec<f64>,
    /// Initial momentum variance.
    pub p0_h: Vec<f64>,
    /// Initial bias variance.
    pub p0_b: Vec<f64>,
    /// Process noise on h.
    pub q_h: Vec<f64>,
    /// Bias random walk.
    pub q_b: Vec<f64>,
}

/// A discrete-time innovation-form model x⁺ = Φx + Γu + Ke, y = Cx + Du + e.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct StateSpaceDoc {
    /// Sample time h (s).
    pub h: f64,
    /// Order n.
    pub order: usize,
    /// Φ.
    pub phi: Matrix,
    /// Γ.
    pub gamma: Matrix,
    /// C.
    pub c: Matrix,
    /// D.
    pub d: Matrix,
    /// Kalman gain K.
    pub k: Matrix,
    /// Singular values that chose the order.
    pub singular_values: Vec<f64>,
    /// Continuous-time A (when Φ has a real logarithm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a_continuous: Option<Matrix>,
    /// Continuous-time B.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b_continuous: Option<Matrix>,
    /// Operating point of the inputs: the model maps u − u₀.
    #[serde(default)]
    pub u_offset: Vec<f64>,
    /// Operating point of the outputs: the model predicts y − y₀.
    #[serde(default)]
    pub y_offset: Vec<f64>,
}

/// The identified model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ModelDocument {
    /// Kind of model.
    pub kind: ModelKind,
    /// Method.
    pub method: Method,
    /// Modelled DOFs.
    pub dofs: Vec<Dof>,
    /// Input channels, in column order (γ = τ − g(η) per DOF, or thr_i).
    pub inputs: Vec<String>,
    /// Output channels (ν per DOF, or x, y, ψ).
    pub outputs: Vec<String>,
    /// Restoring forces, when estimated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restoring: Option<RestoringDoc>,
    /// LPV model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lpv: Option<LpvDoc>,
    /// DP ship model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dp_ship: Option<DpShipDoc>,
    /// Subspace model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state_space: Option<StateSpaceDoc>,
    /// Every estimated parameter with its standard deviation.
    pub parameters: Vec<ParameterRow>,
    /// Physical-structure findings (M not SPD, D̄ not dissipative…), reported
    /// rather than silently corrected.
    pub structure_findings: Vec<String>,
    /// Other notes for the engineer.
    pub notes: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_and_ragged_is_refused() {
        let m = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let rows = to_rows(&m);
        assert_eq!(rows, vec![vec![1.0, 2.0, 3.0], vec![4.0, 5.0, 6.0]]);
        assert_eq!(from_rows(&rows).unwrap(), m);
        assert!(from_rows(&vec![vec![1.0], vec![1.0, 2.0]]).is_none());
    }
}
