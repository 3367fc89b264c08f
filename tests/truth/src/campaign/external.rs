//! Flying EXTERNAL reference schedules — experiments another tool designed —
//! with the truth's own vessel, 20 Hz autopilot, 10 Hz logger and noise.
//!
//! A schedule gives, per DOF, a [`Channel`] sampled at `rate_hz`; it is held
//! zero-order between samples and read at the autopilot's 20 Hz clock. The
//! run starts in trim: an unlogged lead-in of `lead_in_s` holds the first
//! sample of every channel, then `samples / rate_hz` seconds are logged at
//! 10 Hz into the same [`Run`] (log, nav file, [`TruthRecord`](super::TruthRecord))
//! as the truth's own runs, through the same flying routine.
//!
//! Roll and pitch: the autopilot holds attitude (PD on φ, θ), it has no rate
//! loop. [`Channel::Velocity`] on roll or pitch is therefore a RATE reference
//! p_ref or q_ref flown as the attitude reference φ_ref(t) = ∫₀ᵗ p_ref dt
//! (exact for the held samples, from φ_ref = 0 at the first log stamp) with
//! p_ref as the D-term's rate feed-forward (τ = Kp(φ_ref − φ) + Kd(p_ref − p));
//! φ̇ = p only near level trim, so keep the integrated attitude small. During
//! the lead-in such a channel holds φ_ref = 0, p_ref = 0 (trim), not its first
//! rate. [`Channel::Attitude`] is an angle reference (rad).

use nalgebra::Vector6;

use super::fly::{Flight, draw_start_pose, run_seed, start_pose_rng, start_times};
use super::plan::{Program, RunPlan, plan_campaign};
use super::{CampaignSpec, Dof, NoiseSpec, Role, Run};
use crate::controller::{CONTROL_DT, ControllerConfig, Envelope, Reference};
use crate::plant::Plant;
use crate::rng::{Rng, derive_seed};
use crate::signals::SignalKind;
use crate::vessel::Vessel;

/// What drives one DOF during an external run, sampled at the run's
/// `rate_hz` and held zero-order between samples.
#[derive(Debug, Clone, PartialEq)]
pub enum Channel {
    /// Velocity reference: ν_ref for u, v, w (m/s) and r (rad/s) into the
    /// PI loops; for roll and pitch a rate reference p_ref, q_ref (rad/s)
    /// flown as an integrated attitude reference (see the module docs).
    Velocity(Vec<f64>),
    /// Attitude reference φ_ref or θ_ref (rad); roll and pitch only.
    Attitude(Vec<f64>),
    /// Open-loop generalized force τ (N or N·m): it replaces the autopilot's
    /// command in this DOF (feedback and ĝ feed-forward), unclipped by the
    /// autopilot's limits; the vessel's actuator model (if any) still acts.
    Force(Vec<f64>),
    /// The autopilot holds the DOF at zero (velocity 0; attitude 0 in roll
    /// and pitch).
    Hold,
}

impl Channel {
    /// The samples (None for [`Channel::Hold`]).
    pub fn samples(&self) -> Option<&[f64]> {
        match self {
            Channel::Velocity(x) | Channel::Attitude(x) | Channel::Force(x) => Some(x),
            Channel::Hold => None,
        }
    }

    /// `velocity`, `attitude`, `force`, `hold`.
    pub fn label(&self) -> &'static str {
        match self {
            Channel::Velocity(_) => "velocity",
            Channel::Attitude(_) => "attitude",
            Channel::Force(_) => "force",
            Channel::Hold => "hold",
        }
    }
}

/// One externally designed run.
#[derive(Debug, Clone, PartialEq)]
pub struct ExternalRun {
    /// File stem of the run.
    pub name: String,
    /// Sample rate of the channels (Hz).
    pub rate_hz: f64,
    /// Per DOF in Fossen's order (surge, sway, heave, roll, pitch, yaw).
    /// Every non-[`Channel::Hold`] channel has the same number of samples N;
    /// the logged duration is N / `rate_hz` (rounded to the 10 Hz log).
    pub channels: [Channel; 6],
    /// Unlogged flight holding the first samples, for the loops to settle (s).
    pub lead_in_s: f64,
    /// Initial depth z (m). Fixed per run (not drawn from the noise seed), so
    /// flights of one run with different seeds differ in noise only.
    pub start_depth_m: f64,
    /// Initial heading ψ (rad).
    pub start_heading_rad: f64,
}

impl ExternalRun {
    /// A run with a 20 s lead-in starting at 50 m depth, heading 0.
    pub fn new(name: impl Into<String>, rate_hz: f64, channels: [Channel; 6]) -> Self {
        ExternalRun {
            name: name.into(),
            rate_hz,
            channels,
            lead_in_s: 20.0,
            start_depth_m: 50.0,
            start_heading_rad: 0.0,
        }
    }

    /// Number of samples N of the sampled channels.
    ///
    /// # Panics
    /// On an invalid schedule (see [`ExternalRun::validate`]).
    pub fn samples(&self) -> usize {
        self.validate();
        self.channels
            .iter()
            .find_map(|c| c.samples().map(<[f64]>::len))
            .unwrap_or(0)
    }

    /// N / `rate_hz` (s).
    pub fn duration_s(&self) -> f64 {
        self.samples() as f64 / self.rate_hz
    }

    /// Checks the schedule.
    ///
    /// # Panics
    /// With a message naming the run if `rate_hz` is not positive and
    /// finite, `lead_in_s` is negative, no channel has samples, the sampled
    /// channels differ in length or hold a non-finite value, or an
    /// [`Channel::Attitude`] channel drives a DOF other than roll or pitch.
    pub fn validate(&self) {
        let n = &self.name;
        assert!(
            self.rate_hz.is_finite() && self.rate_hz > 0.0,
            "external run {n}: rate_hz must be positive, got {}",
            self.rate_hz
        );
        assert!(
            self.lead_in_s.is_finite() && self.lead_in_s >= 0.0,
            "external run {n}: lead_in_s must be ≥ 0, got {}",
            self.lead_in_s
        );
        let mut len = None;
        for (c, dof) in self.channels.iter().zip(Dof::ALL) {
            if matches!(c, Channel::Attitude(_)) {
                assert!(
                    matches!(dof, Dof::Roll | Dof::Pitch),
                    "external run {n}: an attitude channel drives {}; only roll and pitch have \
                     attitude loops (use Velocity or Force)",
                    dof.label()
                );
            }
            let Some(x) = c.samples() else { continue };
            assert!(
                !x.is_empty(),
                "external run {n}: the {} channel has no samples",
                dof.label()
            );
            assert!(
                x.iter().all(|v| v.is_finite()),
                "external run {n}: the {} channel holds a non-finite sample",
                dof.label()
            );
            match len {
                None => len = Some(x.len()),
                Some(l) => assert!(
                    l == x.len(),
                    "external run {n}: the {} channel has {} samples, earlier channels {l}",
                    dof.label(),
                    x.len()
                ),
            }
        }
        assert!(
            len.is_some(),
            "external run {n}: every channel is Hold; at least one must carry samples (the \
             duration is their count / rate_hz)"
        );
    }
}

/// A validated schedule ready to be read at run time.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Schedule {
    rate_hz: f64,
    n: usize,
    channels: [Channel; 6],
    /// For rate channels on roll (0) and pitch (1): ∫ of the held rate up to
    /// the start of each sample.
    integral: [Vec<f64>; 2],
}

impl Schedule {
    fn new(run: &ExternalRun) -> Self {
        let n = run.samples();
        let integral = [3usize, 4].map(|i| match &run.channels[i] {
            Channel::Velocity(x) => {
                let mut acc = 0.0;
                let mut out = Vec::with_capacity(n);
                for v in x {
                    out.push(acc);
                    acc += v / run.rate_hz;
                }
                out
            }
            _ => Vec::new(),
        });
        Schedule {
            rate_hz: run.rate_hz,
            n,
            channels: run.channels.clone(),
            integral,
        }
    }

    /// The held sample at run time `t` and the time since it started (None
    /// in the lead-in, t < 0).
    fn sample(&self, t: f64) -> Option<(usize, f64)> {
        if t < 0.0 {
            return None;
        }
        let k = ((t * self.rate_hz + 1e-9).floor() as usize).min(self.n - 1);
        Some((k, t - k as f64 / self.rate_hz))
    }

    /// The attitude reference and rate feed-forward of roll/pitch DOF `i`.
    fn attitude(&self, i: usize, t: f64) -> (f64, f64) {
        let at = self.sample(t);
        match (&self.channels[i], at) {
            (Channel::Attitude(x), Some((k, _))) => (x[k], 0.0),
            (Channel::Attitude(x), None) => (x[0], 0.0),
            (Channel::Velocity(x), Some((k, dt))) => (self.integral[i - 3][k] + x[k] * dt, x[k]),
            _ => (0.0, 0.0),
        }
    }

    /// The autopilot's set-points at run time `t`.
    pub(crate) fn reference(&self, t: f64) -> Reference {
        let k = self.sample(t).map_or(0, |(k, _)| k);
        let mut nu = Vector6::zeros();
        for i in [0, 1, 2, 5] {
            if let Channel::Velocity(x) = &self.channels[i] {
                nu[i] = x[k];
            }
        }
        let (phi, p) = self.attitude(3, t);
        let (theta, q) = self.attitude(4, t);
        nu[3] = p;
        nu[4] = q;
        Reference { nu, phi, theta }
    }

    /// The open-loop forces at run time `t`.
    pub(crate) fn open_loop(&self, t: f64) -> [Option<f64>; 6] {
        let k = self.sample(t).map_or(0, |(k, _)| k);
        std::array::from_fn(|i| match &self.channels[i] {
            Channel::Force(x) => Some(x[k]),
            _ => None,
        })
    }

    /// Largest |φ_ref| (i = 3) or |θ_ref| (i = 4) the channel asks for.
    fn max_attitude(&self, i: usize) -> f64 {
        match &self.channels[i] {
            Channel::Attitude(x) => max_abs(x),
            Channel::Velocity(x) => {
                let end = self.integral[i - 3].last().copied().unwrap_or(0.0)
                    + x.last().copied().unwrap_or(0.0) / self.rate_hz;
                max_abs(&self.integral[i - 3]).max(end.abs())
            }
            _ => 0.0,
        }
    }
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

fn min_max(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        })
}

/// Whether the samples take more than one value.
fn varies(x: &[f64]) -> bool {
    let (lo, hi) = min_max(x);
    hi - lo > 1e-12 * hi.abs().max(lo.abs()).max(1.0)
}

/// Shape and switch time of one excitation: two levels with equal interior
/// dwells → square (half period); two levels otherwise → PRBS (shortest
/// interior dwell, the bit time); anything else → mixed.
fn classify(x: &[f64], rate_hz: f64) -> (SignalKind, Option<f64>) {
    let (lo, hi) = min_max(x);
    let tol = 1e-9 * (hi - lo);
    if x.iter()
        .any(|v| (v - lo).abs() > tol && (v - hi).abs() > tol)
    {
        return (SignalKind::Mixed, None);
    }
    let mut dwells = Vec::new();
    let mut run = 1usize;
    for w in x.windows(2) {
        if (w[1] - w[0]).abs() > tol {
            dwells.push(run);
            run = 0;
        }
        run += 1;
    }
    dwells.push(run);
    // first and last dwells may be cut by the run's ends
    let interior = if dwells.len() > 2 {
        &dwells[1..dwells.len() - 1]
    } else {
        &dwells[..1]
    };
    let (shortest, longest) = (
        *interior.iter().min().expect("one dwell at least"),
        *interior.iter().max().expect("one dwell at least"),
    );
    let kind = if longest - shortest <= 1 {
        SignalKind::Square
    } else {
        SignalKind::Prbs
    };
    (kind, Some(shortest as f64 / rate_hz))
}

/// The run plan of an external run, with its metadata inferred:
/// - excited: the DOFs whose samples vary;
/// - role: static when none varies, else dynamic (never validation);
/// - grid speed: the surge velocity reference (its mean if it varies; 0 for a held surge;
///   None when surge is open-loop force), also the one entry of `speeds`;
/// - signal: constant for statics, mixed when several DOFs vary, else the
///   varying channel's shape ([`classify`]); amplitude: half its
///   peak-to-peak (m/s, rad/s, rad, N or N·m).
fn plan_of(run: &ExternalRun) -> RunPlan {
    let schedule = Schedule::new(run);
    let excited: Vec<Dof> = Dof::ALL
        .into_iter()
        .filter(|d| run.channels[d.index()].samples().is_some_and(varies))
        .collect();
    let grid_speed = match &run.channels[0] {
        Channel::Velocity(x) if !varies(x) => Some(x[0]),
        Channel::Velocity(x) => Some(x.iter().sum::<f64>() / x.len() as f64),
        Channel::Hold => Some(0.0),
        _ => None,
    };
    let (role, signal, amplitude, switch_time_s) = match excited.as_slice() {
        [] => (Role::Static, SignalKind::Constant, 0.0, None),
        [d] => {
            let x = run.channels[d.index()].samples().expect("excited");
            let (lo, hi) = min_max(x);
            let (kind, switch) = classify(x, run.rate_hz);
            (Role::Dynamic, kind, 0.5 * (hi - lo), switch)
        }
        [d, ..] => {
            let x = run.channels[d.index()].samples().expect("excited");
            let (lo, hi) = min_max(x);
            (Role::Dynamic, SignalKind::Mixed, 0.5 * (hi - lo), None)
        }
    };
    RunPlan {
        name: run.name.clone(),
        role,
        grid_speed,
        excited,
        signal,
        amplitude,
        switch_time_s,
        speeds: grid_speed.into_iter().collect(),
        duration_s: schedule.n as f64 / run.rate_hz,
        preroll_s: run.lead_in_s,
        start_pose: Some((run.start_depth_m, run.start_heading_rad)),
        program: Program::External(Box::new(schedule)),
    }
}

/// The envelope the autopilot of an external campaign is tuned for:
/// - `u_max`: the largest surge velocity reference of any run (0 if none);
/// - amplitude, surge: the largest half peak-to-peak of a surge velocity
///   reference; sway, heave, yaw: the largest |ν_ref|; roll, pitch: the
///   largest |φ_ref|, |θ_ref| (attitude channels, or the integrated rate of
///   velocity channels);
/// - each amplitude at least 20 % of [`CampaignSpec::default`]'s, so a held
///   DOF keeps some authority against noise and coupling.
///
/// Force channels are open loop and do not enter.
pub fn external_envelope(runs: &[ExternalRun]) -> Envelope {
    let floor = CampaignSpec::default().amplitude;
    let mut u_max = 0.0f64;
    let mut amplitude = floor.map(|a| 0.2 * a);
    for run in runs {
        let s = Schedule::new(run);
        if let Channel::Velocity(x) = &run.channels[0] {
            let (lo, hi) = min_max(x);
            u_max = u_max.max(hi);
            amplitude[0] = amplitude[0].max(0.5 * (hi - lo));
        }
        for i in [1, 2, 5] {
            if let Channel::Velocity(x) = &run.channels[i] {
                amplitude[i] = amplitude[i].max(max_abs(x));
            }
        }
        for i in [3, 4] {
            amplitude[i] = amplitude[i].max(s.max_attitude(i));
        }
    }
    Envelope { u_max, amplitude }
}

fn flight<'a>(
    plant: &'a Plant,
    cfg: &'a ControllerConfig,
    noise: &NoiseSpec,
    offset: f64,
) -> Flight<'a> {
    let spec = CampaignSpec {
        noise: *noise,
        nav_noise: *noise,
        ..CampaignSpec::default()
    };
    Flight::from_spec(plant, cfg, &spec, offset)
}

/// Flies one external run with `vessel` under autopilot `controller`, with
/// measurement noise `noise` (controller inputs, the single/control log and
/// the nav file) drawn from run seed `seed`. Its first log stamp is t = 0 and
/// its nav file is on the control clock (offset 0). To reproduce run i of
/// [`fly_campaign`](super::fly_campaign) use `seed = run_seed(campaign_seed, i)`.
///
/// # Panics
/// On an invalid schedule ([`ExternalRun::validate`]).
pub fn fly_external(
    vessel: &Vessel,
    controller: &ControllerConfig,
    run: &ExternalRun,
    noise: &NoiseSpec,
    seed: u64,
) -> Run {
    let plant = Plant::new(vessel);
    flight(&plant, controller, noise, 0.0).fly(&plan_of(run), 0.0, seed)
}

/// Flies `runs` in order under ONE given autopilot, as a campaign: a
/// campaign-wide clock offset (3–15 s) and start times (30–180 s gaps) drawn
/// from `seed`, and run i's noise from [`run_seed`]`(seed, i)`. Use this to
/// vary only the noise across seeds (the controller stays fixed).
///
/// # Panics
/// On an invalid schedule ([`ExternalRun::validate`]).
pub fn fly_external_runs(
    vessel: &Vessel,
    controller: &ControllerConfig,
    runs: &[ExternalRun],
    noise: &NoiseSpec,
    seed: u64,
) -> Vec<Run> {
    let plans: Vec<RunPlan> = runs.iter().map(plan_of).collect();
    let mut rng = Rng::new(derive_seed(seed, 0xE7_7E4A));
    let (lo, hi) = CampaignSpec::default().clock_offset_range_s;
    let offset = rng.range(lo, hi);
    let starts = start_times(&plans, &mut rng);
    let plant = Plant::new(vessel);
    flight(&plant, controller, noise, offset).fly_all(&plans, &starts, seed)
}

/// Flies an external campaign: the autopilot is tuned once
/// ([`ControllerConfig::tune`] on [`external_envelope`]`(runs)`, drawn from
/// `seed` like [`fly_campaign`](super::fly_campaign)'s), then every run is
/// flown with it by [`fly_external_runs`]. Note a different `seed` also gives
/// a different autopilot (nominal inertia and ĝ); for noise-only
/// replications, tune once and call [`fly_external_runs`].
///
/// # Panics
/// On an invalid schedule ([`ExternalRun::validate`]).
pub fn fly_external_campaign(
    vessel: &Vessel,
    runs: &[ExternalRun],
    noise: &NoiseSpec,
    seed: u64,
) -> (ControllerConfig, Vec<Run>) {
    let mut rng = Rng::new(derive_seed(seed, 0xCA3B));
    let cfg = ControllerConfig::tune(vessel, &external_envelope(runs), &mut rng);
    let flown = fly_external_runs(vessel, &cfg, runs, noise, seed);
    (cfg, flown)
}

/// The truth's own campaign ([`fly_campaign`](super::fly_campaign) with the
/// same arguments) as external schedules sampled at 20 Hz: the autopilot it
/// flies with and, per run, the u, v, w, r velocity and φ, θ attitude
/// references, the pre-roll as lead-in and the drawn start pose. Flying run i
/// with [`fly_external`] and `run_seed(seed, i)` reproduces the campaign's run
/// exactly when its pre-roll holds its first reference (static runs);
/// excited runs differ in the lead-in (the campaign's pre-roll holds the
/// operating point, an external lead-in the first sample) and converge after.
pub fn campaign_as_external(
    vessel: &Vessel,
    spec: &CampaignSpec,
    seed: u64,
) -> (ControllerConfig, Vec<ExternalRun>) {
    let mut rng = Rng::new(derive_seed(seed, 0xCA3B));
    let cfg = ControllerConfig::tune(vessel, &spec.envelope(), &mut rng);
    let _offset = rng.range(spec.clock_offset_range_s.0, spec.clock_offset_range_s.1);
    let plans = plan_campaign(spec, &mut rng);
    let runs = plans
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let n = (p.duration_s * 10.0).round() as usize * 2;
            let refs: Vec<Reference> = (0..n)
                .map(|k| p.program.reference(k as f64 * CONTROL_DT))
                .collect();
            let vel = |i: usize| Channel::Velocity(refs.iter().map(|r| r.nu[i]).collect());
            let (depth, heading) = draw_start_pose(&mut start_pose_rng(run_seed(seed, i)));
            ExternalRun {
                name: p.name.clone(),
                rate_hz: 1.0 / CONTROL_DT,
                channels: [
                    vel(0),
                    vel(1),
                    vel(2),
                    Channel::Attitude(refs.iter().map(|r| r.phi).collect()),
                    Channel::Attitude(refs.iter().map(|r| r.theta).collect()),
                    vel(5),
                ],
                lead_in_s: p.preroll_s,
                start_depth_m: depth,
                start_heading_rad: heading,
            }
        })
        .collect();
    (cfg, runs)
}
