//! A DP campaign identified by the staged parallel EKF (Fossen, Sagatun &
//! Sørensen 1995, sec. 3–4): the runs of the planned decoupled manoeuvres
//! (SI1 surge, SI2 sway–yaw, SI3 azimuth — each run, and each gap-separated
//! block of a run, one parallel EKF subsystem of its stage), M″ and T″ known
//! from the vessel profile, A″_h and K″ estimated, validated on held-out
//! runs by position and heading prediction.
//!
//! Units: logs are SI; the EKF runs in the Bis system of the profile's
//! [`DpPrior`](crate::planning::vessel::DpPrior) (x″ = x/L, t″ = t/√(L/g),
//! ψ and the commands unchanged), so θ″ are the paper's numbers. The stored
//! document keeps the Bis matrices with L and √(L/g), plus A and B in SI;
//! validation is reported in m and rad (see [`super::bis`]).

use nalgebra::{DMatrix, Matrix3, SymmetricEigen};
use serde::{Deserialize, Serialize};

use super::bis::{BisScale, SiDpShip, unwrap_heading};
use super::dataset::{RunInput, segments};
use super::document::{
    DpNoiseDoc, DpShipDoc, Method, ModelDocument, ModelKind, ParameterRow, to_rows,
};
use super::error::IdentifyError;
use super::outcome::{Identified, RunValidation};
use super::roles::assign_roles;
use crate::estimation::ekf::{
    DpIdentConfig, DpStage, EkfError, IdentifiedDpShip, RunData, SI1_FREE, SI2_FREE, SI3_FREE,
    identify_dp_ship,
};
use crate::estimation::{Progress, SubProgress};
use crate::numbers::sig3;
use crate::planning::campaign::ExperimentFamily;
use crate::planning::dof::Dof;
use crate::planning::vessel::{InputChannels, ThrusterKind, VesselKind, VesselProfile};
use crate::simulation::dp_ship::{Matrix3x6, N_THETA, THETA_NAMES};
use crate::validation::{ValidationRecord, ValidationSettings, validate};

/// Shortest block of a run the EKF uses (samples).
const MIN_SAMPLES: usize = 50;

/// Settings of a parallel-EKF identification (JSON `settings` of the job).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct EkfCampaignSettings {
    /// Sweeps through SI1 → SI2 → SI3 (≥ 1): each further sweep restarts
    /// every stage from the previous sweep's θ̂.
    #[serde(default = "default_sweeps")]
    pub sweeps: usize,
    /// Standard deviation of the measured x and y (m).
    #[serde(default = "default_position_noise")]
    pub position_noise_std_m: f64,
    /// Standard deviation of the measured heading (degrees).
    #[serde(default = "default_heading_noise")]
    pub heading_noise_std_deg: f64,
    /// Initial guess of θ″1 … θ″9 (Bis: A″_h11, A″_h22, A″_h23, A″_h32,
    /// A″_h33, K″1 = K″2, K″3 = K″4, K″5, K″6); default: A″_h,ii = −√(L/g)/T_i
    /// from the profile's time constants, no coupling, K″ = 5·10⁻³.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_init: Option<Vec<f64>>,
    /// Standard deviation of that guess (P(0) of θ″); default 0.1 (0.3 for
    /// A″_h33, or 1.2·|guess| if larger) for A″_h, 5·10⁻³ for K″.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_init_std: Option<Vec<f64>>,
    /// Random-walk step of the bias b_h per sample (Bis force, surge, sway, yaw).
    #[serde(default = "default_bias_walk")]
    pub bias_walk_std_bis: [f64; 3],
    /// Standard deviation of the initial bias (Bis force).
    #[serde(default = "default_bias_initial")]
    pub bias_initial_std_bis: [f64; 3],
    /// Process noise on the momentum per sample (Bis); a little keeps the
    /// filter from locking on biased θ″ under position noise.
    #[serde(default = "default_momentum_noise")]
    pub momentum_noise_std_bis: f64,
    /// Parameter random walk per sample (eq. 38); 0 for constant θ″.
    #[serde(default)]
    pub q_theta: f64,
    /// Held-out runs; default: the plan's validation runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_run_ids: Option<Vec<String>>,
    /// Horizon of the k-step predictions of validation.
    #[serde(default = "default_k")]
    pub k: usize,
}

fn default_sweeps() -> usize {
    2
}
fn default_position_noise() -> f64 {
    1.0
}
fn default_heading_noise() -> f64 {
    0.2
}
fn default_bias_walk() -> [f64; 3] {
    [3e-6, 3e-6, 6e-7]
}
fn default_bias_initial() -> [f64; 3] {
    [1e-3, 1e-3, 2e-4]
}
fn default_momentum_noise() -> f64 {
    1e-5
}
fn default_k() -> usize {
    10
}

impl Default for EkfCampaignSettings {
    fn default() -> Self {
        EkfCampaignSettings {
            sweeps: default_sweeps(),
            position_noise_std_m: default_position_noise(),
            heading_noise_std_deg: default_heading_noise(),
            theta_init: None,
            theta_init_std: None,
            bias_walk_std_bis: default_bias_walk(),
            bias_initial_std_bis: default_bias_initial(),
            momentum_noise_std_bis: default_momentum_noise(),
            q_theta: 0.0,
            validation_run_ids: None,
            k: default_k(),
        }
    }
}

/// The thruster kinds the θ″ parameterization of eq. 47 assumes, in column
/// order: two main propellers (K1 = K2), three tunnels (the two stern ones
/// K3 = K4, the bow one K5), one azimuth (K6).
const LAYOUT: [ThrusterKind; 6] = [
    ThrusterKind::Main,
    ThrusterKind::Main,
    ThrusterKind::Tunnel,
    ThrusterKind::Tunnel,
    ThrusterKind::Tunnel,
    ThrusterKind::Azimuth,
];

/// M″, T″ and the Bis scale of a profile, or the field that lacks them.
fn known(profile: &VesselProfile) -> Result<(Matrix3<f64>, Matrix3x6, BisScale), IdentifyError> {
    if profile.kind != VesselKind::Dp3 || profile.dofs != Dof::HORIZONTAL {
        return Err(IdentifyError::invalid(
            "method",
            "parallel_ekf identifies DP vessels (kind dp3, DOFs surge, sway, yaw)",
        ));
    }
    let prior = profile.dp_prior.as_ref().ok_or_else(|| {
        IdentifyError::invalid(
            "vessel.dp_prior",
            "the parallel EKF needs the inertia M″ and the ship length L (Bis scale) in the vessel profile",
        )
    })?;
    let InputChannels::Thrusters {
        thrusters,
        configuration,
    } = &profile.inputs
    else {
        return Err(IdentifyError::invalid(
            "vessel.inputs",
            "the parallel EKF needs thruster commands and the configuration matrix T″",
        ));
    };
    let kinds: Vec<ThrusterKind> = thrusters.iter().map(|t| t.kind).collect();
    if kinds != LAYOUT {
        return Err(IdentifyError::invalid(
            "vessel.inputs.thrusters",
            "the θ″ parameterization (eq. 47) needs six thrusters in the order main, main, tunnel (stern), tunnel (stern), tunnel (bow), azimuth",
        ));
    }
    let m = Matrix3::from_fn(|i, j| prior.inertia_bis[i][j]);
    let t = Matrix3x6::from_fn(|i, j| configuration[i][j]);
    Ok((m, t, BisScale::of(prior)))
}

/// Default initial guess from the profile's time constants.
fn default_theta(profile: &VesselProfile, scale: &BisScale) -> [f64; N_THETA] {
    let a = |d: Dof| -scale.time_unit_s / profile.limit(d).time_constant_s;
    [
        a(Dof::Surge),
        a(Dof::Sway),
        0.0,
        0.0,
        a(Dof::Yaw),
        5e-3,
        5e-3,
        5e-3,
        5e-3,
    ]
}

fn default_theta_std(theta: &[f64; N_THETA]) -> [f64; N_THETA] {
    let base: [f64; N_THETA] = [0.1, 0.1, 0.1, 0.1, 0.3, 5e-3, 5e-3, 5e-3, 5e-3];
    std::array::from_fn(|i| {
        if i < 5 {
            base[i].max(1.2 * theta[i].abs())
        } else {
            base[i]
        }
    })
}

fn nine(field: &str, v: &Option<Vec<f64>>) -> Result<Option<[f64; N_THETA]>, IdentifyError> {
    let Some(v) = v else { return Ok(None) };
    let arr: [f64; N_THETA] = v.as_slice().try_into().map_err(|_| {
        IdentifyError::invalid(
            field,
            format!("θ″ has nine entries (θ″1 … θ″9), got {}", v.len()),
        )
    })?;
    if let Some(i) = arr.iter().position(|x| !x.is_finite()) {
        return Err(IdentifyError::invalid(
            format!("{field}[{i}]"),
            "must be a finite number",
        ));
    }
    Ok(Some(arr))
}

fn check_settings(s: &EkfCampaignSettings) -> Result<(), IdentifyError> {
    let pos = |field: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(IdentifyError::invalid(
                format!("settings.{field}"),
                format!("must be a positive number, got {v}"),
            ))
        }
    };
    let nonneg = |field: &str, v: f64| {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err(IdentifyError::invalid(
                format!("settings.{field}"),
                format!("must be a number ≥ 0, got {v}"),
            ))
        }
    };
    if s.sweeps == 0 || s.sweeps > 20 {
        return Err(IdentifyError::invalid(
            "settings.sweeps",
            format!("must be 1–20, got {}", s.sweeps),
        ));
    }
    if s.k == 0 {
        return Err(IdentifyError::invalid(
            "settings.k",
            "the horizon k must be ≥ 1",
        ));
    }
    pos("position_noise_std_m", s.position_noise_std_m)?;
    pos("heading_noise_std_deg", s.heading_noise_std_deg)?;
    for (i, &v) in s.bias_walk_std_bis.iter().enumerate() {
        nonneg(&format!("bias_walk_std_bis[{i}]"), v)?;
    }
    for (i, &v) in s.bias_initial_std_bis.iter().enumerate() {
        pos(&format!("bias_initial_std_bis[{i}]"), v)?;
    }
    nonneg("momentum_noise_std_bis", s.momentum_noise_std_bis)?;
    nonneg("q_theta", s.q_theta)?;
    if let Some(std) = nine("settings.theta_init_std", &s.theta_init_std)? {
        for (i, &v) in std.iter().enumerate() {
            pos(&format!("theta_init_std[{i}]"), v)?;
        }
    }
    nine("settings.theta_init", &s.theta_init)?;
    Ok(())
}

/// Stage of a planned DP family.
fn stage_of(family: Option<ExperimentFamily>) -> Option<usize> {
    match family? {
        ExperimentFamily::DpSurge => Some(0),
        ExperimentFamily::DpSwayYaw => Some(1),
        ExperimentFamily::DpAzimuth => Some(2),
        _ => None,
    }
}

/// One run's blocks as Bis EKF data: u (commands), z = (x/L, y/L, ψ unwrapped).
struct Block {
    run_id: String,
    h_s: f64,
    u: DMatrix<f64>,
    z: DMatrix<f64>,
}

fn blocks(
    run: &RunInput,
    inputs: &[String],
    scale: &BisScale,
) -> Result<Vec<Block>, IdentifyError> {
    let outputs = ["x", "y", "psi"].map(String::from);
    let segs = segments(run, inputs, &outputs, MIN_SAMPLES)
        .map_err(|e| IdentifyError::invalid(format!("runs[{}]", e.run_id), e.to_string()))?;
    Ok(segs
        .into_iter()
        .map(|s| {
            let mut y = s.y;
            let mut psi: Vec<f64> = y.column(2).iter().copied().collect();
            unwrap_heading(&mut psi);
            y.set_column(2, &nalgebra::DVector::from_vec(psi));
            Block {
                run_id: s.run_id,
                h_s: s.h,
                u: s.u,
                z: scale.pose_to_bis(&y),
            }
        })
        .collect())
}

/// What the identified A″_h, K″ say about physics: D = −A_h·M dissipative
/// (symmetric part positive definite), A stable, K″ > 0.
pub fn structure_findings(m: &Matrix3<f64>, a_h: &Matrix3<f64>, k: &[f64]) -> Vec<String> {
    let mut out = Vec::new();
    let d = -a_h * m;
    let sym = (d + d.transpose()) * 0.5;
    let eig = SymmetricEigen::new(sym).eigenvalues;
    let min = eig.min();
    if min <= 0.0 {
        out.push(format!(
            "D″ = −A″_h·M″ is not dissipative: its symmetric part has eigenvalue {} ≤ 0 (νᵀDν ≤ 0 for some motion); the estimate is reported, not corrected",
            sig3(min)
        ));
    }
    let a = m.try_inverse().map(|mi| mi * a_h * m);
    if let Some(a) = a {
        let re = a
            .complex_eigenvalues()
            .iter()
            .map(|z| z.re)
            .fold(f64::MIN, f64::max);
        if re >= 0.0 {
            out.push(format!(
                "A″ = M″⁻¹A″_h M″ is not stable: an eigenvalue has real part {} ≥ 0",
                sig3(re)
            ));
        }
    }
    for (j, &kj) in k.iter().enumerate() {
        if kj <= 0.0 {
            out.push(format!(
                "K″{} = {} ≤ 0: thruster {} pushes against its configuration column",
                j + 1,
                sig3(kj),
                j + 1
            ));
        }
    }
    out
}

/// Maps an EKF error to the setting or data it concerns.
fn ekf_error(e: EkfError) -> IdentifyError {
    let field = match &e {
        EkfError::Cancelled => return IdentifyError::Cancelled,
        EkfError::Invalid { field, .. }
        | EkfError::Shape { field, .. }
        | EkfError::NotFinite { field }
        | EkfError::NonPositive { field, .. } => match field.as_str() {
            "m" => "vessel.dp_prior.inertia_bis".to_string(),
            "t" => "vessel.inputs.configuration".to_string(),
            "theta_init" | "theta_init_std" | "sweeps" | "q_theta" => format!("settings.{field}"),
            "r" => "settings.position_noise_std_m".to_string(),
            "q_b" => "settings.bias_walk_std_bis".to_string(),
            "p0_b" => "settings.bias_initial_std_bis".to_string(),
            "q_h" => "settings.momentum_noise_std_bis".to_string(),
            _ => "run_ids".to_string(),
        },
        EkfError::NoRuns | EkfError::Diverged { .. } => "run_ids".to_string(),
    };
    IdentifyError::invalid(field, e.to_string())
}

/// Identifies a DP campaign by the staged parallel EKF. `inputs` are the
/// thruster command columns (`thr_1 … thr_6`); `runs` carry x, y, ψ.
pub fn identify_ekf_campaign(
    profile: &VesselProfile,
    inputs: &[String],
    runs: &[RunInput],
    settings: &EkfCampaignSettings,
    progress: &mut dyn Progress,
) -> Result<Identified, IdentifyError> {
    let (m, t, scale) = known(profile)?;
    check_settings(settings)?;
    if inputs.len() != 6 {
        return Err(IdentifyError::invalid(
            "vessel.inputs.thrusters",
            format!(
                "six thruster command columns are needed, got {}",
                inputs.len()
            ),
        ));
    }
    let roles = assign_roles(runs, settings.validation_run_ids.as_deref())?;
    if let Some(r) = roles.statics.first() {
        return Err(IdentifyError::invalid(
            format!("runs[{}]", r.run_id),
            "a static run has no place in the DP manoeuvres SI1–SI3",
        ));
    }
    let mut staged: [Vec<Block>; 3] = Default::default();
    for r in &roles.estimation {
        let s = stage_of(r.family).ok_or_else(|| {
            IdentifyError::invalid(
                format!("runs[{}]", r.run_id),
                "the parallel EKF stages runs by their planned DP manoeuvre (dp_surge → SI1, dp_sway_yaw → SI2, dp_azimuth → SI3); this run flew none — hold it out in settings.validation_run_ids or leave it out of run_ids",
            )
        })?;
        staged[s].extend(blocks(r, inputs, &scale)?);
    }
    for (s, fam) in ["dp_surge", "dp_sway_yaw", "dp_azimuth"].iter().enumerate() {
        if staged[s].is_empty() {
            return Err(IdentifyError::invalid(
                "run_ids",
                format!(
                    "no {fam} run for SI{}: every θ″ needs its manoeuvre (Fossen et al. sec. 4.2, N ≥ 2 recommended)",
                    s + 1
                ),
            ));
        }
    }
    let h_s = staged[0][0].h_s;
    if let Some(b) = staged
        .iter()
        .flatten()
        .find(|b| (b.h_s - h_s).abs() > 1e-9 * h_s)
    {
        return Err(IdentifyError::invalid(
            format!("runs[{}]", b.run_id),
            format!(
                "sample time {} s differs from {h_s} s of the other runs; resample them alike",
                b.h_s
            ),
        ));
    }
    let theta_init = match nine("settings.theta_init", &settings.theta_init)? {
        Some(t) => t,
        None => default_theta(profile, &scale),
    };
    let theta_init_std = match nine("settings.theta_init_std", &settings.theta_init_std)? {
        Some(s) => s,
        None => default_theta_std(&theta_init),
    };
    let sq = |a: [f64; 3]| a.map(|v| v * v);
    let pos = settings.position_noise_std_m / scale.length_m;
    let cfg = DpIdentConfig {
        m,
        t,
        h: h_s / scale.time_unit_s,
        theta_init,
        theta_init_std,
        r: sq([pos, pos, settings.heading_noise_std_deg.to_radians()]),
        p0_h: [1e-8; 3],
        p0_b: sq(settings.bias_initial_std_bis),
        q_h: [settings.momentum_noise_std_bis.powi(2); 3],
        q_b: sq(settings.bias_walk_std_bis),
        q_theta: settings.q_theta,
        sweeps: settings.sweeps,
    };
    let frees = [SI1_FREE.to_vec(), SI2_FREE.to_vec(), SI3_FREE.to_vec()];
    let stages: Vec<DpStage<'_>> = staged
        .iter()
        .zip(frees)
        .enumerate()
        .map(|(s, (b, free))| DpStage {
            name: format!("SI{}", s + 1),
            free,
            runs: b.iter().map(|b| RunData { u: &b.u, z: &b.z }).collect(),
        })
        .collect();
    let id = {
        let mut sub = SubProgress::new(progress, 0.0, 0.85);
        identify_dp_ship(&cfg, &stages, &mut sub).map_err(ekf_error)?
    };
    progress.update(0.85, "validating on held-out runs")?;
    let model = SiDpShip {
        model: IdentifiedDpShip {
            ship: id.ship.clone(),
            r: cfg.r,
            p0_h: cfg.p0_h,
            p0_b: cfg.p0_b,
            q_h: cfg.q_h,
            q_b: cfg.q_b,
        },
        scale,
    };
    let vsettings = ValidationSettings {
        k: settings.k,
        input_names: inputs.to_vec(),
        ..ValidationSettings::default()
    };
    let mut validation = Vec::new();
    for r in &roles.validation {
        let bs = blocks(r, inputs, &scale)?;
        let longest = bs
            .iter()
            .max_by_key(|b| b.z.nrows())
            .expect("blocks is non-empty");
        let y = scale.pose_to_si(&longest.z);
        let report = validate(
            &model,
            &ValidationRecord {
                h: longest.h_s,
                u: &longest.u,
                y: &y,
            },
            &vsettings,
        )
        .map_err(|e| IdentifyError::invalid(format!("runs[{}]", r.run_id), e.to_string()))?;
        validation.push(RunValidation {
            run_id: r.run_id.clone(),
            run_name: r.name.clone(),
            report,
        });
    }
    progress.update(1.0, "done")?;
    let document = document(&id, &cfg, &scale, inputs, &staged);
    let mut used = settings.clone();
    used.theta_init = Some(theta_init.to_vec());
    used.theta_init_std = Some(theta_init_std.to_vec());
    Ok(Identified {
        document,
        validation,
        estimation_run_ids: roles.estimation.iter().map(|r| r.run_id.clone()).collect(),
        validation_run_ids: roles.validation.iter().map(|r| r.run_id.clone()).collect(),
        settings_used: serde_json::to_value(&used).unwrap_or_default(),
    })
}

fn document(
    id: &crate::estimation::ekf::DpIdentification,
    cfg: &DpIdentConfig,
    scale: &BisScale,
    inputs: &[String],
    staged: &[Vec<Block>; 3],
) -> ModelDocument {
    let ship = &id.ship;
    let std = &id.theta_std;
    // θ″ index of each A_h entry and K column (eq. 46–47).
    let a_idx = [(0, 0, 0), (1, 1, 1), (1, 2, 2), (2, 1, 3), (2, 2, 4)];
    let k_idx = [5, 5, 6, 6, 7, 8];
    let mut a_h_std = Matrix3::zeros();
    for &(i, j, p) in &a_idx {
        a_h_std[(i, j)] = std[p];
    }
    let a = ship.state_space_a();
    let b = ship.state_space_b();
    let parameters = (0..N_THETA)
        .map(|p| ParameterRow {
            group: "θ″".into(),
            symbol: format!("θ″{} ({})", p + 1, THETA_NAMES[p]),
            grid_speed_mps: None,
            value: id.theta[p],
            std: Some(std[p]),
            unit: "Bis".into(),
        })
        .collect();
    let dm = |m: &DMatrix<f64>| to_rows(m);
    let fixed = |m: &Matrix3<f64>| dm(&DMatrix::from_column_slice(3, 3, m.as_slice()));
    let wide = |m: &Matrix3x6| dm(&DMatrix::from_column_slice(3, 6, m.as_slice()));
    let mut findings = structure_findings(&ship.m, &ship.a_h, ship.k.as_slice());
    for p in 0..N_THETA {
        if std[p] > 0.5 * id.theta[p].abs() {
            findings.push(format!(
                "θ″{} ({}) = {} ± {} is poorly determined (σ > 50 %): excite its manoeuvre more or fly more runs",
                p + 1,
                THETA_NAMES[p],
                sig3(id.theta[p]),
                sig3(std[p])
            ));
        }
    }
    let counts: Vec<String> = staged
        .iter()
        .enumerate()
        .map(|(s, b)| format!("SI{}: {} block(s)", s + 1, b.len()))
        .collect();
    ModelDocument {
        kind: ModelKind::DpShip,
        method: Method::ParallelEkf,
        dofs: Dof::HORIZONTAL.to_vec(),
        inputs: inputs.to_vec(),
        outputs: vec!["x".into(), "y".into(), "psi".into()],
        restoring: None,
        lpv: None,
        dp_ship: Some(DpShipDoc {
            units: "Bis".into(),
            length_m: scale.length_m,
            time_unit_s: scale.time_unit_s,
            m: fixed(&ship.m),
            t_config: wide(&ship.t),
            a_h: fixed(&ship.a_h),
            a_h_std: fixed(&a_h_std),
            k: ship.k.iter().copied().collect(),
            k_std: k_idx.iter().map(|&p| std[p]).collect(),
            theta: id.theta.to_vec(),
            theta_std: std.to_vec(),
            d: fixed(&ship.damping()),
            a: fixed(&a),
            b: wide(&b),
            a_si: fixed(&scale.a_si(&a)),
            b_si: wide(&scale.b_si(&b)),
            noise: DpNoiseDoc {
                r: cfg.r.to_vec(),
                p0_h: cfg.p0_h.to_vec(),
                p0_b: cfg.p0_b.to_vec(),
                q_h: cfg.q_h.to_vec(),
                q_b: cfg.q_b.to_vec(),
            },
        }),
        state_space: None,
        parameters,
        structure_findings: findings,
        notes: vec![
            format!(
                "Staged parallel EKF (Fossen et al. 1995): SI1 → SI2 → SI3, {} sweep(s); {}; each run and gap-separated block is one parallel subsystem.",
                cfg.sweeps,
                counts.join(", ")
            ),
            format!(
                "Bis units: L = {} m, time √(L/g) = {:.4} s, forces m·g, moments m·g·L; x″ = x/L, t″ = t/√(L/g). a_si, b_si: ν in m/s, rad/s, time in s.",
                scale.length_m, scale.time_unit_s
            ),
            "M″ and T″ are the profile's a-priori values; A″ = M″⁻¹A″_h M″ and B″ = M″⁻¹T″K″ drop C_h (eq. 50–52).".into(),
        ],
    }
}

#[cfg(test)]
#[path = "ekf_campaign_tests.rs"]
mod tests;
