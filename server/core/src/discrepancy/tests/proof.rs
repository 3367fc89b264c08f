//! The acceptance proof: one effect (or two) concealed from the baseline,
//! drawn DOF and magnitude from seeded ranges; discovery must name the
//! right effect first, name nothing on a clean vessel, and close ≥ 80 % of
//! the validation free-run NRMSE gap between baseline and truth.

use std::time::Instant;

use super::scenario::{Scenario, clean_truth, command_share, reach, scenario, true_model};
use crate::discrepancy::candidates::Family;
use crate::discrepancy::discover::{DiscoverySettings, discover};
use crate::discrepancy::report::DiscoveryReport;
use crate::estimation::NoProgress;
use crate::planning::Dof;
use crate::planning::examples::surveyor_rov;
use crate::rng::{SplitMix64, mix};
use crate::simulation::rov::{Current, RovTruth};
use crate::validation::nrmse_fit;

/// A concealed effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Concealed {
    QuadraticDamping,
    Coriolis,
    Tether,
    Current,
    Lag,
    Delay,
    Saturation,
}

impl Concealed {
    fn family(self) -> Family {
        match self {
            Concealed::QuadraticDamping => Family::QuadraticDamping,
            Concealed::Coriolis => Family::Coriolis,
            Concealed::Tether => Family::ConstantLoad,
            Concealed::Current => Family::Current,
            Concealed::Lag => Family::ActuatorLag,
            Concealed::Delay => Family::InputDelay,
            Concealed::Saturation => Family::Saturation,
        }
    }

    /// Puts the effect into `t` with a DOF and magnitude drawn from `rng`;
    /// returns the affected DOFs (empty: several, any is right).
    fn apply(self, t: &mut RovTruth, rng: &mut SplitMix64, avoid: Option<Dof>) -> Vec<Dof> {
        let p = surveyor_rov();
        let reach = reach(&p, &clean_truth());
        let d_lin = t.damping.at(0.0);
        let mut pick = |set: &[Dof]| loop {
            let d = set[(rng.uniform() * set.len() as f64) as usize % set.len()];
            if Some(d) != avoid {
                return d;
            }
        };
        match self {
            Concealed::QuadraticDamping => {
                let d = pick(&[Dof::Surge, Dof::Sway, Dof::Heave, Dof::Yaw]);
                let i = d.index();
                // |ν|ν force equal to 40–80 % of the linear one at 0.4 of the velocity limit.
                let v = 0.4 * p.limit(d).max_velocity;
                t.quadratic_damping[i] = rng.uniform_in(0.4, 0.8) * d_lin[(i, i)] / v;
                vec![d]
            }
            Concealed::Coriolis => {
                t.coriolis = true;
                vec![]
            }
            Concealed::Tether => {
                // A pitch moment (the thesis's τ_θ) or a body force in sway
                // or heave, 10–30 % of the campaign's reach.
                let d = pick(&[Dof::Pitch, Dof::Sway, Dof::Heave]);
                let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                let load = sign * rng.uniform_in(0.1, 0.3) * reach[d.index()];
                match d {
                    Dof::Pitch => t.tether.pitch_moment = load,
                    _ => t.tether.body_force[d.index()] = load,
                }
                vec![d]
            }
            Concealed::Current => {
                let speed = rng.uniform_in(0.1, 0.25);
                let dir = rng.uniform_in(0.0, std::f64::consts::TAU);
                t.current = Current::Constant {
                    ned: [speed * dir.cos(), speed * dir.sin(), 0.0],
                };
                vec![Dof::Surge, Dof::Sway]
            }
            Concealed::Lag => {
                let d = pick(&Dof::ALL);
                t.actuators.time_constants[d.index()] = rng.uniform_in(0.3, 1.0);
                vec![d]
            }
            Concealed::Delay => {
                // The simulator delays every DOF's command alike (a
                // transport delay of the command link).
                t.actuators.delay_samples = 2 + (rng.uniform() * 5.0) as usize;
                vec![]
            }
            Concealed::Saturation => {
                let d = pick(&Dof::ALL);
                // Clip at 60–80 % of the largest command of the campaign,
                // so the effect is material.
                t.actuators.saturation[d.index()] =
                    rng.uniform_in(0.6, 0.8) * command_share(d) * reach[d.index()];
                vec![d]
            }
        }
    }
}

/// Outcome of one case.
pub struct Outcome {
    pub report: DiscoveryReport,
    pub expected: Vec<(Family, Vec<Dof>)>,
    pub gap_closed: Option<f64>,
    pub seconds: f64,
}

/// Runs discovery on a truth with `effects` concealed (seeded draws). The
/// gap is measured against the truth written in the model's form, driven
/// by the same recorded η, so only the concealed physics counts.
pub fn run_case(effects: &[Concealed], seed: u64) -> Outcome {
    let mut rng = SplitMix64::new(mix(seed ^ 0xD15C));
    let mut t = clean_truth();
    let mut expected = Vec::new();
    let mut used: Option<Dof> = None;
    for &e in effects {
        let dofs = e.apply(&mut t, &mut rng, used);
        used = dofs.first().copied();
        expected.push((e.family(), dofs));
    }
    let s: Scenario = scenario(t, seed, 3, 1, 120.0);
    let settings = DiscoverySettings {
        vessel: Some(s.profile.clone()),
        ..DiscoverySettings::default()
    };
    let t0 = Instant::now();
    let report =
        discover(&s.baseline, &s.est, &s.val, &settings, &mut NoProgress).expect("discovery runs");
    let seconds = t0.elapsed().as_secs_f64();
    // Gap on the channels the truth's free run fits clearly better.
    let val = &s.val[0];
    let truth_sim = true_model(&s.truth).simulate(val);
    let (mut closed, mut gap) = (0.0, 0.0);
    for (i, c) in report.validation.iter().enumerate() {
        let t_fit = nrmse_fit(val.nu.column(i).as_slice(), truth_sim.column(i).as_slice());
        if let (Some(b), Some(a), Some(tf)) = (c.before.free_run, c.after.free_run, t_fit)
            && tf - b > 0.02
        {
            gap += tf - b;
            closed += a - b;
        }
    }
    Outcome {
        report,
        expected,
        gap_closed: (gap > 0.0).then(|| closed / gap),
        seconds,
    }
}

/// The check of one outcome; Err names what failed.
pub fn judge(o: &Outcome) -> Result<(), String> {
    let f = &o.report.findings;
    if o.expected.is_empty() {
        if !f.is_empty() {
            return Err(format!(
                "clean case named {:?}",
                f.iter().map(|x| &x.label).collect::<Vec<_>>()
            ));
        }
        return Ok(());
    }
    // Each concealed effect must be named, and the first finding must be one of them.
    let matches = |fi: &crate::discrepancy::report::Finding, (fam, dofs): &(Family, Vec<Dof>)| {
        fi.effect.family() == *fam && (dofs.is_empty() || fi.dofs.iter().any(|d| dofs.contains(d)))
    };
    let first = f.first().ok_or("nothing named")?;
    if !o.expected.iter().any(|e| matches(first, e)) {
        return Err(format!(
            "first named {} (expected {:?})",
            first.label, o.expected
        ));
    }
    for e in &o.expected {
        if !f.iter().any(|fi| matches(fi, e)) {
            return Err(format!(
                "{e:?} not named; named {:?}",
                f.iter().map(|x| &x.label).collect::<Vec<_>>()
            ));
        }
    }
    match o.gap_closed {
        Some(g) if g < 0.8 => Err(format!("closed only {:.0} % of the gap", 100.0 * g)),
        _ => Ok(()),
    }
}

fn table(cases: &[(&str, Vec<Concealed>)], seeds: &[u64]) {
    let mut failures = Vec::new();
    eprintln!(
        "{:<22} {:>5}  {:<48} {:>8} {:>7}",
        "case", "seed", "named first (DOFs)", "gap", "time s"
    );
    for (name, effects) in cases {
        for &seed in seeds {
            let o = run_case(effects, seed);
            let first = o.report.findings.first().map_or("—".to_string(), |f| {
                format!(
                    "{} ({})",
                    f.label,
                    f.dofs
                        .iter()
                        .map(|d| d.name())
                        .collect::<Vec<_>>()
                        .join(",")
                )
            });
            eprintln!(
                "{:<22} {:>5}  {:<48} {:>8} {:>7.2}",
                name,
                seed,
                first,
                o.gap_closed
                    .map_or("–".into(), |g| format!("{:.0} %", 100.0 * g)),
                o.seconds
            );
            if let Err(e) = judge(&o) {
                eprintln!("    FAIL: {e}");
                for s in &o.report.summary {
                    eprintln!("      {s}");
                }
                failures.push(format!("{name} seed {seed}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

fn cases() -> Vec<(&'static str, Vec<Concealed>)> {
    use Concealed::*;
    vec![
        ("clean", vec![]),
        ("quadratic damping", vec![QuadraticDamping]),
        ("Coriolis", vec![Coriolis]),
        ("tether moment", vec![Tether]),
        ("current", vec![Current]),
        ("actuator lag", vec![Lag]),
        ("input delay", vec![Delay]),
        ("saturation", vec![Saturation]),
        ("quad + lag", vec![QuadraticDamping, Lag]),
        ("tether + delay", vec![Tether, Delay]),
        ("current + saturation", vec![Current, Saturation]),
    ]
}

#[test]
fn proof_table_one_seed() {
    table(&cases(), &[11]);
}

#[test]
#[ignore]
fn proof_table_more_seeds() {
    table(&cases(), &[12, 13, 14, 15]);
}
