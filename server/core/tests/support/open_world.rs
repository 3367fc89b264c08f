//! The λ-filter campaign identification graded on the independent truth
//! (`seatrial-truth`: a 6-DOF Fossen model with C(ν)ν, speed-scheduled
//! linear + quadratic damping and g(η), flown by another team's 20 Hz PI
//! controller with a wrong nominal g(η) feed-forward, logged at 10 Hz).
//! Nothing here is shared with the estimator: the logs go through the
//! service's CSV parser as a user's upload would.

#![allow(dead_code)]

use nalgebra::DMatrix;
use nalgebra::DVector;
use seatrial_core::estimation::NoProgress;
use seatrial_core::identification::outcome::Identified;
use seatrial_core::identification::predictor::validate_on_run_with;
use seatrial_core::identification::{
    LambdaCampaignSettings, RunInput, identify_lambda_campaign, lambda_campaign::StructureChoice,
};
use seatrial_core::logs::{LogRole, ParseOptions, parse_log, to_uniform};
use seatrial_core::models::{coriolis, project_physical};
use seatrial_core::planning::campaign::ExperimentFamily;
use seatrial_core::planning::dof::Dof;
use seatrial_core::planning::examples::surveyor_rov;
use seatrial_core::planning::vessel::VesselProfile;
use seatrial_core::validation::{ValidationSettings, nrmse_fit};
use seatrial_truth::{
    Campaign, CampaignSpec, Role, Run, Vessel, effective_linearization,
    effective_linearization_given_quadratic, fly_campaign, true_predictions,
};

/// One parameter's error in units of its reported std.
#[derive(Debug, Clone)]
pub struct ZScore {
    pub name: String,
    pub estimate: f64,
    pub truth: f64,
    pub std: f64,
}

impl ZScore {
    pub fn z(&self) -> f64 {
        (self.estimate - self.truth) / self.std
    }
}

/// Per channel: the service's and the true model's fits on the validation
/// run, and the affine least-squares baseline's 1-step fit.
#[derive(Debug, Clone)]
pub struct ChannelFit {
    pub channel: String,
    pub one_step: Option<f64>,
    pub one_step_true: Option<f64>,
    pub free_run: Option<f64>,
    pub free_run_true: Option<f64>,
    /// Free run of the best model of the identified class: each grid
    /// point's effective linearization of the truth over its runs, with
    /// the true g(η) — what the estimator could reach at best.
    pub free_run_oracle: Option<f64>,
    /// The stored model's free run, validated from its document.
    pub free_run_stored: Option<f64>,
    /// The same with its extension below the grid removed: the lowest
    /// sub-model held there (thesis).
    pub free_run_held: Option<f64>,
    pub one_step_affine: Option<f64>,
}

pub struct SeedReport {
    pub seed: u64,
    pub z: Vec<ZScore>,
    pub fits: Vec<ChannelFit>,
    /// Per grid point: speed, physical, and why not.
    pub physical: Vec<(f64, bool, String)>,
    pub findings: Vec<String>,
    pub notes: Vec<String>,
}

/// The profile a user would write for `campaign`'s vehicle: the Surveyor
/// template with force limits of twice the largest logged command and
/// rough time constants.
pub fn profile_for(campaign: &Campaign) -> VesselProfile {
    let mut p = surveyor_rov();
    p.name = format!("drawn ROV {}", campaign.seed);
    for (j, d) in Dof::ALL.iter().enumerate() {
        let tau_max = campaign
            .runs
            .iter()
            .map(|r| r.log.tau.column(j).amax())
            .fold(0.0, f64::max);
        let lim = p.limits.get_mut(d).expect("six DOFs");
        lim.max_force = 2.0 * tau_max.max(1.0);
        lim.max_force_rate = lim.max_force;
        lim.time_constant_s = 1.0;
    }
    p
}

fn family(role: Role) -> ExperimentFamily {
    match role {
        Role::Static => ExperimentFamily::Static,
        Role::Dynamic => ExperimentFamily::Dynamic,
        Role::Validation => ExperimentFamily::Validation,
    }
}

/// A run as the service reads it: its single-file CSV through the parser.
pub fn to_input(profile: &VesselProfile, run: &Run, described: bool) -> RunInput {
    let csv = run.single_csv();
    let opts = ParseOptions::for_vessel(profile, LogRole::Single, None);
    let parsed = parse_log(csv.as_bytes(), &opts).expect("the truth's CSV parses");
    let (record, _) = to_uniform(&parsed.table, None).expect("uniform");
    RunInput {
        run_id: run.meta.name.clone(),
        name: run.meta.name.clone(),
        family: described.then(|| family(run.meta.role)),
        grid_speed_mps: if described { run.meta.grid_speed } else { None },
        excited_dofs: Vec::new(),
        record,
    }
}

/// ν_{k+1} = A ν_k + B τ_k + c by ordinary least squares over the
/// estimation runs (the few lines of numpy a user would write), and its
/// 1-step predictions on a log.
struct Affine {
    theta: DMatrix<f64>,
}

impl Affine {
    fn regressor(nu: &DMatrix<f64>, tau: &DMatrix<f64>, k: usize) -> Vec<f64> {
        let mut x: Vec<f64> = nu.row(k).iter().copied().collect();
        x.extend(tau.row(k).iter().copied());
        x.push(1.0);
        x
    }

    fn fit(runs: &[&Run]) -> Self {
        let rows: usize = runs.iter().map(|r| r.log.nu.nrows() - 1).sum();
        let mut x = DMatrix::zeros(rows, 13);
        let mut y = DMatrix::zeros(rows, 6);
        let mut i = 0;
        for r in runs {
            for k in 0..r.log.nu.nrows() - 1 {
                let reg = Self::regressor(&r.log.nu, &r.log.tau, k);
                for (j, v) in reg.iter().enumerate() {
                    x[(i, j)] = *v;
                }
                for j in 0..6 {
                    y[(i, j)] = r.log.nu[(k + 1, j)];
                }
                i += 1;
            }
        }
        let theta = x.svd(true, true).solve(&y, 1e-12).expect("least squares");
        Affine { theta }
    }

    fn one_step(&self, run: &Run) -> DMatrix<f64> {
        let n = run.log.nu.nrows();
        let mut out = run.log.nu.clone();
        for k in 0..n - 1 {
            let reg = Self::regressor(&run.log.nu, &run.log.tau, k);
            for j in 0..6 {
                out[(k + 1, j)] = (0..13).map(|a| reg[a] * self.theta[(a, j)]).sum();
            }
        }
        out
    }
}

fn column_fit(
    measured: &DMatrix<f64>,
    predicted: &DMatrix<f64>,
    j: usize,
    skip: usize,
) -> Option<f64> {
    let m: Vec<f64> = measured.column(j).iter().skip(skip).copied().collect();
    let p: Vec<f64> = predicted.column(j).iter().skip(skip).copied().collect();
    nrmse_fit(&m, &p)
}

/// Flies seed `seed`'s vessel, identifies it with the default settings and
/// grades the result. `described`: the runs carry their role and grid
/// speed (else the service must infer them).
/// The truth's best linear-affine model over the runs named `run_ids`.
/// The truth's coefficient of |ν_i|ν_i: D_q,i, and in surge also D_lu,0
/// (D_lu|u_r| is the speed growth of the linear damping, quadratic in u).
fn true_quadratic(vessel: &Vessel, i: usize) -> f64 {
    vessel.damping_quadratic[i]
        + if i == 0 {
            vessel.damping_linear_per_speed[0]
        } else {
            0.0
        }
}

fn fitted_linearization(
    vessel: &Vessel,
    campaign: &Campaign,
    run_ids: &[String],
) -> seatrial_truth::Linearization {
    let runs: Vec<&Run> = campaign
        .runs
        .iter()
        .filter(|r| run_ids.contains(&r.meta.name))
        .collect();
    effective_linearization(vessel, &runs)
}

/// A flown campaign as the service identifies it.
pub struct Identification {
    pub profile: VesselProfile,
    pub inputs: Vec<RunInput>,
    /// The force columns, one per DOF.
    pub columns: Vec<String>,
    pub out: Identified,
}

/// Reads `campaign`'s runs through the parser and identifies them on its
/// grid with `settings`.
pub fn identify(
    campaign: &Campaign,
    described: bool,
    settings: &LambdaCampaignSettings,
) -> Identification {
    let profile = profile_for(campaign);
    let inputs: Vec<RunInput> = campaign
        .runs
        .iter()
        .map(|r| to_input(&profile, r, described))
        .collect();
    let columns: Vec<String> = profile
        .dofs
        .iter()
        .map(|d| d.force_column().to_string())
        .collect();
    let out = identify_lambda_campaign(
        &profile,
        &campaign.spec.grid_speeds,
        &columns,
        &inputs,
        settings,
        &mut NoProgress,
    )
    .expect("identification succeeds");
    Identification {
        profile,
        inputs,
        columns,
        out,
    }
}

pub fn evaluate(seed: u64, described: bool, settings: &LambdaCampaignSettings) -> SeedReport {
    evaluate_with(seed, described, settings, &CampaignSpec::default())
}

/// [`evaluate`] on a campaign flown to `spec`.
pub fn evaluate_with(
    seed: u64,
    described: bool,
    settings: &LambdaCampaignSettings,
    spec: &CampaignSpec,
) -> SeedReport {
    let vessel = Vessel::draw(seed);
    let campaign = fly_campaign(&vessel, spec, seed);
    let Identification {
        inputs,
        columns,
        out,
        ..
    } = identify(&campaign, described, settings);
    let doc = &out.document;
    let lpv = doc.lpv.as_ref().expect("an LPV model");

    // Parameters against the truth's best linear-affine model over the
    // runs each grid point was fitted to.
    let mut z = Vec::new();
    let restoring = doc.restoring.as_ref().map(|r| r.params);
    let wb_est = restoring.map_or(0.0, |r| r.weight_minus_buoyancy_n);
    for point in &lpv.points {
        // A model with quadratic damping is graded against the truth's best
        // linear-affine model beside the truth's own D_q, in the DOFs the
        // model gives one (an entry left out, σ 0, is linear there).
        let lin = if let Some(std) = &lpv.quadratic_damping_std {
            let d_q = nalgebra::Vector6::from_fn(|i, _| {
                if std.get(i).is_some_and(|s| *s > 0.0) {
                    true_quadratic(&vessel, i)
                } else {
                    0.0
                }
            });
            let runs: Vec<&Run> = campaign
                .runs
                .iter()
                .filter(|r| point.run_ids.contains(&r.meta.name))
                .collect();
            effective_linearization_given_quadratic(&vessel, &runs, &d_q, point.speed_mps)
        } else {
            fitted_linearization(&vessel, &campaign, &point.run_ids)
        };
        let name = |g: &str, i: usize, j: usize| {
            format!(
                "{g}[{},{}]@{:.2}",
                Dof::ALL[i].name(),
                Dof::ALL[j].name(),
                point.speed_mps
            )
        };
        for i in 0..6 {
            for j in 0..6 {
                for (g, est, std, truth) in [
                    ("M", point.m[i][j], point.m_std[i][j], lin.m[(i, j)]),
                    (
                        "D̄",
                        point.d_bar[i][j],
                        point.d_bar_std[i][j],
                        lin.d_bar[(i, j)],
                    ),
                ] {
                    // M is symmetric: its pair (i, j), (j, i) is one parameter.
                    if g == "M" && j < i {
                        continue;
                    }
                    if std > 0.0 && std.is_finite() {
                        z.push(ZScore {
                            name: name(g, i, j),
                            estimate: est,
                            truth,
                            std,
                        });
                    }
                }
            }
        }
        if let (Some(b), Some(s)) = (&point.load, &point.load_std) {
            for i in 0..6 {
                // Heave: the constant the model and the truth put in heave
                // together with −(W − B): compare b − (W − B) with its truth.
                let (est, truth) = if i == 2 {
                    (b[i] - wb_est, lin.bias[i] - vessel.w_minus_b)
                } else {
                    (b[i], lin.bias[i])
                };
                z.push(ZScore {
                    name: format!("b[{}]@{:.2}", Dof::ALL[i].name(), point.speed_mps),
                    estimate: est,
                    truth,
                    std: s[i],
                });
            }
        }
    }
    if let (Some(d_q), Some(std)) = (&lpv.quadratic_damping, &lpv.quadratic_damping_std) {
        for i in 0..6 {
            // An entry left out (0, no σ) is not an estimate to judge.
            if std[i] > 0.0 && std[i].is_finite() {
                z.push(ZScore {
                    name: format!("D_q[{}]", Dof::ALL[i].name()),
                    estimate: d_q[i],
                    truth: true_quadratic(&vessel, i),
                    std: std[i],
                });
            }
        }
    }
    if let Some(r) = &doc.restoring {
        for p in &r.parameters {
            let truth = match p.symbol.as_str() {
                "W−B" => vessel.w_minus_b,
                "z_G·W − z_B·B" => vessel.zg_w_minus_zb_b(),
                _ => continue,
            };
            if let Some(std) = p.std {
                z.push(ZScore {
                    name: p.symbol.clone(),
                    estimate: p.value,
                    truth,
                    std,
                });
            }
        }
    }

    // Fits on the validation run: the service's report against the true
    // model through the same metric, and the affine baseline.
    let estimation: Vec<&Run> = campaign
        .runs
        .iter()
        .filter(|r| r.meta.role != Role::Validation)
        .collect();
    let affine = Affine::fit(&estimation);
    let val_run = campaign.validation_runs()[0];
    let report = &out
        .validation
        .iter()
        .find(|v| v.run_id == val_run.meta.name)
        .expect("validated on the held-out run")
        .report;
    let truth_pred = true_predictions(&vessel, &val_run.log);
    let oracle = {
        let mut doc = doc.clone();
        if let Some(r) = doc.restoring.as_mut() {
            r.params.weight_minus_buoyancy_n = vessel.w_minus_b;
            r.params.zg_weight_minus_zb_buoyancy_nm = vessel.zg_w_minus_zb_b();
        }
        // The best linear model: no quadratic damping.
        doc.lpv.as_mut().expect("an LPV model").quadratic_damping = None;
        for point in doc.lpv.as_mut().expect("an LPV model").points.iter_mut() {
            let lin = fitted_linearization(&vessel, &campaign, &point.run_ids);
            point.m = (0..6)
                .map(|i| (0..6).map(|j| lin.m[(i, j)]).collect())
                .collect();
            point.d_bar = (0..6)
                .map(|i| (0..6).map(|j| lin.d_bar[(i, j)]).collect())
                .collect();
            point.load = Some(lin.bias.iter().copied().collect());
        }
        let val_input = inputs
            .iter()
            .find(|r| r.run_id == val_run.meta.name)
            .expect("the validation run is an input");
        validate_on_run_with(&doc, val_input, &columns, ValidationSettings::default()).ok()
    };
    let val_input = inputs
        .iter()
        .find(|r| r.run_id == val_run.meta.name)
        .expect("the validation run is an input");
    let stored = validate_on_run_with(doc, val_input, &columns, ValidationSettings::default()).ok();
    let held = {
        let mut doc = doc.clone();
        doc.lpv.as_mut().expect("an LPV model").extension = None;
        validate_on_run_with(&doc, val_input, &columns, ValidationSettings::default()).ok()
    };
    let free_run = |r: &Option<seatrial_core::validation::ValidationReport>, j: usize| {
        r.as_ref()
            .and_then(|o| o.channels.get(j))
            .and_then(|c| c.fit_simulation)
    };
    let aff = affine.one_step(val_run);
    let fits = report
        .channels
        .iter()
        .enumerate()
        .map(|(j, c)| ChannelFit {
            channel: c.output.clone(),
            one_step: c.fit_one_step,
            one_step_true: column_fit(&val_run.log.nu, &truth_pred.one_step, j, 1),
            free_run: c.fit_simulation,
            free_run_true: column_fit(&val_run.log.nu, &truth_pred.free_run, j, 0),
            free_run_oracle: free_run(&oracle, j),
            free_run_stored: free_run(&stored, j),
            free_run_held: free_run(&held, j),
            one_step_affine: column_fit(&val_run.log.nu, &aff, j, 1),
        })
        .collect();
    let physical = lpv
        .points
        .iter()
        .map(|p| {
            let m = DMatrix::from_fn(6, 6, |i, j| p.m[i][j]);
            let d = DMatrix::from_fn(6, 6, |i, j| p.d_bar[i][j]);
            (p.speed_mps, physical(&m, &d, p.speed_mps))
        })
        .map(|(s, (ok, why))| (s, ok, why))
        .collect();
    SeedReport {
        seed,
        z,
        fits,
        physical,
        findings: doc.structure_findings.clone(),
        notes: doc.notes.clone(),
    }
}

/// M symmetric positive definite and D = D̄ − J_C(M, u₀) dissipative, with
/// J_C the linearization of C(ν)ν (from the model's own M) at ν₀ = (u₀, 0…).
fn physical(m: &DMatrix<f64>, d_bar: &DMatrix<f64>, u0: f64) -> (bool, String) {
    let f = |nu: &DVector<f64>| coriolis(m, nu).expect("6-DOF") * nu;
    let mut jc = DMatrix::zeros(6, 6);
    for c in 0..6 {
        let mut e = DVector::zeros(6);
        e[0] = u0;
        let (mut p, mut q) = (e.clone(), e.clone());
        p[c] += 1.0;
        q[c] -= 1.0;
        jc.set_column(c, &((f(&p) - f(&q)) / 2.0));
    }
    let asym = (m - m.transpose()).norm() / m.norm();
    let proj = project_physical(m, &(d_bar - &jc));
    // A projected D sits on the dissipative boundary (an eigenvalue of its
    // symmetric part exactly 0); recomputing it here from the stored D̄ and
    // M leaves round-off of either sign, which is not energy gain.
    let d = d_bar - &jc;
    let eig = ((&d + d.transpose()) * 0.5).symmetric_eigenvalues();
    let producing = eig.iter().filter(|&&l| l < -1e-9 * eig.amax()).count();
    let ok = asym < 1e-9 && proj.m_raised == 0 && producing == 0;
    (
        ok,
        format!(
            "M asymmetry {asym:.2e}, {} non-positive M eigenvalue(s), {producing} energy-producing D direction(s)",
            proj.m_raised
        ),
    )
}

/// The default settings, or one structure.
pub fn settings(structure: Option<StructureChoice>) -> LambdaCampaignSettings {
    let mut s = LambdaCampaignSettings::default();
    if let Some(st) = structure {
        s.structure = st;
    }
    s
}
