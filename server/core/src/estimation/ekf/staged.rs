//! Staged, decoupled identification of a DP ship (Fossen et al. 1995,
//! sec. 4.2–4.4, Fig. 4): SI1 (surge: θ″1 = A_h11, θ″6 = K1 = K2) → SI2 (sway
//! and yaw with the tunnel thrusters: θ″2 … θ″5, θ″7 = K3 = K4, θ″8 = K5) →
//! SI3 (azimuth: θ″9 = K6). Each stage is a parallel augmented EKF over its
//! runs (N ≥ 1, the paper uses N = 2) on the momentum model with bias
//! ([`super::dp_model`]); the parameters of earlier stages are frozen at
//! their estimates, those of later stages at the initial guess.
//!
//! M and T are known (eq. 29–30); A_h and K are estimated, and the result is
//! also given in state-space form A = M⁻¹·A_h·M, B = M⁻¹·T·K (eq. 51–52).

use nalgebra::{DMatrix, Matrix3};

use super::dp_model::{DP_STATES, DpMomentumModel};
use super::error::{EkfError, check_finite, check_variances};
use super::filter::{EkfSettings, RunData, parallel_ekf};
use super::model::Rk4;
use crate::estimation::{Progress, SubProgress};
use crate::simulation::dp_ship::model::{DpShip, N_GROUPS, N_THETA, ThrustLayout};

/// Free θ″ indices (0-based) of SI1: A_h11 and K1 = K2.
pub const SI1_FREE: [usize; 2] = [0, 5];
/// Free θ″ indices of SI2: A_h22, A_h23, A_h32, A_h33, K3 = K4, K5.
pub const SI2_FREE: [usize; 6] = [1, 2, 3, 4, 6, 7];
/// Free θ″ index of SI3: K6.
pub const SI3_FREE: [usize; 1] = [8];

/// One identification stage: its runs (u N × 6, z = measured η N × 3) and the
/// θ″ it estimates.
#[derive(Debug, Clone)]
pub struct DpStage<'a> {
    /// Name for progress and results (e.g. "SI1").
    pub name: String,
    /// Indices 0–8 of the θ″ estimated in this stage.
    pub free: Vec<usize>,
    /// The runs processed in parallel.
    pub runs: Vec<RunData<'a>>,
}

/// Known quantities, initial guess and noise model of the identification
/// (units of the model: Bis for the supply vessel). Variances are per sample.
#[derive(Debug, Clone, PartialEq)]
pub struct DpIdentConfig {
    /// Inertia M including added mass (known, eq. 30).
    pub m: Matrix3<f64>,
    /// Thruster configuration T and its coefficient groups (known, eq. 29, 47).
    pub thrust: ThrustLayout,
    /// Sample time h.
    pub h: f64,
    /// Initial guess of θ″1 … θ″9.
    pub theta_init: [f64; N_THETA],
    /// Standard deviation of that guess (P(0) of θ), > 0.
    pub theta_init_std: [f64; N_THETA],
    /// Measurement noise variances of x, y, ψ (R), > 0.
    pub r: [f64; 3],
    /// Initial momentum variance (runs start near rest), > 0.
    pub p0_h: [f64; 3],
    /// Initial bias variance, > 0.
    pub p0_b: [f64; 3],
    /// Process noise on h per sample (w_h), ≥ 0.
    pub q_h: [f64; 3],
    /// Bias random walk per sample (w_b, eq. 37), ≥ 0.
    pub q_b: [f64; 3],
    /// Parameter random walk per sample (w_θ, eq. 38), ≥ 0; 0 for constant θ.
    pub q_theta: f64,
    /// Sweeps through all stages, ≥ 1. In the first sweep SI1's sway/yaw
    /// parameters are frozen at the initial guess; a wrong guess
    /// mis-predicts the bias-driven sway/yaw drift of the surge runs and
    /// biases A_h11 by a few percent. Each further sweep starts every stage
    /// from the previous sweep's θ̂ (frozen values and initial guess; P(0) of
    /// θ as configured), which removes that bias. 2 is enough in practice.
    pub sweeps: usize,
}

impl DpIdentConfig {
    /// The settings a user would pick for Fossen's supply vessel flown as
    /// `trial`: the paper's M and T (eq. 29–30), a generic initial guess
    /// (not the truth) and the trial's noise model.
    pub fn supply_vessel(trial: &crate::simulation::dp_ship::TrialConfig) -> Self {
        let ship = DpShip::supply_vessel();
        let sq = |a: [f64; 3]| a.map(|v| v * v);
        DpIdentConfig {
            m: ship.m,
            thrust: ship.thrust,
            h: trial.h,
            // Damping time constants of ~ 10 Bis units, no coupling, and a
            // thrust coefficient of a few 10⁻³ for every thruster.
            theta_init: [-0.1, -0.1, 0.0, 0.0, -0.1, 5e-3, 5e-3, 5e-3, 5e-3],
            theta_init_std: [0.1, 0.1, 0.1, 0.1, 0.3, 5e-3, 5e-3, 5e-3, 5e-3],
            r: sq([
                trial.position_noise_std,
                trial.position_noise_std,
                trial.heading_noise_std,
            ]),
            p0_h: [1e-8; 3],
            p0_b: sq([1e-3, 1e-3, 2e-4]),
            // A little noise on h keeps the EKF from growing overconfident
            // (with ~0 it locks on biased θ″ for noisy positions).
            q_h: [1e-10; 3],
            q_b: sq(trial.bias_walk_std),
            q_theta: 0.0,
            sweeps: 2,
        }
    }
}

impl DpIdentConfig {
    /// Diagonals of P(0) and Q of one run's states [h; η; b_h]: P(0) of η is
    /// R (the first measured pose), η has no process noise.
    pub fn state_noise(&self) -> (Vec<f64>, Vec<f64>) {
        let p0 = [self.p0_h, self.r, self.p0_b].concat();
        let q = [self.q_h, [0.0; 3], self.q_b].concat();
        (p0, q)
    }
}

/// Each run's x(0): at rest (h = 0) at its first measured pose, bias 0.
pub fn initial_states(runs: &[RunData<'_>]) -> Result<Vec<Vec<f64>>, EkfError> {
    runs.iter()
        .enumerate()
        .map(|(i, run)| {
            if run.z.ncols() != 3 || run.z.nrows() == 0 {
                return Err(EkfError::Shape {
                    field: format!("runs[{i}].z"),
                    expected: "N × 3 (x, y, ψ), N ≥ 1".into(),
                    got: format!("{} × {}", run.z.nrows(), run.z.ncols()),
                });
            }
            let mut x = vec![0.0; DP_STATES];
            for j in 0..3 {
                x[3 + j] = run.z[(0, j)];
            }
            Ok(x)
        })
        .collect()
}

/// The result of one stage.
#[derive(Debug, Clone, PartialEq)]
pub struct DpStageResult {
    /// Stage name.
    pub name: String,
    /// θ″ indices estimated.
    pub free: Vec<usize>,
    /// Estimates of those θ″.
    pub theta: Vec<f64>,
    /// Their covariance.
    pub theta_cov: DMatrix<f64>,
    /// θ̂ after each sample (K × free).
    pub theta_trace: DMatrix<f64>,
    /// Estimated bias b̂_h per run (N_i × 3).
    pub bias: Vec<DMatrix<f64>>,
    /// Estimated momentum ĥ per run (N_i × 3).
    pub momentum: Vec<DMatrix<f64>>,
    /// Innovations z − H·x̂⁻ per run (N_i × 3: x, y, ψ).
    pub innovations: Vec<DMatrix<f64>>,
}

/// The identified DP ship.
#[derive(Debug, Clone, PartialEq)]
pub struct DpIdentification {
    /// θ″1 … θ″9 after all stages.
    pub theta: [f64; N_THETA],
    /// Their standard deviations from the stage that estimated them (0 for
    /// parameters no stage estimated).
    pub theta_std: [f64; N_THETA],
    /// The ship with the identified A_h and K.
    pub ship: DpShip,
    /// A = M⁻¹·A_h·M (eq. 51).
    pub a: Matrix3<f64>,
    /// B = M⁻¹·T·K (eq. 52), 3 × r.
    pub b: DMatrix<f64>,
    /// Per-stage details.
    pub stages: Vec<DpStageResult>,
}

fn validate(cfg: &DpIdentConfig, stages: &[DpStage<'_>]) -> Result<(), EkfError> {
    check_finite("m", cfg.m.iter())?;
    check_finite("t", cfg.thrust.t.iter())?;
    let thrust = &cfg.thrust;
    if thrust.t.nrows() != 3
        || thrust.t.ncols() == 0
        || thrust.groups.len() != thrust.t.ncols()
        || thrust.groups.iter().any(|&g| g >= N_GROUPS)
    {
        return Err(EkfError::Invalid {
            field: "t".into(),
            reason: format!(
                "T must be 3 × r (r ≥ 1) with a group 0–{} per column; got {} × {} with {} group(s)",
                N_GROUPS - 1,
                thrust.t.nrows(),
                thrust.t.ncols(),
                thrust.groups.len()
            ),
        });
    }
    check_finite("theta_init", &cfg.theta_init)?;
    if !(cfg.h.is_finite() && cfg.h > 0.0) {
        return Err(EkfError::Invalid {
            field: "h".into(),
            reason: format!("sample time must be > 0, got {}", cfg.h),
        });
    }
    if (cfg.m - cfg.m.transpose()).abs().max() > 1e-12 * cfg.m.abs().max()
        || cfg.m.cholesky().is_none()
    {
        return Err(EkfError::Invalid {
            field: "m".into(),
            reason: "inertia must be symmetric positive definite".into(),
        });
    }
    check_variances("theta_init_std", &cfg.theta_init_std, true)?;
    check_variances("r", &cfg.r, true)?;
    check_variances("p0_h", &cfg.p0_h, true)?;
    check_variances("p0_b", &cfg.p0_b, true)?;
    check_variances("q_h", &cfg.q_h, false)?;
    check_variances("q_b", &cfg.q_b, false)?;
    check_variances("q_theta", &[cfg.q_theta], false)?;
    if cfg.sweeps == 0 {
        return Err(EkfError::Invalid {
            field: "sweeps".into(),
            reason: "at least one sweep through the stages is needed".into(),
        });
    }
    if stages.is_empty() {
        return Err(EkfError::Invalid {
            field: "stages".into(),
            reason: "at least one stage is needed".into(),
        });
    }
    for (s, stage) in stages.iter().enumerate() {
        let field = format!("stages[{s}].free");
        if stage.free.is_empty() {
            return Err(EkfError::Invalid {
                field,
                reason: "a stage must estimate at least one θ″".into(),
            });
        }
        for (c, &f) in stage.free.iter().enumerate() {
            if f >= N_THETA || stage.free[..c].contains(&f) {
                return Err(EkfError::Invalid {
                    field,
                    reason: format!("θ″ index {f} is out of 0–8 or repeated"),
                });
            }
            if f >= 5 && !thrust.uses(f - 5) {
                return Err(EkfError::Invalid {
                    field,
                    reason: format!(
                        "θ″{} is the coefficient of a thruster group with no column",
                        f + 1
                    ),
                });
            }
        }
        if stage.runs.is_empty() {
            return Err(EkfError::NoRuns);
        }
    }
    Ok(())
}

/// Runs the stages in order (SI1 → SI2 → SI3), each a parallel EKF over its
/// runs, freezing every stage's estimates for the next ones; repeated for
/// `cfg.sweeps` sweeps. The stage results are those of the last sweep.
pub fn identify_dp_ship(
    cfg: &DpIdentConfig,
    stages: &[DpStage<'_>],
    progress: &mut dyn Progress,
) -> Result<DpIdentification, EkfError> {
    validate(cfg, stages)?;
    let mut theta = cfg.theta_init;
    let mut theta_std = [0.0; N_THETA];
    let mut results = Vec::with_capacity(stages.len());
    let width = 1.0 / (stages.len() * cfg.sweeps) as f64;
    for sweep in 0..cfg.sweeps {
        results.clear();
        for (s, stage) in stages.iter().enumerate() {
            let start = (sweep * stages.len() + s) as f64 * width;
            let stage_result = run_stage(
                cfg,
                s,
                stage,
                &mut theta,
                &mut theta_std,
                start,
                width,
                progress,
            )?;
            results.push(stage_result);
        }
    }
    let ship = DpShip::from_theta(cfg.m, cfg.thrust.clone(), &theta);
    Ok(DpIdentification {
        theta,
        theta_std,
        a: ship.state_space_a(),
        b: ship.state_space_b(),
        ship,
        stages: results,
    })
}

/// One stage: the parallel EKF over its runs with the other θ″ frozen at
/// `theta`, whose free entries it then updates.
#[allow(clippy::too_many_arguments)]
fn run_stage(
    cfg: &DpIdentConfig,
    s: usize,
    stage: &DpStage<'_>,
    theta: &mut [f64; N_THETA],
    theta_std: &mut [f64; N_THETA],
    start: f64,
    width: f64,
    progress: &mut dyn Progress,
) -> Result<DpStageResult, EkfError> {
    {
        let model = Rk4 {
            model: DpMomentumModel::new(cfg.m, cfg.thrust.clone(), *theta, stage.free.clone()),
            h: cfg.h,
        };
        let x0 = initial_states(&stage.runs).map_err(|e| prefix_runs(e, s))?;
        let (p0_x, q_x) = cfg.state_noise();
        let settings = EkfSettings {
            x0,
            theta0: stage.free.iter().map(|&f| theta[f]).collect(),
            p0_x,
            p0_theta: stage
                .free
                .iter()
                .map(|&f| cfg.theta_init_std[f].powi(2))
                .collect(),
            q_x,
            q_theta: vec![cfg.q_theta; stage.free.len()],
            r: cfg.r.to_vec(),
        };
        let mut sub = SubProgress::new(progress, start, width);
        let out = parallel_ekf(&model, &stage.runs, &settings, &stage.name, &mut sub)
            .map_err(|e| prefix_runs(e, s))?;
        let std = out.theta_std();
        for (c, &f) in stage.free.iter().enumerate() {
            theta[f] = out.theta[c];
            theta_std[f] = std[c];
        }
        Ok(DpStageResult {
            name: stage.name.clone(),
            free: stage.free.clone(),
            theta: out.theta.iter().copied().collect(),
            theta_cov: out.theta_cov,
            theta_trace: out.theta_trace,
            bias: out
                .states
                .iter()
                .map(|x| x.columns(6, 3).into_owned())
                .collect(),
            momentum: out
                .states
                .iter()
                .map(|x| x.columns(0, 3).into_owned())
                .collect(),
            innovations: out.innovations,
        })
    }
}

/// Names a run field within its stage (`runs[1].u` → `stages[2].runs[1].u`).
fn prefix_runs(e: EkfError, stage: usize) -> EkfError {
    let fix = |field: String| {
        if field.starts_with("runs") {
            format!("stages[{stage}].{field}")
        } else {
            field
        }
    };
    match e {
        EkfError::Shape {
            field,
            expected,
            got,
        } => EkfError::Shape {
            field: fix(field),
            expected,
            got,
        },
        EkfError::NotFinite { field } => EkfError::NotFinite { field: fix(field) },
        other => other,
    }
}
