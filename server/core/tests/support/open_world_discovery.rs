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
    /// A constant sway force of 0.05 N per kg of the vessel's mass (250 N
    /// on a 5 t ROV), as a tether pulls.
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
    /// right place (`Some(false)`: lag ↔ delay), or something else (`None`).
    pub fn names(self, e: &Effect) -> Option<bool> {
        match (self, e) {
            (Concealed::Current, Effect::Current) => Some(true),
            (Concealed::Tether, Effect::ConstantLoad { dof: Dof::Sway }) => Some(true),
            (Concealed::Lag, Effect::ActuatorLag { .. }) => Some(true),
            (Concealed::Lag, Effect::InputDelay { .. } | Effect::CommonInputDelay) => Some(false),
            (Concealed::Saturation, Effect::Saturation { dof: Dof::Heave }) => Some(true),
            (Concealed::QuadraticSway, Effect::QuadraticDamping { dof: Dof::Sway }) => Some(true),
            _ => None,
        }
    }

    /// The vessel with the effect switched on.
    fn apply(self, vessel: &mut Vessel, clean: &Campaign) {
        match self {
            Concealed::Clean => {}
            Concealed::Current => vessel.current_ned = Vector3::new(0.25, 0.15, 0.0),
            Concealed::Tether => vessel.tether[1] = 0.05 * vessel.mass,
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
    /// Per named effect (same order): whether the stored model keeps it,
    /// and the held-out verdict that decided it.
    pub kept: Vec<(Option<bool>, Option<String>)>,
    pub grid_points: usize,
    pub stored: bool,
    /// The gate's sentence.
    pub verdict: String,
    pub gaps: Vec<GapRow>,
    /// Seconds spent flying the truth, identifying, discovering.
    pub secs: [f64; 3],
}

impl DiscoveryCase {
    /// hit: the concealed effect named first; partial: its look-alike
    /// first; false: a physical label on the clean case; miss otherwise.
    pub fn score(&self) -> &'static str {
        match (self.concealed, self.named.first()) {
            (Concealed::Clean, None) => "clean ✓",
            (Concealed::Clean, Some(_)) => "false",
            (_, Some((_, _, Some(true)))) => "hit",
            (_, Some((_, _, Some(false)))) => "partial",
            _ => "miss",
        }
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
        if let (Some((label, _, _)), Some((Some(false), Some(why)))) =
            (c.named.first(), c.kept.first())
        {
            s += &format!("    first named, left out: {label}: {why}\n");
        }
        s += &format!("    {}\n", c.verdict);
    }
    s
}
