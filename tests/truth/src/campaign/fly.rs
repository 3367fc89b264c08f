//! Flying runs: the plant under the 20 Hz autopilot, the 10 Hz logger (every
//! second command, thesis eq. 5.2: τ_obs(k) = τ_real(2k)), and the nav
//! computer sampling on its own clock.

use nalgebra::{DMatrix, Vector6};

use super::plan::{RunPlan, plan_campaign};
use super::{Campaign, CampaignSpec, Log, NavLog, NoiseSpec, Run, RunMeta, TruthRecord};
use crate::controller::{CONTROL_DT, Controller, ControllerConfig};
use crate::kinematics::wrap_pi;
use crate::plant::{DelayLine, Plant, State};
use crate::rng::{Rng, derive_seed};
use crate::vessel::Vessel;

/// Log every second controller sample: 10 Hz.
const LOG_EVERY: i64 = 2;

fn to_matrix(rows: &[Vector6<f64>]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), 6, |i, j| rows[i][j])
}

fn measure(x: &State, noise: &NoiseSpec, rng: &mut Rng) -> (Vector6<f64>, Vector6<f64>) {
    let nu = Vector6::from_fn(|i, _| x.nu[i] + noise.nu_std(i) * rng.normal());
    let mut eta = Vector6::from_fn(|i, _| x.eta[i] + noise.eta_std(i) * rng.normal());
    eta[5] = wrap_pi(eta[5]);
    (nu, eta)
}

/// The generator of a run's initial pose, from the run seed.
pub(crate) fn start_pose_rng(run_seed: u64) -> Rng {
    Rng::new(derive_seed(run_seed, 3))
}

/// Initial depth 20–80 m and heading in (−π, π) (rad).
pub(crate) fn draw_start_pose(rng: &mut Rng) -> (f64, f64) {
    let depth = rng.range(20.0, 80.0);
    (
        depth,
        rng.range(-std::f64::consts::PI, std::f64::consts::PI),
    )
}

/// Everything one run needs besides its plan: the one flying routine of the
/// truth's own campaign and of external schedules.
pub(crate) struct Flight<'a> {
    pub plant: &'a Plant,
    pub cfg: &'a ControllerConfig,
    /// Noise on the controller's measurements and the single/control logs.
    pub noise: NoiseSpec,
    /// Noise of the nav computer's file.
    pub nav_noise: NoiseSpec,
    /// Nav file rate (Hz).
    pub nav_rate_hz: f64,
    /// Internal RK4 rate (Hz), a multiple of 20.
    pub integration_rate_hz: f64,
    /// Clock offset (s): nav t + offset = control t.
    pub offset: f64,
}

impl<'a> Flight<'a> {
    /// The flight settings of `spec` with clock offset `offset`.
    pub fn from_spec(
        plant: &'a Plant,
        cfg: &'a ControllerConfig,
        spec: &CampaignSpec,
        offset: f64,
    ) -> Self {
        Flight {
            plant,
            cfg,
            noise: spec.noise,
            nav_noise: spec.nav_noise,
            nav_rate_hz: spec.nav_rate_hz,
            integration_rate_hz: spec.integration_rate_hz,
            offset,
        }
    }

    /// Flies `plan` with its first log stamp at control time `t0`.
    pub fn fly(&self, plan: &RunPlan, t0: f64, seed: u64) -> Run {
        let mut meas_rng = Rng::new(derive_seed(seed, 1));
        let mut nav_rng = Rng::new(derive_seed(seed, 2));
        let mut init_rng = start_pose_rng(seed);
        let substeps = (self.integration_rate_hz * CONTROL_DT).round().max(1.0) as i64;
        let h = CONTROL_DT / substeps as f64;

        // Start in trim at the program's first set-point, loops preset.
        let r0 = plan.program.reference(0.0);
        let (depth, heading) = plan
            .start_pose
            .unwrap_or_else(|| draw_start_pose(&mut init_rng));
        let eta0 = Vector6::new(0.0, 0.0, depth, 0.0, 0.0, heading);
        let nu0 = Vector6::new(r0.nu[0], 0.0, 0.0, 0.0, 0.0, 0.0);
        let mut x = State::new(eta0, nu0);
        let v = self.plant.vessel();
        let mut ctrl = Controller::new(self.cfg.clone());
        let trim = v.hydrodynamic_force(&nu0) + v.restoring(&eta0)
            - self.cfg.nominal_restoring(0.0, 0.0)
            - v.tether;
        ctrl.preset(&trim);
        x.tau_act = trim + self.cfg.nominal_restoring(0.0, 0.0);
        // A transport delay: the commands issued so far, the trim force
        // before the first one.
        let mut delay_line = v.actuator.delay_s.map(|d| DelayLine::new(d, x.tau_act));

        let rows = (plan.duration_s * 10.0).round() as i64;
        let ticks = rows * LOG_EVERY;
        let pre = (plan.preroll_s / CONTROL_DT).round() as i64;
        let tick_time = |j: i64| t0 + j as f64 * CONTROL_DT;

        // Nav samples n/rate on the nav clock, at control time n/rate + offset.
        let rate = self.nav_rate_hz;
        let last_log = tick_time(ticks - LOG_EVERY);
        let mut n_nav = ((t0 - self.offset) * rate).ceil() as i64;
        let n_last = ((last_log - self.offset) * rate).floor() as i64;

        let mut log_t = Vec::with_capacity(rows as usize);
        let (mut log_tau, mut log_nu, mut log_eta) = (Vec::new(), Vec::new(), Vec::new());
        let (mut true_nu, mut true_eta, mut applied) = (Vec::new(), Vec::new(), Vec::new());
        let (mut cmd20, mut t20) = (Vec::new(), Vec::new());
        let (mut nav_t, mut nav_nu, mut nav_eta) = (Vec::new(), Vec::new(), Vec::new());
        let mut saturated = 0usize;

        for j in -pre..ticks {
            let (y_nu, y_eta) = measure(&x, &self.noise, &mut meas_rng);
            let run_t = j as f64 * CONTROL_DT;
            let (mut tau, mut sat) = ctrl.update(&y_nu, &y_eta, &plan.program.reference(run_t));
            // open-loop DOFs: the schedule's τ replaces the autopilot's
            for (i, f) in plan.program.open_loop(run_t).into_iter().enumerate() {
                if let Some(f) = f {
                    tau[i] = f;
                    sat[i] = false;
                }
            }
            if let Some(line) = delay_line.as_mut() {
                line.push(tick_time(j), tau);
            }
            // The command reaching the hull over the RK4 step from `ts`:
            // the delayed one at the step's midpoint (see DelayLine).
            let hull = |ts: f64| match &delay_line {
                Some(line) => line.at(ts + 0.5 * h),
                None => tau,
            };
            if j >= 0 {
                saturated += usize::from(sat.iter().any(|s| *s));
                cmd20.push(tau);
                t20.push(tick_time(j));
                if j % LOG_EVERY == 0 {
                    log_t.push(tick_time(j));
                    log_tau.push(tau);
                    log_nu.push(y_nu);
                    log_eta.push(y_eta);
                    true_nu.push(x.nu);
                    true_eta.push(x.eta);
                    applied.push(self.plant.applied_force(&x, &hull(tick_time(j))));
                }
            }
            for s in 0..substeps {
                let ts = tick_time(j) + s as f64 * h;
                let cmd = hull(ts);
                if j >= 0 {
                    // nav instants inside [ts, ts + h): a partial RK4 step
                    while n_nav <= n_last {
                        let tc = n_nav as f64 / rate + self.offset;
                        if tc >= ts + h {
                            break;
                        }
                        let xn = self.plant.rk4_step_at(ts, &x, &cmd, (tc - ts).max(0.0));
                        let (m_nu, m_eta) = measure(&xn, &self.nav_noise, &mut nav_rng);
                        nav_t.push(n_nav as f64 / rate);
                        nav_nu.push(m_nu);
                        nav_eta.push(m_eta);
                        n_nav += 1;
                    }
                }
                x = self.plant.rk4_step_at(ts, &x, &cmd, h);
            }
        }

        Run {
            meta: RunMeta {
                name: plan.name.clone(),
                role: plan.role,
                grid_speed: plan.grid_speed,
                excited: plan.excited.clone(),
                signal: plan.signal,
                amplitude: plan.amplitude,
                switch_time_s: plan.switch_time_s,
                speeds: plan.speeds.clone(),
                start_s: t0,
                duration_s: rows as f64 / 10.0,
                clock_offset_s: self.offset,
                saturated_fraction: saturated as f64 / ticks.max(1) as f64,
            },
            log: Log {
                t: log_t,
                tau: to_matrix(&log_tau),
                nu: to_matrix(&log_nu),
                eta: to_matrix(&log_eta),
            },
            nav: NavLog {
                t: nav_t,
                nu: to_matrix(&nav_nu),
                eta: to_matrix(&nav_eta),
            },
            truth: TruthRecord {
                nu: to_matrix(&true_nu),
                eta: to_matrix(&true_eta),
                tau_applied: to_matrix(&applied),
                tau_cmd_20hz: to_matrix(&cmd20),
                t_20hz: t20,
            },
        }
    }
}

/// Control-clock start times of `plans` flown one after the other: the
/// first 100–1000 s into the clock, then 30–180 s gaps (all on the 10 Hz grid).
pub(crate) fn start_times(plans: &[RunPlan], rng: &mut Rng) -> Vec<f64> {
    let mut t0 = (rng.range(100.0, 1000.0) * 10.0).round() / 10.0;
    let mut starts = Vec::with_capacity(plans.len());
    for p in plans {
        starts.push(t0);
        t0 += p.duration_s + (rng.range(30.0, 180.0) * 10.0).round() / 10.0;
    }
    starts
}

/// The noise seed of run `index` of a campaign flown with `seed` (own plans
/// and external campaigns alike): different indices or seeds give
/// independent noise, the same pair the same noise.
pub fn run_seed(seed: u64, index: usize) -> u64 {
    derive_seed(seed, 1000 + index as u64)
}

impl Flight<'_> {
    /// Flies every plan, plan i from `starts[i]` with noise seed
    /// [`run_seed`]`(seed, i)`. Runs are independent (own seeds), so flying
    /// them on a few threads changes nothing in the result.
    pub fn fly_all(&self, plans: &[RunPlan], starts: &[f64], seed: u64) -> Vec<Run> {
        let workers = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
        let next = std::sync::atomic::AtomicUsize::new(0);
        let mut done: Vec<(usize, Run)> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..workers)
                .map(|_| {
                    s.spawn(|| {
                        let mut out = Vec::new();
                        loop {
                            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            let Some(p) = plans.get(i) else { break out };
                            out.push((i, self.fly(p, starts[i], run_seed(seed, i))));
                        }
                    })
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().expect("a run panicked"))
                .collect()
        });
        done.sort_by_key(|(i, _)| *i);
        done.into_iter().map(|(_, r)| r).collect()
    }
}

/// Flies the campaign `spec` with `vessel`, everything drawn from `seed`:
/// the team's controller (nominal inertia and ĝ), the clock offset, run
/// durations and signals, initial depth and heading, and all noise. Runs
/// follow each other on the control clock with 30–180 s gaps.
pub fn fly_campaign(vessel: &Vessel, spec: &CampaignSpec, seed: u64) -> Campaign {
    let mut rng = Rng::new(derive_seed(seed, 0xCA3B));
    let cfg = ControllerConfig::tune(vessel, &spec.envelope(), &mut rng);
    let (lo, hi) = spec.clock_offset_range_s;
    let offset = rng.range(lo, hi);
    let plans = plan_campaign(spec, &mut rng);
    let plant = Plant::new(vessel);
    let flight = Flight::from_spec(&plant, &cfg, spec, offset);
    let starts = start_times(&plans, &mut rng);
    let runs = flight.fly_all(&plans, &starts, seed);
    Campaign {
        vessel: vessel.clone(),
        spec: spec.clone(),
        seed,
        clock_offset_s: offset,
        controller: cfg,
        runs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_delayed_vehicle_feels_the_command_issued_six_ticks_earlier() {
        // d = 0.3 s = 6 controller ticks: the force on the hull at each log
        // row is the 20 Hz command of 6 ticks before, exactly (ideal
        // thrusters otherwise). 0.285 s lands on the same tick at the log
        // instants (the step from t holds τ_cmd(t + 2.5 ms − d)).
        for d in [0.3, 0.285] {
            let mut v = Vessel::draw(5);
            v.actuator.delay_s = Some(d);
            let c = fly_campaign(&v, &CampaignSpec::default(), 5);
            let mut checked = 0;
            for r in c.runs.iter().take(3) {
                let tr = &r.truth;
                for i in 3..tr.tau_applied.nrows() {
                    let applied = tr.tau_applied.row(i);
                    let issued = tr.tau_cmd_20hz.row(2 * i - 6);
                    assert_eq!(applied, issued, "d {d}, {} row {i}", r.meta.name);
                    checked += 1;
                }
                // and not the command of the same instant
                let same = (3..tr.tau_applied.nrows())
                    .filter(|&i| tr.tau_applied.row(i) == tr.tau_cmd_20hz.row(2 * i))
                    .count();
                assert!(same * 10 < tr.tau_applied.nrows(), "{same}");
            }
            assert!(checked > 1000);
        }
    }
}
