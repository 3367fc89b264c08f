//! Issue 15's proof for the ROV: the predicted precision of a plan
//! (`design::predict_precision`, which flies the plan with a prior through
//! the project's OWN simulator) against the empirical spread of the
//! λ-filter estimates when the same plan is flown, seed after seed, by the
//! INDEPENDENT truth (`seatrial-truth`: its own 6-DOF plant, 20 Hz
//! autopilot on noisy measurements with a wrong ĝ(η) feed-forward, 10 Hz
//! logger).
//!
//! The bridge is plain numbers: each planned experiment's schedule columns
//! become the truth's [`Channel`]s, the truth vessel's published parameters
//! become the prior [`RovTruth`], the truth's [`NoiseSpec`] becomes the
//! prediction's [`MeasurementNoise`]. The truth's CSV is read through the
//! service's parser as an upload would be.

#![allow(dead_code)]

use std::collections::BTreeMap;

use nalgebra::Matrix6;
use seatrial_core::design::{PrecisionPrediction, PredictSettings, Prior, PriorSource};
use seatrial_core::estimation::NoProgress;
use seatrial_core::identification::autopilot_fit::{InferredAutopilot, infer_autopilot};
use seatrial_core::identification::document::ParameterRow;
use seatrial_core::identification::{LambdaCampaignSettings, RunInput, identify_lambda_campaign};
use seatrial_core::logs::{LogRole, ParseOptions, input_columns, parse_log, to_uniform};
use seatrial_core::planning::{
    Autopilot, AutopilotLoop, CampaignSpec, Dof, ExperimentFamily, Plan, PlannedExperiment,
    RestoringFeedForward, VesselProfile, examples,
};
use seatrial_core::simulation::rov::{LinearDamping, Restoring, RovTruth};
use seatrial_core::simulation::trials::MeasurementNoise;
use seatrial_truth::controller::ControllerConfig;
use seatrial_truth::rng::{Rng, derive_seed};
use seatrial_truth::{
    Channel, ExternalRun, NoiseSpec, Vessel, external_envelope, fly_external_runs,
};

#[path = "precision_truth/compare.rs"]
mod compare;

pub use compare::*;

/// Seed of the plan (its PRBS draws).
pub const PLAN_SEED: u64 = 7;
/// Seed of the one autopilot tuning every noise seed flies with.
pub const TUNE_SEED: u64 = 15;
/// Largest factor between empirical and predicted std that counts as a
/// match (the goal).
pub const FACTOR: f64 = 1.5;

/// Velocity-reference column of DOF i (u_ref … r_ref).
const VELOCITY: [&str; 6] = ["u_ref", "v_ref", "w_ref", "p_ref", "q_ref", "r_ref"];
/// Force column of DOF i.
const FORCE: [&str; 6] = ["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N"];

/// Everything the comparison needs, built once.
pub struct Setup {
    pub profile: VesselProfile,
    pub plan: Plan,
    pub vessel: Vessel,
    pub controller: ControllerConfig,
    pub runs: Vec<ExternalRun>,
    pub noise: NoiseSpec,
    /// How both sides identify (the service's λ-filter defaults unless
    /// [`PlanVariant::linear_damping`]).
    pub lambda: LambdaCampaignSettings,
}

/// Which plan to fly.
#[derive(Debug, Clone, Default)]
pub struct PlanVariant {
    /// Replaces the spec's grid (knots).
    pub grid_kn: Option<Vec<f64>>,
    /// Leaves out the recursive family (the all-DOF REC runs, whose
    /// roll/pitch rate references integrate to large attitudes).
    pub no_recursive: bool,
    /// Flies the campaign as `design::design_campaign` designs it within
    /// the rule-based plan's hours (prior: the source documents' vessel,
    /// as a supervisor would have; the truth flies it).
    pub designed: bool,
    /// Repeats every run of the rule-based plan this many times (0 or 1:
    /// once), as the design's rule-based front does (`repetitions`).
    pub repeat: u32,
    /// Leaves the truth's autopilot out of the profile, so the prediction
    /// flies the project's generic loops (designed from the limits alone)
    /// instead of the team's declared gains and ĝ feed-forward.
    pub generic_autopilot: bool,
    /// Identifies with linear damping only (both sides), not the service's
    /// default quadratic damping.
    pub linear_damping: bool,
    /// Seed of the truth's autopilot tuning (default [`TUNE_SEED`]).
    pub tune_seed: Option<u64>,
}

/// The service's rule-based Surveyor plan, as `variant` asks.
pub fn plan(variant: &PlanVariant) -> (VesselProfile, Plan) {
    let profile = examples::surveyor_rov();
    let mut spec: CampaignSpec = examples::surveyor_campaign(PLAN_SEED);
    if let Some(g) = &variant.grid_kn {
        spec.grid.speeds = g.clone();
    }
    if variant.no_recursive {
        spec.families.retain(|f| *f != ExperimentFamily::Recursive);
    }
    if variant.repeat > 1 {
        spec.repetitions = Some(spec.repetitions_for(profile.kind) * variant.repeat);
    }
    if variant.designed {
        let Prior::Rov(prior) = Prior::reference(&profile).expect("the reference prior") else {
            panic!("the Surveyor's prior is an ROV")
        };
        spec =
            seatrial_core::design::design_campaign(&profile, &spec, &prior, None, &mut NoProgress)
                .expect("the design")
                .spec;
    }
    let plan = seatrial_core::planning::generate_plan(&profile, &spec).expect("the plan");
    (profile, plan)
}

/// The Surveyor-like truth vessel, the plan as external schedules and one
/// autopilot tuned for their envelope.
pub fn setup(variant: &PlanVariant) -> Setup {
    let (profile, plan) = plan(variant);
    let vessel = Vessel::surveyor_like();
    let runs: Vec<ExternalRun> = plan.experiments.iter().map(to_external).collect();
    let mut rng = Rng::new(derive_seed(variant.tune_seed.unwrap_or(TUNE_SEED), 0xCA3B));
    let controller = ControllerConfig::tune(&vessel, &external_envelope(&runs), &mut rng);
    let mut profile = profile;
    if !variant.generic_autopilot {
        profile.autopilot = Some(autopilot_of(&controller, &profile));
    }
    Setup {
        profile,
        plan,
        vessel,
        controller,
        runs,
        noise: NoiseSpec::default(),
        lambda: LambdaCampaignSettings {
            quadratic_damping: !variant.linear_damping,
            ..LambdaCampaignSettings::default()
        },
    }
}

/// The truth's autopilot as the team would declare it in the profile:
/// PI gains of the velocity loops, PD gains of the attitude loops, the
/// nominal W − B and z_G W − z_B B it feeds forward (plain numbers; the
/// truth's limits stay its own).
pub fn autopilot_of(c: &ControllerConfig, profile: &VesselProfile) -> Autopilot {
    let loops = profile
        .dofs
        .iter()
        .map(|&d| {
            let i = d.index();
            let attitude = matches!(d, Dof::Roll | Dof::Pitch);
            (
                d,
                AutopilotLoop {
                    kp: c.kp[i],
                    ki: c.ki[i],
                    kd: attitude.then_some(c.kd[i]),
                },
            )
        })
        .collect();
    Autopilot {
        loops,
        restoring_feed_forward: Some(RestoringFeedForward {
            w_minus_b: c.nominal_w_minus_b,
            zg_w_minus_zb_b: c.nominal_zg_w_minus_zb_b,
        }),
    }
}

/// A planned experiment as the truth's external schedule, column by column
/// as `simulation::trials` reads it: `u_ref … r_ref` velocity (roll and
/// pitch: rate) references, `phi_ref`, `theta_ref` attitude references,
/// `tau_X … tau_N` open-loop forces; a DOF without a column is held.
pub fn to_external(p: &PlannedExperiment) -> ExternalRun {
    let s = &p.schedule;
    let channels: [Channel; 6] = std::array::from_fn(|i| {
        let col = |name: &str| {
            s.columns
                .iter()
                .position(|c| c == name)
                .map(|c| s.values[c].clone())
        };
        if let Some(x) = col(VELOCITY[i]) {
            Channel::Velocity(x)
        } else if let Some(x) = (i == 3).then(|| col("phi_ref")).flatten() {
            Channel::Attitude(x)
        } else if let Some(x) = (i == 4).then(|| col("theta_ref")).flatten() {
            Channel::Attitude(x)
        } else if let Some(x) = col(FORCE[i]) {
            Channel::Force(x)
        } else {
            Channel::Hold
        }
    });
    ExternalRun::new(p.experiment.code.clone(), s.sample_rate_hz, channels)
}

/// The prior "equal to the vessel": the truth's published M = M_RB + M_A,
/// D_l(u) = D_l0 + D_lu·u tabulated over the plan's speeds (exact under
/// the interpolation; the plan never reverses, u > 0), D_q, C(ν) from M,
/// W = m g, B = W − (W − B), r_G = (0, 0, z_G), r_B = (0, 0, z_B).
pub fn prior_of(v: &Vessel) -> RovTruth {
    let d0 = Matrix6::from_diagonal(&v.damping_linear);
    let d1 = Matrix6::from_diagonal(&v.damping_linear_per_speed);
    let speeds: Vec<f64> = (0..=10).map(|k| 0.25 * k as f64).collect();
    let mut t = RovTruth::new(v.m(), LinearDamping::affine(d0, d1, speeds));
    t.quadratic_damping = std::array::from_fn(|i| v.damping_quadratic[i]);
    t.coriolis = true;
    t.restoring = Restoring {
        weight: v.weight(),
        buoyancy: v.buoyancy(),
        r_g: [0.0, 0.0, v.z_g],
        r_b: [0.0, 0.0, v.z_b],
    };
    t
}

/// The truth's white noise as the project's simulator states it.
pub fn measurement_noise(n: &NoiseSpec) -> MeasurementNoise {
    MeasurementNoise {
        nu: std::array::from_fn(|i| n.nu_std(i)),
        eta: std::array::from_fn(|i| n.eta_std(i)),
    }
}

/// Key of a parameter row: group, symbol, grid speed.
pub type Key = (String, String, Option<String>);

fn key(group: &str, symbol: &str, speed: Option<f64>) -> Key {
    (
        group.to_string(),
        symbol.to_string(),
        speed.map(|u| format!("{u:.4}")),
    )
}

/// Rows as the prediction tabulates them: the document's parameters, then
/// the restoring rows not already among them.
fn rows(doc: &seatrial_core::identification::document::ModelDocument) -> Vec<&ParameterRow> {
    let mut rows: Vec<&ParameterRow> = doc.parameters.iter().collect();
    if let Some(r) = &doc.restoring {
        for p in &r.parameters {
            if !rows
                .iter()
                .any(|q| q.symbol == p.symbol && q.group == p.group)
            {
                rows.push(p);
            }
        }
    }
    rows
}

/// The plan's grid speeds, ascending.
pub fn grid(plan: &Plan) -> Vec<f64> {
    plan.grid_speeds()
}

/// One seed's estimates: per key the value and the reported std.
pub type Estimates = BTreeMap<Key, (f64, Option<f64>)>;

/// Flies the plan on the truth with noise seed `seed` (one autopilot for
/// all seeds) and identifies it as the service would.
pub fn fly_and_identify(s: &Setup, seed: u64) -> Estimates {
    let flown = fly_external_runs(&s.vessel, &s.controller, &s.runs, &s.noise, seed);
    identify_flown(s, &flown)
}

/// [`fly_and_identify`] with the autopilot re-tuned from `seed` (its
/// nominal inertia and ĝ(η) drawn anew): the spread then holds the
/// campaign-to-campaign change of the closed loop, not only the noise.
pub fn fly_and_identify_retuned(s: &Setup, seed: u64) -> Estimates {
    let (_, flown) = seatrial_truth::fly_external_campaign(&s.vessel, &s.runs, &s.noise, seed);
    identify_flown(s, &flown)
}

/// The truth's flown runs as the service reads them: each run's single
/// CSV through the parser, paired with its planned experiment.
pub fn run_inputs(s: &Setup, flown: &[seatrial_truth::Run]) -> Vec<RunInput> {
    s.plan
        .experiments
        .iter()
        .zip(flown)
        .map(|(p, run)| {
            assert_eq!(run.meta.name, p.experiment.code);
            let csv = run.single_csv();
            let opts = ParseOptions::for_vessel(&s.profile, LogRole::Single, None);
            let parsed = parse_log(csv.as_bytes(), &opts).expect("the truth's CSV parses");
            let (record, _) = to_uniform(&parsed.table, None).expect("uniform");
            let e = &p.experiment;
            RunInput {
                run_id: e.code.clone(),
                name: e.code.clone(),
                family: Some(e.family),
                grid_speed_mps: e.grid_speed_mps,
                excited_dofs: e.dofs.clone(),
                record,
            }
        })
        .collect()
}

/// Infers the truth's autopilot from its flown runs (noise seed `seed`),
/// as the service would from a first dive.
pub fn infer_truth_autopilot(s: &Setup, seed: u64) -> InferredAutopilot {
    let flown = fly_external_runs(&s.vessel, &s.controller, &s.runs, &s.noise, seed);
    let inputs = run_inputs(s, &flown);
    let pairs: Vec<_> = s.plan.experiments.iter().zip(inputs.iter()).collect();
    infer_autopilot(&s.profile, &pairs).expect("the truth's autopilot is inferred")
}

fn identify_flown(s: &Setup, flown: &[seatrial_truth::Run]) -> Estimates {
    let inputs = run_inputs(s, flown);
    let id = identify_lambda_campaign(
        &s.profile,
        &grid(&s.plan),
        &input_columns(&s.profile),
        &inputs,
        &s.lambda,
        &mut NoProgress,
    )
    .expect("the truth's campaign identifies");
    rows(&id.document)
        .into_iter()
        .map(|r| (key(&r.group, &r.symbol, r.grid_speed_mps), (r.value, r.std)))
        .collect()
}

/// `fly_and_identify` for `seeds`, on up to `threads` threads.
pub fn fly_seeds(s: &Setup, seeds: &[u64], threads: usize) -> Vec<Estimates> {
    fly_seeds_with(s, seeds, threads, fly_and_identify)
}

/// `f` for `seeds`, on up to `threads` threads, in seed order.
pub fn fly_seeds_with(
    s: &Setup,
    seeds: &[u64],
    threads: usize,
    f: fn(&Setup, u64) -> Estimates,
) -> Vec<Estimates> {
    let threads = threads.clamp(1, seeds.len().max(1));
    let chunks: Vec<Vec<u64>> = (0..threads)
        .map(|t| seeds.iter().copied().skip(t).step_by(threads).collect())
        .collect();
    let mut out: Vec<(u64, Estimates)> = std::thread::scope(|scope| {
        let handles: Vec<_> = chunks
            .iter()
            .map(|c| scope.spawn(move || c.iter().map(|&k| (k, f(s, k))).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a seed's worker"))
            .collect()
    });
    out.sort_by_key(|(k, _)| *k);
    out.into_iter().map(|(_, e)| e).collect()
}

/// The prediction: the plan flown by the project's simulator with the
/// vessel as prior and the truth's noise.
pub fn predict(s: &Setup) -> PrecisionPrediction {
    predict_seed(s, PredictSettings::default().seed)
}

/// [`predict`] with the simulator's noise seed `seed`.
pub fn predict_seed(s: &Setup, seed: u64) -> PrecisionPrediction {
    predict_with(s, prior_of(&s.vessel), seed)
}

/// [`predict_seed`] with another prior.
pub fn predict_with(s: &Setup, prior: RovTruth, seed: u64) -> PrecisionPrediction {
    predict_noise(s, prior, measurement_noise(&s.noise), seed)
}

/// [`predict_with`] with another noise.
pub fn predict_noise(
    s: &Setup,
    prior: RovTruth,
    noise: MeasurementNoise,
    seed: u64,
) -> PrecisionPrediction {
    seatrial_core::design::predict_precision(
        &s.profile,
        &s.plan,
        &Prior::Rov(Box::new(prior)),
        PriorSource::Reference,
        &PredictSettings {
            rov_noise: noise,
            seed,
            lambda: s.lambda.clone(),
            ..PredictSettings::default()
        },
        &mut NoProgress,
    )
    .expect("the prediction")
}

/// A prediction's expected values as one seed's estimates.
pub fn estimates_of_prediction(p: &PrecisionPrediction) -> Estimates {
    p.parameters
        .iter()
        .map(|r| {
            (
                key(&r.group, &r.symbol, r.grid_speed_mps),
                (r.expected_value, r.predicted_std),
            )
        })
        .collect()
}
