//! The run list and each run's set-point program.

use nalgebra::Vector6;

use super::external::Schedule;
use super::{CampaignSpec, Dof, Role};
use crate::controller::Reference;
use crate::rng::Rng;
use crate::signals::{Signal, SignalKind, Staircase};

/// Set-points over run time t (s; t < 0 is the unlogged pre-roll).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Program {
    /// Hold u₀, everything else at zero.
    Hold { u0: f64 },
    /// Hold u₀ and excite one DOF: a velocity set-point for u, v, w, r, an
    /// attitude set-point for φ, θ.
    Excite { u0: f64, dof: Dof, signal: Signal },
    /// A forward-speed staircase with other DOFs excited on top.
    Validation {
        stairs: Staircase,
        extra: Vec<(Dof, Signal)>,
    },
    /// An external reference schedule (see [`super::external`]).
    External(Box<Schedule>),
}

fn add(r: &mut Reference, dof: Dof, value: f64) {
    match dof {
        Dof::Roll => r.phi += value,
        Dof::Pitch => r.theta += value,
        d => r.nu[d.index()] += value,
    }
}

impl Program {
    pub(crate) fn reference(&self, t: f64) -> Reference {
        let mut r = Reference {
            nu: Vector6::zeros(),
            phi: 0.0,
            theta: 0.0,
        };
        match self {
            Program::Hold { u0 } => r.nu[0] = *u0,
            Program::Excite { u0, dof, signal } => {
                r.nu[0] = *u0;
                add(&mut r, *dof, signal.at(t));
            }
            Program::Validation { stairs, extra } => {
                r.nu[0] = stairs.at(t);
                for (d, s) in extra {
                    add(&mut r, *d, s.at(t));
                }
            }
            Program::External(s) => return s.reference(t),
        }
        r
    }

    /// Open-loop forces at run time `t`: `Some(τᵢ)` replaces the
    /// autopilot's command in DOF i (only external schedules have any).
    pub(crate) fn open_loop(&self, t: f64) -> [Option<f64>; 6] {
        match self {
            Program::External(s) => s.open_loop(t),
            _ => [None; 6],
        }
    }
}

/// One run to fly.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RunPlan {
    pub name: String,
    pub role: Role,
    pub grid_speed: Option<f64>,
    pub excited: Vec<Dof>,
    pub signal: SignalKind,
    pub amplitude: f64,
    pub switch_time_s: Option<f64>,
    pub speeds: Vec<f64>,
    pub duration_s: f64,
    /// Unlogged flight before the first log stamp (s).
    pub preroll_s: f64,
    /// Initial depth (m) and heading (rad); None: drawn from the run seed.
    pub start_pose: Option<(f64, f64)>,
    pub program: Program,
}

/// Rounds to the 10 Hz log grid.
fn tenth(x: f64) -> f64 {
    (x * 10.0).round() / 10.0
}

fn excitation(kind: SignalKind, amp: f64, rng: &mut Rng) -> Signal {
    match kind {
        SignalKind::Square => Signal::Square {
            amp,
            half_period_s: tenth(rng.range(8.0, 15.0)),
            start: rng.sign(),
        },
        _ => Signal::prbs(amp, tenth(rng.range(2.0, 5.0)), 1 + rng.below(511) as u16),
    }
}

/// The campaign's runs in flying order: per grid speed a static run and the
/// dynamic runs (square and PRBS alternating over DOFs and grid points), then
/// the validation run.
pub(crate) fn plan_campaign(spec: &CampaignSpec, rng: &mut Rng) -> Vec<RunPlan> {
    let mut plans = Vec::new();
    for (gi, &u0) in spec.grid_speeds.iter().enumerate() {
        let (lo, hi) = spec.static_duration_s;
        plans.push(RunPlan {
            name: format!("u{u0:.2}_static"),
            role: Role::Static,
            grid_speed: Some(u0),
            excited: vec![],
            signal: SignalKind::Constant,
            amplitude: 0.0,
            switch_time_s: None,
            speeds: vec![u0],
            duration_s: tenth(rng.range(lo, hi)),
            preroll_s: spec.preroll_s,
            start_pose: None,
            program: Program::Hold { u0 },
        });
        for &dof in &spec.dynamic_dofs {
            let kind = if (gi + dof.index()) % 2 == 0 {
                SignalKind::Square
            } else {
                SignalKind::Prbs
            };
            let mut amp = spec.amplitude[dof.index()] * rng.range(0.8, 1.2);
            if dof == Dof::Surge {
                amp = amp.min(0.6 * u0);
            }
            let signal = excitation(kind, amp, rng);
            let (lo, hi) = spec.dynamic_duration_s;
            plans.push(RunPlan {
                name: format!("u{u0:.2}_dyn_{}_{}", dof.label(), kind.label()),
                role: Role::Dynamic,
                grid_speed: Some(u0),
                excited: vec![dof],
                signal: kind,
                amplitude: amp,
                switch_time_s: Some(signal.switch_time_s()),
                speeds: vec![u0],
                duration_s: tenth(rng.range(lo, hi)),
                preroll_s: spec.preroll_s,
                start_pose: None,
                program: Program::Excite { u0, dof, signal },
            });
        }
    }
    let mut levels = spec.validation_speeds();
    rng.shuffle(&mut levels);
    let duration = tenth(spec.validation_duration_s);
    let extra = Dof::ALL[1..]
        .iter()
        .map(|&d| {
            let amp = 0.6 * spec.amplitude[d.index()];
            let bit = tenth(rng.range(3.0, 8.0));
            (d, Signal::prbs(amp, bit, 1 + rng.below(511) as u16))
        })
        .collect();
    plans.push(RunPlan {
        name: "validation".into(),
        role: Role::Validation,
        grid_speed: None,
        excited: Dof::ALL.to_vec(),
        signal: SignalKind::Mixed,
        amplitude: 0.0,
        switch_time_s: None,
        speeds: levels.clone(),
        duration_s: duration,
        preroll_s: spec.preroll_s,
        start_pose: None,
        program: Program::Validation {
            stairs: Staircase {
                segment_s: duration / levels.len() as f64,
                levels,
                ramp_rate: 0.05,
            },
            extra,
        },
    });
    plans
}
