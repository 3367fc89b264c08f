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

use super::bis::{BisScale, SiDpShip, unwrap_heading};
use super::dataset::{RunInput, segments};
use super::document::{
    DpNoiseDoc, DpShipDoc, Method, ModelDocument, ModelKind, ParameterRow, to_rows,
};
use super::ekf_checks::{every_stage, stage_of};
use super::ekf_init::{InitBlock, WITHOUT_PRIOR_FINDING, ls_start, without_prior_note};
use super::ekf_layout::{EkfLayout, ekf_layout, is_paper_layout, stage_frees};
use super::ekf_refine::{RefineOutcome, not_run, refine_campaign};
pub use super::ekf_settings::EkfCampaignSettings;
use super::ekf_settings::{check_settings, nine};
use super::error::IdentifyError;
use super::outcome::{Identified, RunValidation};
use super::roles::assign_roles;
use crate::estimation::ekf::{
    DpIdentConfig, DpStage, EkfError, IdentifiedDpShip, RunData, identify_dp_ship,
};
use crate::estimation::{Progress, SubProgress};
use crate::numbers::sig3;
use crate::planning::dof::Dof;
use crate::planning::vessel::{VesselKind, VesselProfile};
use crate::simulation::dp_ship::N_THETA;
use crate::validation::{ValidationRecord, ValidationSettings, validate};

/// Shortest block of a run the EKF uses (samples).
const MIN_SAMPLES: usize = 50;

/// The pose columns the EKF measures (Fossen et al. eq. 39: z = [x, y, ψ]).
pub const EKF_POSE: [&str; 3] = ["x", "y", "psi"];

/// Why a campaign without M″ keeps the staged EKF's θ″.
const NO_REFINEMENT_WITHOUT_PRIOR: &str = "Not refined after the staging: without M″ the θ″ rest on the rough least-squares inertia, and a likelihood refinement would only fit them tighter to it; θ″ and std are the staged EKF's.";

/// Checks that `profile` can be identified by the parallel EKF: a DP vessel
/// with surge, sway, yaw, a ship length L, and a thrust layout of at most
/// four coefficient groups (or generalized forces); the field that is wrong
/// is named.
pub fn check_ekf_profile(profile: &VesselProfile) -> Result<(), IdentifyError> {
    known(profile).map(|_| ())
}

/// M″ (when the profile gives it), the thrust layout and the Bis scale of
/// a profile, or the field that lacks them.
pub(crate) fn known(
    profile: &VesselProfile,
) -> Result<(Option<Matrix3<f64>>, EkfLayout, BisScale), IdentifyError> {
    if profile.kind != VesselKind::Dp3 || profile.dofs != Dof::HORIZONTAL {
        return Err(IdentifyError::invalid(
            "method",
            "parallel_ekf identifies DP vessels (kind dp3, DOFs surge, sway, yaw)",
        ));
    }
    let prior = profile.dp_prior.as_ref().ok_or_else(|| {
        IdentifyError::invalid(
            "vessel.dp_prior.length_m",
            "the parallel EKF needs the ship length L (the Bis scale) in the vessel profile's dp_prior; the inertia M″ is optional",
        )
    })?;
    let layout = ekf_layout(profile, prior.length_m)?;
    let m = prior
        .inertia_bis
        .as_ref()
        .map(|m| Matrix3::from_fn(|i, j| m[i][j]));
    Ok((m, layout, BisScale::of(prior)))
}

/// Default initial guess from the profile's time constants.
pub(crate) fn default_theta(profile: &VesselProfile, scale: &BisScale) -> [f64; N_THETA] {
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

/// θ″ with the slots of groups the layout does not use at 0.
fn unused_zero(mut theta: [f64; N_THETA], layout: &EkfLayout) -> [f64; N_THETA] {
    for g in 0..4 {
        if !layout.thrust.uses(g) {
            theta[5 + g] = 0.0;
        }
    }
    theta
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
    let (prior_m, layout, scale) = known(profile)?;
    check_settings(settings)?;
    if inputs.len() != layout.thrust.columns() {
        return Err(IdentifyError::invalid(
            "vessel.inputs.thrusters",
            format!(
                "{} input columns are needed ({}), got {}",
                layout.thrust.columns(),
                layout.columns.join(", "),
                inputs.len()
            ),
        ));
    }
    let roles = assign_roles(runs, settings.validation_run_ids.as_deref())?;
    if let Some(r) = roles.statics.first() {
        stage_of(&r.run_id, r.family)?;
    }
    let mut staged: [Vec<Block>; 3] = Default::default();
    for r in &roles.estimation {
        staged[stage_of(&r.run_id, r.family)?].extend(blocks(r, inputs, &scale)?);
    }
    every_stage(&staged.each_ref().map(Vec::len), is_paper_layout(profile))?;
    let frees = stage_frees(
        &layout,
        &staged.each_ref().map(|b| b.iter().map(|b| &b.u).collect()),
    )?;
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
    let ls = || {
        let b: Vec<InitBlock<'_>> = staged
            .iter()
            .flatten()
            .map(|b| InitBlock { u: &b.u, z: &b.z })
            .collect();
        ls_start(&b, h_s / scale.time_unit_s, &layout.thrust)
    };
    let start = match prior_m {
        Some(_) => None,
        None => Some(ls().map_err(|e| {
            IdentifyError::invalid(
                "vessel.dp_prior.inertia_bis",
                format!(
                    "the profile gives no M″ and the runs do not determine it: {e}; give M″ in the profile"
                ),
            )
        })?),
    };
    let m = prior_m.unwrap_or_else(|| start.as_ref().map_or(Matrix3::identity(), |s| s.m));
    let theta_init = match nine("settings.theta_init", &settings.theta_init)? {
        Some(t) => t,
        None => match (&start, prior_m) {
            (Some(s), _) => s.theta,
            // Logged forces: K″ = F_ref/(m·g) is unknown, unlike a thrust
            // coefficient's usual few 10⁻³; the least-squares fit gives
            // K″/M″11, scaled by the prior's M″11.
            (None, Some(pm)) if layout.force_ref_n.is_some() => {
                let mut t = default_theta(profile, &scale);
                if let Ok(s) = ls() {
                    t[5] = s.theta[5] * pm[(0, 0)];
                }
                t
            }
            _ => default_theta(profile, &scale),
        },
    };
    let theta_init = unused_zero(theta_init, &layout);
    let theta_init_std = match nine("settings.theta_init_std", &settings.theta_init_std)? {
        Some(s) => s,
        None => default_theta_std(&theta_init),
    };
    let sq = |a: [f64; 3]| a.map(|v| v * v);
    let pos = settings.position_noise_std_m / scale.length_m;
    let cfg = DpIdentConfig {
        m,
        thrust: layout.thrust.clone(),
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
    let idle: Vec<String> = (0..3)
        .filter(|&s| !staged[s].is_empty() && frees[s].is_empty())
        .map(|s| format!("SI{}", s + 1))
        .collect();
    let stages: Vec<DpStage<'_>> = staged
        .iter()
        .zip(frees)
        .enumerate()
        .filter(|(_, (b, free))| !b.is_empty() && !free.is_empty())
        .map(|(s, (b, free))| DpStage {
            name: format!("SI{}", s + 1),
            free,
            runs: b.iter().map(|b| RunData { u: &b.u, z: &b.z }).collect(),
        })
        .collect();
    // Without M″ the θ″ rest on a rough least-squares inertia: a likelihood
    // refinement would only fit them tighter to it.
    let refine = settings.refine && prior_m.is_some();
    let mut id = {
        let width = if refine { 0.5 } else { 0.85 };
        let mut sub = SubProgress::new(progress, 0.0, width);
        identify_dp_ship(&cfg, &stages, &mut sub).map_err(ekf_error)?
    };
    let held_out = roles
        .validation
        .iter()
        .map(|r| blocks(r, inputs, &scale).map(|b| (r, b)))
        .collect::<Result<Vec<_>, _>>()?;
    let refined = if refine {
        let estimation: Vec<RunData<'_>> =
            stages.iter().flat_map(|s| s.runs.iter().copied()).collect();
        let check: Vec<RunData<'_>> = held_out
            .iter()
            .flat_map(|(_, bs)| bs.iter().map(|b| RunData { u: &b.u, z: &b.z }))
            .collect();
        let mut sub = SubProgress::new(progress, 0.5, 0.35);
        refine_campaign(&mut id, &cfg, &layout.names, &estimation, &check, &mut sub)?
    } else if settings.refine {
        RefineOutcome {
            notes: vec![NO_REFINEMENT_WITHOUT_PRIOR.into()],
            findings: Vec::new(),
            record: Some(not_run(&id, NO_REFINEMENT_WITHOUT_PRIOR)),
        }
    } else {
        RefineOutcome::default()
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
    for (r, bs) in &held_out {
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
    let mut document = document(&id, &cfg, &scale, &layout, inputs, &staged);
    if !idle.is_empty() {
        document.notes.push(format!(
            "The {} run(s) drive no thruster group left to estimate after the earlier stages: not used.",
            idle.join(", ")
        ));
    }
    document.notes.extend(refined.notes);
    document.structure_findings.extend(refined.findings);
    if let Some(dp) = document.dp_ship.as_mut() {
        dp.refinement = refined.record;
    }
    if let Some(st) = &start {
        document.notes[2] = without_prior_note(&st.m);
        document
            .structure_findings
            .push(WITHOUT_PRIOR_FINDING.to_string());
        document.notes.push(format!(
            "EKF started from the least-squares fit: θ″ = [{}].",
            st.theta.map(sig3).join(", ")
        ));
    }
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
    layout: &EkfLayout,
    inputs: &[String],
    staged: &[Vec<Block>; 3],
) -> ModelDocument {
    let names = &layout.names;
    let used = |p: usize| p < 5 || layout.thrust.uses(p - 5);
    let ship = &id.ship;
    let std = &id.theta_std;
    // θ″ index of each A_h entry and K column (eq. 46–47).
    let a_idx = [(0, 0, 0), (1, 1, 1), (1, 2, 2), (2, 1, 3), (2, 2, 4)];
    let mut a_h_std = Matrix3::zeros();
    for &(i, j, p) in &a_idx {
        a_h_std[(i, j)] = std[p];
    }
    let a = ship.state_space_a();
    let b = ship.state_space_b();
    let parameters = (0..N_THETA)
        .filter(|&p| used(p))
        .map(|p| ParameterRow {
            group: "θ″".into(),
            symbol: format!("θ″{} ({})", p + 1, names[p]),
            grid_speed_mps: None,
            value: id.theta[p],
            std: Some(std[p]),
            unit: "Bis".into(),
        })
        .collect();
    let dm = |m: &DMatrix<f64>| to_rows(m);
    let fixed = |m: &Matrix3<f64>| dm(&DMatrix::from_column_slice(3, 3, m.as_slice()));
    let mut findings = structure_findings(&ship.m, &ship.a_h, ship.k.as_slice());
    for p in (0..N_THETA).filter(|&p| used(p)) {
        if std[p] > 0.5 * id.theta[p].abs() {
            findings.push(format!(
                "θ″{} ({}) = {} ± {} is poorly determined (σ > 50 %): excite its manoeuvre more or fly more runs",
                p + 1,
                names[p],
                sig3(id.theta[p]),
                sig3(std[p])
            ));
        }
    }
    let counts: Vec<String> = staged
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.is_empty())
        .map(|(s, b)| format!("SI{}: {} block(s)", s + 1, b.len()))
        .collect();
    let mut layout_note = layout.note.clone();
    if let Some(f) = layout.force_ref_n {
        let k = id.theta[5];
        if k > 0.0 {
            layout_note.push_str(&format!(
                " Implied m = F_ref/(g·K″) = {} t: the displacement when the profile gives M″; without M″, the surge inertia m·M″11 including added mass.",
                sig3(f / (9.81 * k) / 1000.0)
            ));
        }
    }
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
            t_config: dm(&ship.thrust.t),
            a_h: fixed(&ship.a_h),
            a_h_std: fixed(&a_h_std),
            k: ship.k.iter().copied().collect(),
            k_std: ship.thrust.groups.iter().map(|&g| std[5 + g]).collect(),
            theta: id.theta.to_vec(),
            theta_std: std.to_vec(),
            d: fixed(&ship.damping()),
            a: fixed(&a),
            b: dm(&b),
            a_si: fixed(&scale.a_si(&a)),
            b_si: dm(&scale.b_si(&b)),
            noise: DpNoiseDoc {
                r: cfg.r.to_vec(),
                p0_h: cfg.p0_h.to_vec(),
                p0_b: cfg.p0_b.to_vec(),
                q_h: cfg.q_h.to_vec(),
                q_b: cfg.q_b.to_vec(),
            },
            refinement: None,
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
            layout_note,
        ],
    }
}

#[cfg(test)]
#[path = "ekf_campaign_tests.rs"]
mod tests;
