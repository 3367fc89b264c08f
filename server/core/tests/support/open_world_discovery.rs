//! Missing-physics discovery graded on the independent truth
//! (`seatrial-truth`): a drawn vessel with one effect switched on that the
//! λ-filter LPV model cannot carry, flown by another team's controller and
//! logged at 10 Hz, identified by the service's λ identification, then
//! examined by the service's campaign discovery. The truth's own
//! predictions on the held-out run give the gap the augmented model should
//! close. Nothing here is shared with the estimator but the CSV parser.

#![allow(dead_code)]

use nalgebra::{DMatrix, Vector3, Vector6};
use seatrial_core::discrepancy::Effect;
use seatrial_core::estimation::NoProgress;
use seatrial_core::identification::LambdaCampaignSettings;
use seatrial_core::identification::discover_campaign::{
    DiscoverCampaignSettings, discover_campaign,
};
use seatrial_core::numbers::sig3;
use seatrial_core::planning::dof::Dof;
use seatrial_core::validation::nrmse_fit;
use seatrial_truth::{Campaign, CampaignSpec, Vessel, fly_campaign, true_predictions};

use super::open_world::{Identification, identify};

/// The effect concealed from the λ model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Concealed {
    /// The drawn vessel as it is.
    Clean,
    /// A steady current of 0.25 m/s north, 0.15 m/s east.
    Current,
    /// A tether pull fixed in NED (it leads to the ship), of 30 % of the
    /// clean campaign's RMS sway command, towards a bearing drawn from the
    /// seed: in the body frame it turns with the heading, which the
    /// baseline's constant loads cannot follow.
    Tether,
    /// Thrusters following the command through a 0.4 s first-order lag in
    /// every DOF.
    Lag,
    /// Heave thrust clipped at 60 % of the clean campaign's largest heave
    /// command.
    Saturation,
    /// Quadratic sway damping four times the drawn one.
    QuadraticSway,
}

impl Concealed {
    pub const ALL: [Concealed; 6] = [
        Concealed::Clean,
        Concealed::Current,
        Concealed::Tether,
        Concealed::Lag,
        Concealed::Saturation,
        Concealed::QuadraticSway,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Concealed::Clean => "clean",
            Concealed::Current => "current",
            Concealed::Tether => "tether",
            Concealed::Lag => "actuator lag",
            Concealed::Saturation => "saturation",
            Concealed::QuadraticSway => "quadratic sway damping",
        }
    }

    /// Whether `e` names this effect (`Some(true)`), a look-alike at the
    /// right place (`Some(false)`: lag ↔ delay, a body-fixed load for the
    /// tether's pull, cubic for quadratic drag in the same DOF), or
    /// something else (`None`).
    pub fn names(self, e: &Effect) -> Option<bool> {
        match (self, e) {
            (Concealed::Current, Effect::Current) => Some(true),
            (Concealed::Tether, Effect::TetherPull) => Some(true),
            (
                Concealed::Tether,
                Effect::ConstantLoad {
                    dof: Dof::Surge | Dof::Sway,
                },
            ) => Some(false),
            (Concealed::Lag, Effect::ActuatorLag { .. }) => Some(true),
            (Concealed::Lag, Effect::InputDelay { .. } | Effect::CommonInputDelay) => Some(false),
            (Concealed::Saturation, Effect::Saturation { dof: Dof::Heave }) => Some(true),
            (Concealed::QuadraticSway, Effect::QuadraticDamping { dof: Dof::Sway }) => Some(true),
            (Concealed::QuadraticSway, Effect::CubicDamping { dof: Dof::Sway }) => Some(false),
            _ => None,
        }
    }

    /// The concealed effect's true size in the units discovery reports.
    fn truth_text(self, vessel: &Vessel) -> String {
        match self {
            Concealed::Clean => "none concealed".into(),
            Concealed::Current => format!(
                "V_N {:.3}, V_E {:.3} m/s",
                vessel.current_ned.x, vessel.current_ned.y
            ),
            Concealed::Tether => format!(
                "F_N {:.1}, F_E {:.1} N",
                vessel.tether_ned.x, vessel.tether_ned.y
            ),
            Concealed::Lag => "T_a 0.4 s in every DOF".into(),
            Concealed::Saturation => format!(
                "heave τ_max {:.1} N",
                vessel.actuator.limits.map_or(f64::NAN, |l| l[2])
            ),
            Concealed::QuadraticSway => format!(
                "d_v|v| {:.1} N·s²/m² (drawn {:.1})",
                vessel.damping_quadratic[1],
                vessel.damping_quadratic[1] / 4.0
            ),
        }
    }

    /// The vessel with the effect switched on.
    fn apply(self, vessel: &mut Vessel, clean: &Campaign) {
        match self {
            Concealed::Clean => {}
            Concealed::Current => vessel.current_ned = Vector3::new(0.25, 0.15, 0.0),
            Concealed::Tether => {
                let (sum, n) = clean.runs.iter().fold((0.0, 0usize), |(s, n), r| {
                    let c = r.log.tau.column(1);
                    (s + c.iter().map(|x| x * x).sum::<f64>(), n + c.len())
                });
                let size = 0.3 * (sum / n.max(1) as f64).sqrt();
                let bearing = (seed_bearing(vessel.mass)).to_radians();
                vessel.tether_ned = Vector3::new(size * bearing.cos(), size * bearing.sin(), 0.0);
            }
            Concealed::Lag => vessel.actuator.lag_s = Some(Vector6::repeat(0.4)),
            Concealed::Saturation => {
                let peak = clean
                    .runs
                    .iter()
                    .map(|r| r.log.tau.column(2).amax())
                    .fold(0.0, f64::max);
                let mut lim = Vector6::repeat(f64::INFINITY);
                lim[2] = 0.6 * peak;
                vessel.actuator.limits = Some(lim);
            }
            Concealed::QuadraticSway => vessel.damping_quadratic[1] *= 4.0,
        }
    }
}

/// A bearing (°) from the drawn vessel, so each seed pulls its own way.
fn seed_bearing(mass: f64) -> f64 {
    (mass * 137.508).rem_euclid(360.0)
}

/// Whether the truth has `e` as physics of its own, beyond the concealed
/// effect: quadratic damping in every DOF (a cubic term approximates it),
/// linear damping growing with |u| (cross-flow |u|ν_i), C(ν)ν from M, g(η),
/// the heave load W − B, and the couplings z_G puts in M_RB. Naming one of
/// these is not a false label, though it is not the concealed effect.
pub fn in_truth(vessel: &Vessel, e: &Effect) -> bool {
    let i = |d: Dof| d.index();
    match *e {
        Effect::QuadraticDamping { dof } | Effect::CubicDamping { dof } => {
            vessel.damping_quadratic[i(dof)] > 0.0
        }
        Effect::CrossDamping {
            dof,
            from: Dof::Surge,
        } => vessel.damping_linear_per_speed[i(dof)] > 0.0,
        Effect::CoriolisFromM | Effect::CoriolisProduct { .. } | Effect::Restoring { .. } => true,
        Effect::ConstantLoad { dof: Dof::Heave } => vessel.w_minus_b != 0.0,
        Effect::Coupling { dof, from } => {
            let m = vessel.m();
            m[(i(dof), i(from))] != 0.0
        }
        _ => false,
    }
}

/// The truth's own value of a coefficient discovery reports for physics
/// the truth has: a Coriolis product's coefficient (the mixed term of the
/// quadratic C(ν)ν, Fossen 2011 eq. 6.43, from the truth's M) or a
/// quadratic damping coefficient.
pub fn truth_coefficient(vessel: &Vessel, e: &Effect) -> Option<f64> {
    match *e {
        Effect::CoriolisProduct { dof, a, b } if a != b => {
            let m = vessel.m();
            let f = |i: Option<usize>, j: Option<usize>| {
                let mut nu = Vector6::zeros();
                for k in [i, j].into_iter().flatten() {
                    nu[k] = 1.0;
                }
                seatrial_truth::forces::coriolis_force(&m, &nu)[dof.index()]
            };
            let (ia, ib) = (Some(a.index()), Some(b.index()));
            Some(f(ia, ib) - f(ia, None) - f(None, ib) + f(None, None))
        }
        Effect::QuadraticDamping { dof } => Some(vessel.damping_quadratic[dof.index()]),
        _ => None,
    }
}

/// One channel of the held-out run: baseline, augmented (if stored) and
/// true model, 1-step and 10 s restarted free run (NRMSE fits).
#[derive(Debug, Clone)]
pub struct GapRow {
    pub channel: String,
    pub base: [Option<f64>; 2],
    pub augmented: Option<[Option<f64>; 2]>,
    pub truth: [Option<f64>; 2],
}

impl GapRow {
    /// Share of the baseline-to-truth gap closed, per metric (None: no gap
    /// worth closing, < 0.02, or no augmented model).
    pub fn closed(&self) -> [Option<f64>; 2] {
        std::array::from_fn(|i| {
            let (b, t) = (self.base[i]?.max(0.0), self.truth[i]?);
            let a = self.augmented?[i]?.max(0.0);
            (t - b > 0.02).then(|| (a - b) / (t - b))
        })
    }
}

/// What discovery made of one case.
#[derive(Debug, Clone)]
pub struct DiscoveryCase {
    pub concealed: Concealed,
    pub seed: u64,
    /// Effects across the grid in the report's order: label, grid speeds,
    /// and whether it names the concealed effect.
    pub named: Vec<(String, usize, Option<bool>)>,
    /// Per named effect (same order): physics the truth has anyway
    /// ([`in_truth`]).
    pub in_truth: Vec<bool>,
    /// Per named effect (same order): its estimates at each grid speed
    /// that chose it, "speed: name value ± std, …".
    pub estimates: Vec<Vec<String>>,
    /// The concealed effect's true size.
    pub truth_size: String,
    /// The first-named effect's values (coefficients, then shape) at each
    /// grid speed that chose it.
    pub first_values: Vec<Vec<f64>>,
    /// Per named effect (same order): whether the stored model keeps it,
    /// and the held-out verdict that decided it.
    pub kept: Vec<(Option<bool>, Option<String>)>,
    pub grid_points: usize,
    pub stored: bool,
    /// The gate's sentence.
    pub verdict: String,
    pub gaps: Vec<GapRow>,
    /// Per named effect (same order): the truth's value of its first
    /// coefficient where the truth has it ([`truth_coefficient`]).
    pub truth_values: Vec<Option<f64>>,
    /// The true vessel, effect switched on.
    pub vessel: Vessel,
    /// Seconds spent flying the truth, identifying, discovering.
    pub secs: [f64; 3],
}

impl DiscoveryCase {
    /// hit: the concealed effect named first; partial: its look-alike
    /// first; on the clean case, "clean ✓" when nothing is named, "truth ✓"
    /// when all that is named is physics the truth has ([`in_truth`]), and
    /// false otherwise; miss otherwise.
    pub fn score(&self) -> &'static str {
        match (self.concealed, self.named.first()) {
            (Concealed::Clean, None) => "clean ✓",
            (Concealed::Clean, Some(_)) if self.false_labels().is_empty() => "truth ✓",
            (Concealed::Clean, Some(_)) => "false",
            (_, Some((_, _, Some(true)))) => "hit",
            (_, Some((_, _, Some(false)))) => "partial",
            _ => "miss",
        }
    }

    /// Named effects that are neither the concealed one (or its
    /// look-alike) nor physics the truth has.
    pub fn false_labels(&self) -> Vec<&str> {
        self.named
            .iter()
            .zip(&self.in_truth)
            .filter(|((_, _, hit), t)| hit.is_none() && !**t)
            .map(|((l, _, _), _)| l.as_str())
            .collect()
    }

    /// False labels the stored model keeps.
    pub fn false_kept(&self) -> Vec<&str> {
        self.named
            .iter()
            .zip(&self.in_truth)
            .zip(&self.kept)
            .filter(|(((_, _, hit), t), k)| {
                hit.is_none() && !**t && k.0 == Some(true) && self.stored
            })
            .map(|(((l, _, _), _), _)| l.as_str())
            .collect()
    }
}

fn fit(measured: &DMatrix<f64>, predicted: &DMatrix<f64>, j: usize, skip: usize) -> Option<f64> {
    let m: Vec<f64> = measured.column(j).iter().skip(skip).copied().collect();
    let p: Vec<f64> = predicted.column(j).iter().skip(skip).copied().collect();
    nrmse_fit(&m, &p)
}

/// Flies seed `seed`'s drawn vessel with `concealed` switched on, identifies
/// it (default λ settings: g(η) estimated), runs the campaign discovery and
/// grades it against the truth.
pub fn discover_case(seed: u64, concealed: Concealed, spec: &CampaignSpec) -> DiscoveryCase {
    let t0 = std::time::Instant::now();
    let mut vessel = Vessel::draw(seed);
    let clean = fly_campaign(&vessel, spec, seed);
    concealed.apply(&mut vessel, &clean);
    let campaign = if concealed == Concealed::Clean {
        clean
    } else {
        fly_campaign(&vessel, spec, seed)
    };
    let t_flown = t0.elapsed().as_secs_f64();
    let Identification {
        profile,
        inputs,
        columns,
        out: base,
    } = identify(&campaign, true, &LambdaCampaignSettings::default());
    let t_identified = t0.elapsed().as_secs_f64();
    let out = discover_campaign(
        &base.document,
        &profile,
        &columns,
        &inputs,
        &base.estimation_run_ids,
        &base.validation_run_ids,
        &DiscoverCampaignSettings::default(),
        &mut NoProgress,
    )
    .expect("discovery runs");
    let discovery_s = t0.elapsed().as_secs_f64() - t_identified;
    let named = out
        .report
        .effects
        .iter()
        .map(|e| {
            (
                e.label.clone(),
                e.grid_speeds_mps.len(),
                concealed.names(&e.effect),
            )
        })
        .collect();
    let in_truth = out
        .report
        .effects
        .iter()
        .map(|e| in_truth(&vessel, &e.effect))
        .collect();
    let estimates = out
        .report
        .effects
        .iter()
        .map(|e| {
            out.report
                .points
                .iter()
                .filter_map(|p| {
                    let f = p.report.findings.iter().find(|f| f.effect == e.effect)?;
                    let est: Vec<String> = f
                        .coefficients
                        .iter()
                        .chain(&f.shape)
                        .map(|c| {
                            let std = c.std.map_or(String::new(), |s| format!(" ± {}", sig3(s)));
                            format!("{} {}{std}", c.name, sig3(c.value))
                        })
                        .collect();
                    Some(format!("{:.2} m/s: {}", p.grid_speed_mps, est.join(", ")))
                })
                .collect()
        })
        .collect();
    let first_values = out
        .report
        .effects
        .first()
        .map(|e| {
            out.report
                .points
                .iter()
                .filter_map(|p| p.report.findings.iter().find(|f| f.effect == e.effect))
                .map(|f| {
                    f.coefficients
                        .iter()
                        .chain(&f.shape)
                        .map(|c| c.value)
                        .collect()
                })
                .collect()
        })
        .unwrap_or_default();
    let kept = out
        .report
        .effects
        .iter()
        .map(|e| (e.kept, e.held_out_verdict.clone()))
        .collect();
    let val_run = campaign.validation_runs()[0];
    let truth = true_predictions(&vessel, &val_run.log);
    let report_of = |v: &[seatrial_core::identification::outcome::RunValidation]| {
        v.iter()
            .find(|r| r.run_id == val_run.meta.name)
            .map(|r| r.report.clone())
    };
    let base_val = report_of(&base.validation).expect("the held-out run is validated");
    let aug_val = out
        .augmented
        .as_ref()
        .and_then(|a| report_of(&a.validation));
    let gaps = base_val
        .channels
        .iter()
        .enumerate()
        .map(|(j, c)| GapRow {
            channel: c.output.clone(),
            base: [c.fit_one_step, c.fit_restarted],
            augmented: aug_val.as_ref().map(|a| {
                let ca = &a.channels[j];
                [ca.fit_one_step, ca.fit_restarted]
            }),
            truth: [
                fit(&val_run.log.nu, &truth.one_step, j, 1),
                fit(&val_run.log.nu, &truth.restarted_10s, j, 0),
            ],
        })
        .collect();
    DiscoveryCase {
        concealed,
        seed,
        named,
        in_truth,
        estimates,
        truth_size: concealed.truth_text(&vessel),
        first_values,
        truth_values: out
            .report
            .effects
            .iter()
            .map(|e| truth_coefficient(&vessel, &e.effect))
            .collect(),
        vessel: vessel.clone(),
        kept,
        grid_points: spec.grid_speeds.len(),
        stored: out.augmented.is_some(),
        verdict: out.report.summary.last().cloned().unwrap_or_default(),
        gaps,
        secs: [t_flown, t_identified - t_flown, discovery_s],
    }
}

/// The table of cases: one line each, then the gap rows of channels with a
/// gap.
pub fn format_cases(cases: &[DiscoveryCase]) -> String {
    let mut s = format!(
        "{:<24} {:>4}  {:<8} {:<7} {:<60} {:>18}\n",
        "case", "seed", "score", "stored", "named (grid points)", "fly/identify/discover s"
    );
    for c in cases {
        let named: Vec<String> = c
            .named
            .iter()
            .take(4)
            .map(|(l, n, _)| format!("{l} ({n}/{})", c.grid_points))
            .collect();
        s += &format!(
            "{:<24} {:>4}  {:<8} {:<7} {:<60} {:>5.0}/{:>5.0}/{:>5.1}\n",
            c.concealed.name(),
            c.seed,
            c.score(),
            if c.stored { "yes" } else { "no" },
            if named.is_empty() {
                "—".to_string()
            } else {
                named.join("; ")
            },
            c.secs[0],
            c.secs[1],
            c.secs[2]
        );
        for g in &c.gaps {
            let closed = g.closed();
            if closed.iter().all(Option::is_none) {
                continue;
            }
            let f = |v: Option<f64>| v.map_or("—".into(), |x| format!("{x:.3}"));
            let pct = |v: Option<f64>| v.map_or("—".into(), |x| format!("{:.0} %", 100.0 * x));
            s += &format!(
                "    {:<2} 1-step {} → {} (truth {}, closed {}); 10 s free run {} → {} (truth {}, closed {})\n",
                g.channel,
                f(g.base[0]),
                f(g.augmented.and_then(|a| a[0])),
                f(g.truth[0]),
                pct(closed[0]),
                f(g.base[1]),
                f(g.augmented.and_then(|a| a[1])),
                f(g.truth[1]),
                pct(closed[1]),
            );
        }
        let kept: Vec<&str> = c
            .named
            .iter()
            .zip(&c.kept)
            .filter(|(_, k)| k.0 == Some(true))
            .map(|(n, _)| n.0.as_str())
            .collect();
        if c.stored {
            s += &format!("    kept: {}\n", kept.join("; "));
        }
        if let (Some((label, _, _)), Some(est)) = (c.named.first(), c.estimates.first()) {
            s += &format!(
                "    first named, {label}: {} — truth: {}\n",
                est.join("; "),
                c.truth_size
            );
        }
        if std::env::var_os("ESTIMATES").is_some() {
            for ((label, _, _), est) in c.named.iter().zip(&c.estimates).skip(1) {
                s += &format!("    also {label}: {}\n", est.join("; "));
            }
        }
        for (((label, _, _), est), t) in c.named.iter().zip(&c.estimates).zip(&c.truth_values) {
            if let Some(t) = t {
                s += &format!(
                    "    in the truth, {label}: {} — truth {}\n",
                    est.join("; "),
                    sig3(*t)
                );
            }
        }
        let false_named = c.false_labels();
        if !false_named.is_empty() {
            s += &format!(
                "    named, absent from the truth: {} (kept: {})\n",
                false_named.join("; "),
                if c.false_kept().is_empty() {
                    "none".to_string()
                } else {
                    c.false_kept().join("; ")
                }
            );
        }
        if let (Some((label, _, _)), Some((Some(false), Some(why)))) =
            (c.named.first(), c.kept.first())
        {
            s += &format!("    first named, left out: {label}: {why}\n");
        }
        s += &format!("    {}\n", c.verdict);
    }
    s
}
