//! The deciding experiment: when two hypotheses explain the data about
//! equally well, simulate both fitted models on a catalogue of runs the
//! vessel can fly (open-loop τ per the planner's force columns, within the
//! profile's force, rate and velocity limits, at one or four headings) and
//! propose the run on which their predictions differ most, in units of the
//! sensor noise.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::data::Record;
use super::model::AugmentedModel;
use crate::planning::plan::ChannelPlan;
use crate::planning::waveform::Waveform;
use crate::planning::{Dof, ExperimentFamily, SignalKind, VesselProfile};

/// A proposed run in planner terms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ExperimentProposal {
    /// Labels of the two hypotheses it separates.
    pub separates: [String; 2],
    /// Static (held force; `signal` is then only nominal) or dynamic family.
    pub family: ExperimentFamily,
    /// The excited DOF.
    pub dof: Dof,
    /// Signal shape of the excited DOF.
    pub signal: SignalKind,
    /// Forward speed the surge offset gives (predicted, m/s).
    pub grid_speed_mps: f64,
    /// Headings to fly it at (deg, one leg each).
    pub headings_deg: Vec<f64>,
    /// Length of each leg (s; at most 1800 in a campaign's `deciding`).
    pub duration_s: f64,
    /// Force columns, as in a planned experiment (`Quantity::Force`).
    pub channels: Vec<ChannelPlan>,
    /// RMS difference of the two predictions over the run, in noise σ.
    pub predicted_separation_sigma: f64,
    /// What the pilot does.
    pub instruction: String,
}

/// A held step (static run) or an excitation signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    Step,
    Square,
    Multisine,
}

struct Design {
    dof: Dof,
    signal: Shape,
    amplitude: f64,
    surge_offset: f64,
    headings: Vec<f64>,
}

/// Samples of a design's force columns (n × DOFs) for one leg.
fn forces(
    p: &VesselProfile,
    dofs: &[Dof],
    d: &Design,
    fs: f64,
    n: usize,
) -> Option<(DMatrix<f64>, Vec<ChannelPlan>)> {
    let mut tau = DMatrix::zeros(n, dofs.len());
    let mut channels = Vec::new();
    for (i, &dof) in dofs.iter().enumerate() {
        let l = p.limits.get(&dof)?;
        let excited = dof == d.dof;
        let offset = if dof == Dof::Surge {
            d.surge_offset * l.max_force
        } else {
            0.0
        };
        let (waveform, amplitude) = if excited {
            let w = match d.signal {
                Shape::Square => Waveform::Square {
                    period_s: 10.0 * l.time_constant_s,
                },
                Shape::Multisine => Waveform::Multisine {
                    f_lo_hz: 0.02 / l.time_constant_s.max(0.1),
                    f_hi_hz: (2.0 / l.time_constant_s).min(0.4 * fs),
                    period_s: n as f64 / fs,
                },
                Shape::Step => Waveform::Step { sign: 1.0 },
            };
            (w, d.amplitude * l.max_force)
        } else {
            (Waveform::Constant, 0.0)
        };
        let raw = waveform.sample(offset, amplitude, fs, n).ok()?;
        let x = crate::signals::rate_limit(&raw, l.max_force_rate, fs, offset);
        for (k, v) in x.iter().enumerate() {
            tau[(k, i)] = v.clamp(-l.max_force, l.max_force);
        }
        channels.push(ChannelPlan {
            column: dof.force_column().into(),
            unit: dof.force_unit().into(),
            dof: Some(dof),
            thruster: None,
            excited,
            waveform,
            offset,
            amplitude,
            limit: l.max_force,
            rate_limit: Some(l.max_force_rate),
            analysis: None,
        });
    }
    Some((tau, channels))
}

/// Proposes the run that best separates models `a` and `b` (both fitted
/// on the same data), or `None` when the profile lacks the model's DOFs or
/// no design keeps both models within the velocity limits.
#[allow(clippy::too_many_arguments)]
pub(crate) fn propose(
    profile: &VesselProfile,
    a: &AugmentedModel,
    b: &AugmentedModel,
    labels: [String; 2],
    focus: &[Dof],
    noise_sigma: &[f64],
    heading0: f64,
    h: f64,
) -> Option<ExperimentProposal> {
    let dofs = &a.dofs;
    let leg_s = 60.0;
    let n = (leg_s / h).round() as usize;
    let fs = 1.0 / h;
    let mut best: Option<(f64, Design, Vec<ChannelPlan>, f64)> = None;
    let mut excite: Vec<Dof> = focus.to_vec();
    excite.retain(|d| dofs.contains(d));
    if excite.is_empty() {
        excite = dofs.clone();
    }
    for &dof in &excite {
        for signal in [Shape::Step, Shape::Square, Shape::Multisine] {
            for amplitude in [0.3, 0.6, 0.9] {
                for surge_offset in [0.0, 0.5] {
                    if dof == Dof::Surge && surge_offset > 0.0 && signal == Shape::Step {
                        continue;
                    }
                    for legs in [1usize, 4] {
                        let headings: Vec<f64> = (0..legs)
                            .map(|q| heading0 + q as f64 * std::f64::consts::FRAC_PI_2)
                            .collect();
                        let d = Design {
                            dof,
                            signal,
                            amplitude,
                            surge_offset,
                            headings,
                        };
                        let Some((tau, channels)) = forces(profile, dofs, &d, fs, n) else {
                            continue;
                        };
                        let mut acc = 0.0;
                        let mut cnt = 0usize;
                        let mut speed = 0.0;
                        let mut feasible = true;
                        for &psi in &d.headings {
                            let mut eta = DMatrix::zeros(n, 6);
                            eta.column_mut(5).fill(psi);
                            let rec = Record {
                                name: String::new(),
                                h,
                                tau: tau.clone(),
                                nu: DMatrix::zeros(n, dofs.len()),
                                eta,
                            };
                            let ya = a.simulate(&rec);
                            let yb = b.simulate(&rec);
                            for (i, dd) in dofs.iter().enumerate() {
                                let vmax = profile
                                    .limits
                                    .get(dd)
                                    .map_or(f64::INFINITY, |l| l.max_velocity);
                                let s = noise_sigma.get(i).copied().unwrap_or(1.0).max(1e-12);
                                for k in 0..n {
                                    if ya[(k, i)].abs() > 1.2 * vmax
                                        || yb[(k, i)].abs() > 1.2 * vmax
                                    {
                                        feasible = false;
                                    }
                                    let e = (ya[(k, i)] - yb[(k, i)]) / s;
                                    acc += e * e;
                                    cnt += 1;
                                }
                                if *dd == Dof::Surge {
                                    speed += ya.column(i).mean() / d.headings.len() as f64;
                                }
                            }
                        }
                        if !feasible || cnt == 0 {
                            continue;
                        }
                        let sep = (acc / cnt as f64).sqrt();
                        // A four-leg run must separate clearly better to be worth its time.
                        let score = if legs > 1 { sep / 1.25 } else { sep };
                        if best.as_ref().is_none_or(|b| score > b.0) {
                            best = Some((score, d, channels, speed));
                        }
                    }
                }
            }
        }
    }
    let (score, d, channels, speed) = best?;
    let sep = if d.headings.len() > 1 {
        score * 1.25
    } else {
        score
    };
    let (family, signal) = match d.signal {
        Shape::Step => (ExperimentFamily::Static, SignalKind::Square),
        Shape::Square => (ExperimentFamily::Dynamic, SignalKind::Square),
        Shape::Multisine => (ExperimentFamily::Dynamic, SignalKind::Multisine),
    };
    let headings_deg: Vec<f64> = d
        .headings
        .iter()
        .map(|x| x.to_degrees().rem_euclid(360.0))
        .collect();
    let lim = profile.limits.get(&d.dof).map_or(0.0, |l| l.max_force);
    let what = if family == ExperimentFamily::Static {
        format!(
            "hold {} = {:.0} {} constant",
            d.dof.force_column(),
            d.amplitude * lim,
            d.dof.force_unit()
        )
    } else {
        format!(
            "excite {} with a {} of amplitude {:.0} {}",
            d.dof.name(),
            if d.signal == Shape::Square {
                "square wave"
            } else {
                "multisine"
            },
            d.amplitude * lim,
            d.dof.force_unit()
        )
    };
    let instruction = format!(
        "At {:.2} m/s forward speed, {what} for {:.0} s{}; the two hypotheses then predict velocities {:.1} σ apart.",
        speed,
        leg_s,
        if headings_deg.len() > 1 {
            format!(
                " at each of the headings {} °",
                headings_deg
                    .iter()
                    .map(|h| format!("{h:.0}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        } else {
            format!(" at heading {:.0} °", headings_deg[0])
        },
        sep
    );
    Some(ExperimentProposal {
        separates: labels,
        family,
        dof: d.dof,
        signal,
        grid_speed_mps: speed,
        headings_deg,
        duration_s: leg_s,
        channels,
        predicted_separation_sigma: sep,
        instruction,
    })
}
