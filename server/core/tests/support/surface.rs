//! The λ-filter campaign identification on horizontal (3-DOF) surface
//! vessels, graded on the independent surface-vessel truth
//! (`seatrial_truth::usv`: Fossen's manoeuvring model with relative
//! velocity to a current, C_A with its Munk moment, quadratic surge and
//! cross-flow drag). The logs go through the service's CSV parser as a
//! user's upload would; nothing here is shared with the estimator.

#![allow(dead_code)]

use std::collections::BTreeMap;

use seatrial_core::estimation::NoProgress;
use seatrial_core::identification::document::NedCurrentDoc;
use seatrial_core::identification::{
    Identified, LambdaCampaignSettings, RunInput, identify_lambda_campaign,
};
use seatrial_core::logs::{LogRole, ParseOptions, parse_log, to_uniform};
use seatrial_core::planning::campaign::ExperimentFamily;
use seatrial_core::planning::dof::Dof;
use seatrial_core::planning::vessel::{
    DofLimits, DpPrior, InputChannels, VesselKind, VesselProfile,
};
use seatrial_core::validation::nrmse_fit;
use seatrial_truth::usv::{
    Current, Effects, Noise, SupplyTrial, SurfaceCampaign, SurfaceVessel, UsvTrial,
    fly_supply_campaign, fly_usv_campaign,
};

/// One graded identification.
pub struct SurfaceReport {
    pub label: String,
    pub seed: u64,
    /// The true mean current: speed (m/s) and direction (rad), when flown.
    pub current_true: Option<(f64, f64)>,
    pub current_est: Option<NedCurrentDoc>,
    /// Per channel (u, v, r) on the held-out run: the model's free-run
    /// fit and the true model's (its exact states against the log).
    pub free_run: Vec<(String, Option<f64>, Option<f64>)>,
    pub notes: Vec<String>,
    /// The share of the held-out run whose true speed through the water
    /// u_r = u − u_c(ψ) (noise-free log, true current) lies below the
    /// lowest grid speed.
    pub below_grid_share: f64,
    /// The model's surge quadratic drag D_q[surge] and its std (N·s²/m²),
    /// when it carries one.
    pub surge_drag: Option<(f64, f64)>,
}

impl SurfaceReport {
    /// Largest shortfall of the model's free-run fit below the true
    /// model's over the channels (None when a fit is missing).
    pub fn worst_gap(&self) -> Option<f64> {
        self.free_run
            .iter()
            .map(|(_, m, t)| Some(t.as_ref()? - m.as_ref()?))
            .try_fold(f64::NEG_INFINITY, |acc, g| g.map(|g| acc.max(g)))
    }

    /// Relative error of the estimated current speed.
    pub fn current_error(&self) -> Option<f64> {
        let (s, _) = self.current_true?;
        let e = self.current_est.as_ref()?;
        Some((e.speed_mps - s) / s)
    }

    pub fn line(&self) -> String {
        let fits: Vec<String> = self
            .free_run
            .iter()
            .map(|(c, m, t)| {
                format!(
                    "{c} {:.3}/{:.3}",
                    m.unwrap_or(f64::NAN),
                    t.unwrap_or(f64::NAN)
                )
            })
            .collect();
        let truth = self
            .current_true
            .map(|(s, b)| format!("{s:.3} m/s → {:.0}°", b.to_degrees().rem_euclid(360.0)))
            .unwrap_or_else(|| "none".into());
        let est = self
            .current_est
            .as_ref()
            .map(|c| {
                format!(
                    "{:.3} ± {:.3} m/s → {:.0}°",
                    c.speed_mps, c.speed_std_mps, c.direction_deg
                )
            })
            .unwrap_or_else(|| "none".into());
        format!(
            "{:<22} seed {}: current {truth:<18} est {est:<28} free run model/true {}",
            self.label,
            self.seed,
            fits.join(", ")
        )
    }
}

/// One DOF's limits as a user states them: top velocity, force, force
/// rate and time constant.
fn limits(
    max_velocity: f64,
    max_force: f64,
    max_force_rate: f64,
    time_constant_s: f64,
) -> DofLimits {
    DofLimits {
        max_velocity,
        max_force,
        max_force_rate,
        max_accel: None,
        time_constant_s,
        max_angle: None,
    }
}

/// The profile a user writes for a DP vessel logging τ: force limits of
/// twice the largest logged, rough time constants, its length.
pub fn supply_profile(vessel: &SurfaceVessel, trial: &SupplyTrial) -> VesselProfile {
    let lim = |v, f: f64, t| limits(v, f, f / 10.0, t);
    let f = trial.force_max;
    VesselProfile {
        name: format!("{} (drawn)", vessel.name),
        kind: VesselKind::Dp3,
        dofs: Dof::HORIZONTAL.to_vec(),
        inputs: InputChannels::GeneralizedForces,
        limits: BTreeMap::from([
            (Dof::Surge, lim(4.0, 2.0 * f[0], 80.0)),
            (Dof::Sway, lim(2.0, 2.0 * f[1], 40.0)),
            (Dof::Yaw, lim(0.05, 2.0 * f[2], 15.0)),
        ]),
        controller_rate_hz: 1.0,
        logger_rate_hz: 1.0,
        dp_prior: Some(DpPrior {
            length_m: vessel.length_m,
            inertia_bis: None,
        }),
        heading_unit: None,
        autopilot: None,
    }
}

fn family(f: &str) -> ExperimentFamily {
    match f {
        "dp_surge" => ExperimentFamily::DpSurge,
        "dp_sway_yaw" => ExperimentFamily::DpSwayYaw,
        "validation" => ExperimentFamily::Validation,
        _ => ExperimentFamily::Dynamic,
    }
}

/// The campaign's runs through the parser.
pub fn inputs(profile: &VesselProfile, campaign: &SurfaceCampaign) -> Vec<RunInput> {
    let opts = ParseOptions::for_vessel(profile, LogRole::Single, None);
    campaign
        .runs
        .iter()
        .map(|r| {
            let parsed = parse_log(r.csv.as_bytes(), &opts).expect("the truth's CSV parses");
            let (record, _) = to_uniform(&parsed.table, None).expect("uniform");
            RunInput {
                run_id: r.name.clone(),
                name: r.name.clone(),
                family: Some(family(r.family)),
                grid_speed_mps: None,
                excited_dofs: Vec::new(),
                record,
            }
        })
        .collect()
}

/// Column `j` of a truth CSV.
fn column(csv: &str, j: usize) -> Vec<f64> {
    csv.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .nth(j)
                .expect("column")
                .parse()
                .expect("number")
        })
        .collect()
}

/// The true current of a campaign's validation run: mean speed and its
/// direction.
fn current_of(effects: &Effects, campaign: &SurfaceCampaign) -> Option<(f64, f64)> {
    let dir = match effects.current {
        Current::None => return None,
        Current::Constant { direction_rad, .. } => direction_rad,
        Current::GaussMarkov { direction_rad, .. } => direction_rad,
    };
    let mean = campaign
        .runs
        .iter()
        .map(|r| r.current.mean_mps())
        .sum::<f64>()
        / campaign.runs.len() as f64;
    Some((mean, dir))
}

/// Identifies the supply-vessel campaign of `vessel` under `effects`
/// (seed `seed`) and grades it.
pub fn supply_case(
    label: &str,
    vessel: &SurfaceVessel,
    effects: Effects,
    seed: u64,
    settings: &LambdaCampaignSettings,
) -> (SurfaceReport, Identified) {
    let trial = SupplyTrial {
        effects,
        ..SupplyTrial::default()
    };
    let campaign = fly_supply_campaign(vessel, &trial, seed);
    let exact = fly_supply_campaign(
        vessel,
        &SupplyTrial {
            noise: Noise::NONE,
            ..trial
        },
        seed,
    );
    let profile = supply_profile(vessel, &trial);
    grade(
        label,
        seed,
        &effects,
        &profile,
        &[0.0],
        (&campaign, &exact),
        settings,
    )
}

/// Identifies `campaign` (read through the parser for `profile`) on `grid`
/// and grades its held-out run against the same campaign flown exactly.
fn grade(
    label: &str,
    seed: u64,
    effects: &Effects,
    profile: &VesselProfile,
    grid: &[f64],
    (campaign, exact): (&SurfaceCampaign, &SurfaceCampaign),
    settings: &LambdaCampaignSettings,
) -> (SurfaceReport, Identified) {
    let runs = inputs(profile, campaign);
    let cols: Vec<String> = profile
        .dofs
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    let out = identify_lambda_campaign(profile, grid, &cols, &runs, settings, &mut NoProgress)
        .expect("identification succeeds");
    let val = campaign.runs.last().expect("a validation run");
    let val_exact = exact.runs.last().expect("a validation run");
    let report = &out
        .validation
        .iter()
        .find(|v| v.run_id == val.name)
        .expect("validated on the held-out run")
        .report;
    let free_run = ["u", "v", "r"]
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let truth = nrmse_fit(&column(&val.csv, 4 + i), &column(&val_exact.csv, 4 + i));
            (c.to_string(), report.channels[i].fit_simulation, truth)
        })
        .collect();
    let (u, psi) = (column(&val_exact.csv, 4), column(&val_exact.csv, 9));
    let below = (0..u.len())
        .filter(|&k| {
            let u_c = val_exact.current.segment(k, 1.0).body(psi[k])[0];
            u[k] - u_c < grid[0]
        })
        .count();
    let report = SurfaceReport {
        label: label.into(),
        below_grid_share: below as f64 / u.len().max(1) as f64,
        seed,
        current_true: current_of(effects, campaign),
        current_est: out.document.lpv.as_ref().and_then(|l| l.current.clone()),
        surge_drag: out.document.lpv.as_ref().and_then(|l| {
            let d = l.quadratic_damping.as_ref()?.first().copied()?;
            let s = l.quadratic_damping_std.as_ref()?.first().copied()?;
            (d != 0.0).then_some((d, s))
        }),
        free_run,
        notes: out.document.notes.clone(),
    };
    (report, out)
}

/// The Otter's profile as its owner writes it: a 3-DOF surface vessel
/// logging τ (its two propellers' forces; τ_Y = 0), force limits of twice
/// the largest logged.
pub fn otter_profile(vessel: &SurfaceVessel) -> VesselProfile {
    let lim = |v, f, t| limits(v, f, f, t);
    VesselProfile {
        name: format!("{} (drawn)", vessel.name),
        kind: VesselKind::Dp3,
        dofs: Dof::HORIZONTAL.to_vec(),
        inputs: InputChannels::GeneralizedForces,
        limits: BTreeMap::from([
            (Dof::Surge, lim(3.0, 250.0, 1.0)),
            (Dof::Sway, lim(1.0, 100.0, 1.0)),
            (Dof::Yaw, lim(0.5, 50.0, 1.0)),
        ]),
        controller_rate_hz: 10.0,
        logger_rate_hz: 10.0,
        dp_prior: None,
        heading_unit: None,
        autopilot: None,
    }
}

/// Identifies the Otter campaign of `vessel` flown as `trial` on `grid`
/// and grades it.
pub fn otter_case(
    label: &str,
    vessel: &SurfaceVessel,
    trial: &UsvTrial,
    seed: u64,
    grid: &[f64],
    settings: &LambdaCampaignSettings,
) -> (SurfaceReport, Identified) {
    let campaign = fly_usv_campaign(vessel, trial, seed);
    let exact = fly_usv_campaign(
        vessel,
        &UsvTrial {
            noise: Noise::NONE,
            ..*trial
        },
        seed,
    );
    let profile = otter_profile(vessel);
    grade(
        label,
        seed,
        &trial.effects,
        &profile,
        grid,
        (&campaign, &exact),
        settings,
    )
}

/// The Otter's grid as its crew states it: the steady speed through the
/// water of each of the campaign's command levels on a straight course
/// (both propellers at the level), to the nearest 0.05 m/s — what the
/// surge runs' mean speeds show in still water.
pub fn otter_grid(vessel: &SurfaceVessel, effects: &Effects) -> Vec<f64> {
    use seatrial_truth::usv::OTTER_THRUST_N;
    UsvTrial::default()
        .levels
        .iter()
        .map(|level| {
            let u =
                vessel.steady_surge_speed(2.0 * level * OTTER_THRUST_N, effects.quadratic_surge);
            (u / 0.05).round() * 0.05
        })
        .collect()
}
