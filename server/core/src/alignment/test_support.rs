//! Test-only generators: a seeded SplitMix64 with Box–Muller normals, a
//! smooth "depth" signal evaluable at any time (low-pass noise as a sum of
//! random sinusoids with a first-order spectrum, plus smooth ramps), and
//! logs sampled from it with a clock offset, jittered stamps and noise.

use std::f64::consts::PI;

use crate::timeseries::LogTable;

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, seedable, good enough.
#[derive(Debug, Clone)]
pub(crate) struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed ^ 0x5DEE_CE66_D1CE_4E5B)
    }

    pub fn next_u64(&mut self) -> u64 {
        let out = crate::rng::mix(self.0);
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        out
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

/// A smooth depth-like signal of true time (m).
#[derive(Debug, Clone)]
pub(crate) struct Depth {
    /// (amplitude, angular frequency, phase).
    waves: Vec<(f64, f64, f64)>,
    /// (start, duration, change): smooth ramps (dives and ascents).
    ramps: Vec<(f64, f64, f64)>,
    base: f64,
}

impl Depth {
    /// Low-pass noise (80 random sinusoids in 0.002–0.5 Hz with a
    /// first-order spectrum of corner `corner_hz`, scaled to `wave_rms` m)
    /// plus three smooth ramps of 2–6 m over 20–60 s within `[0, duration]`.
    pub fn random(rng: &mut Rng, duration: f64, wave_rms: f64, corner_hz: f64) -> Self {
        let mut waves: Vec<(f64, f64, f64)> = (0..80)
            .map(|_| {
                let f = rng.range(0.002, 0.5);
                let amp = 1.0 / (1.0 + (f / corner_hz).powi(2)).sqrt();
                (amp, 2.0 * PI * f, rng.range(0.0, 2.0 * PI))
            })
            .collect();
        let rms = (waves.iter().map(|w| 0.5 * w.0 * w.0).sum::<f64>()).sqrt();
        waves.iter_mut().for_each(|w| w.0 *= wave_rms / rms);
        let ramps = (0..3)
            .map(|_| {
                let dz = rng.range(2.0, 6.0) * if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                (rng.range(0.0, duration), rng.range(20.0, 60.0), dz)
            })
            .collect();
        Depth {
            waves,
            ramps,
            base: 20.0,
        }
    }

    /// A slow, ramp-dominated dive: waves of 0.55 m rms with a 0.05 Hz
    /// corner. At 30 dB SNR (relative to the whole signal, mostly ramps)
    /// little of the signal carries timing: reported standard errors are
    /// 0.015–0.05 samples at 10 Hz, against ~0.01 for [`Depth::lively`].
    pub fn slow(rng: &mut Rng, duration: f64) -> Self {
        Self::random(rng, duration, 0.55, 0.05)
    }

    /// A livelier depth record (excitation experiments): waves of 1 m rms
    /// with a 0.1 Hz corner, plus the ramps.
    pub fn lively(rng: &mut Rng, duration: f64) -> Self {
        Self::random(rng, duration, 1.0, 0.1)
    }

    /// A slow wander without ramps (a depth hold drifting, a sensor's own
    /// drift): 40 random sinusoids in 0.0005–`max_hz` Hz with a flat
    /// spectrum, scaled to `rms` m, around `base` m.
    pub fn drift(rng: &mut Rng, rms: f64, max_hz: f64, base: f64) -> Self {
        let mut waves: Vec<(f64, f64, f64)> = (0..40)
            .map(|_| {
                let f = rng.range(0.0005, max_hz);
                (1.0, 2.0 * PI * f, rng.range(0.0, 2.0 * PI))
            })
            .collect();
        let total = (waves.iter().map(|w| 0.5 * w.0 * w.0).sum::<f64>()).sqrt();
        waves.iter_mut().for_each(|w| w.0 *= rms / total);
        Depth {
            waves,
            ramps: Vec::new(),
            base,
        }
    }

    /// Heave at one period (s) and amplitude (m), slowly modulated by
    /// `modulation` (0: a pure sinusoid).
    pub fn heave(rng: &mut Rng, period: f64, amplitude: f64, modulation: f64) -> Self {
        let w = 2.0 * PI / period;
        let dw = w * modulation * rng.range(0.5, 1.0);
        Depth {
            waves: vec![
                (amplitude, w, rng.range(0.0, 2.0 * PI)),
                (amplitude * modulation, w + dw, rng.range(0.0, 2.0 * PI)),
            ],
            ramps: Vec::new(),
            base: 20.0,
        }
    }

    /// A pure sinusoid of the given period (s) around 20 m.
    pub fn sinusoid(period: f64) -> Self {
        Depth {
            waves: vec![(1.0, 2.0 * PI / period, 0.3)],
            ramps: Vec::new(),
            base: 20.0,
        }
    }

    pub fn eval(&self, t: f64) -> f64 {
        let waves: f64 = self
            .waves
            .iter()
            .map(|(a, w, p)| a * (w * t + p).sin())
            .sum();
        let ramps: f64 = self
            .ramps
            .iter()
            .map(|&(t0, dur, dz)| {
                let s = ((t - t0) / dur).clamp(0.0, 1.0);
                dz * s * s * (3.0 - 2.0 * s)
            })
            .sum();
        self.base + waves + ramps
    }

    /// Standard deviation over `[a, b]` (sampled at 10 Hz).
    pub fn std(&self, a: f64, b: f64) -> f64 {
        let n = ((b - a) * 10.0) as usize + 1;
        let x: Vec<f64> = (0..n).map(|k| self.eval(a + k as f64 * 0.1)).collect();
        let m = x.iter().sum::<f64>() / n as f64;
        (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n as f64).sqrt()
    }
}

/// How one log samples the truth.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LogSpec {
    pub rate_hz: f64,
    /// True time of the first sample and of the end (s).
    pub start: f64,
    pub end: f64,
    /// Stamp = true time + `clock` (+ jitter).
    pub clock: f64,
    /// Stamp jitter, uniform in ± `jitter` · dt.
    pub jitter: f64,
    /// Additive white noise on the values.
    pub noise: f64,
}

impl LogSpec {
    /// True sample times.
    pub fn true_times(&self) -> Vec<f64> {
        let dt = 1.0 / self.rate_hz;
        let n = ((self.end - self.start) * self.rate_hz).floor() as usize + 1;
        (0..n).map(|k| self.start + k as f64 * dt).collect()
    }

    /// Stamps and noisy values of `f` at the true sample times.
    pub fn sample(&self, f: impl Fn(f64) -> f64, rng: &mut Rng) -> (Vec<f64>, Vec<f64>) {
        let dt = 1.0 / self.rate_hz;
        self.true_times()
            .into_iter()
            .map(|tau| {
                let stamp = tau + self.clock + self.jitter * dt * rng.range(-1.0, 1.0);
                (stamp, f(tau) + self.noise * rng.normal())
            })
            .unzip()
    }
}

/// A case of the accuracy sweeps: truth, control and nav logs of a shared
/// depth channel. Nav stamps = true + `control.clock − offset`.
pub(crate) struct Case {
    pub offset: f64,
    pub control: (Vec<f64>, Vec<f64>),
    pub nav: (Vec<f64>, Vec<f64>),
    pub dt_slow: f64,
}

/// Control at `control_hz` over true [0, duration], nav at `nav_hz` over a
/// random sub-window, clock offset `offset`, SNR `snr_db`, jitter ±1 % dt,
/// depth [`Depth::lively`] or (`slow`) [`Depth::slow`].
pub(crate) fn make_case(
    seed: u64,
    (control_hz, nav_hz): (f64, f64),
    offset: f64,
    duration: f64,
    snr_db: f64,
    slow: bool,
) -> Case {
    let mut rng = Rng::new(seed);
    let depth = if slow {
        Depth::slow(&mut rng, duration)
    } else {
        Depth::lively(&mut rng, duration)
    };
    let noise = depth.std(0.0, duration) * 10f64.powf(-snr_db / 20.0);
    let control = LogSpec {
        rate_hz: control_hz,
        start: 0.0,
        end: duration,
        clock: 100.0,
        jitter: 0.01,
        noise,
    };
    let nav = LogSpec {
        rate_hz: nav_hz,
        start: rng.range(0.0, 0.1 * duration),
        end: duration - rng.range(0.0, 0.1 * duration),
        clock: 100.0 - offset,
        jitter: 0.01,
        noise,
    };
    let c = control.sample(|t| depth.eval(t), &mut rng);
    let n = nav.sample(|t| depth.eval(t), &mut rng);
    Case {
        offset,
        control: c,
        nav: n,
        dt_slow: 1.0 / control_hz.min(nav_hz),
    }
}

/// The kinds of run of the calibration sweeps, strong to hopeless.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RunKind {
    /// 10 min of lively depth at 30 dB (an excitation run).
    Lively,
    /// 3 min of lively depth at 15 dB.
    ShortNoisy,
    /// 5 min of a ramp-dominated dive at 25 dB.
    SlowDive,
    /// A static run holding depth: a slow drift of 2–10 cm and 1–3 cm of
    /// white noise on each log, 5–10 min.
    StaticHold,
    /// The same, each depth sensor also wandering on its own.
    StaticWander,
    /// Heave at one period (6–30 s), 5 min: every period fits.
    Heave,
}

impl RunKind {
    pub const ALL: [RunKind; 6] = [
        RunKind::Lively,
        RunKind::ShortNoisy,
        RunKind::SlowDive,
        RunKind::StaticHold,
        RunKind::StaticWander,
        RunKind::Heave,
    ];
}

/// One seeded run of `kind` with clock offset `offset` (s): control 10 Hz
/// over true [0, duration], nav at 20 Hz over a random sub-window.
pub(crate) fn make_run(kind: RunKind, seed: u64, offset: f64) -> Case {
    match kind {
        RunKind::Lively => return make_case(seed, (10.0, 20.0), offset, 600.0, 30.0, false),
        RunKind::ShortNoisy => return make_case(seed, (10.0, 20.0), offset, 180.0, 15.0, false),
        RunKind::SlowDive => return make_case(seed, (10.0, 20.0), offset, 300.0, 25.0, true),
        _ => {}
    }
    let mut rng = Rng::new(seed);
    let (duration, depth, noise, wander) = match kind {
        RunKind::Heave => {
            let (period, amp) = (rng.range(6.0, 30.0), rng.range(0.1, 0.5));
            let modulation = rng.range(0.0, 0.05);
            let depth = Depth::heave(&mut rng, period, amp, modulation);
            (300.0, depth, rng.range(0.01, 0.05), 0.0)
        }
        _ => {
            let duration = rng.range(300.0, 600.0);
            let (rms, max_hz) = (rng.range(0.02, 0.1), rng.range(0.002, 0.01));
            let depth = Depth::drift(&mut rng, rms, max_hz, 20.0);
            let wander = if kind == RunKind::StaticWander {
                0.5 * rms
            } else {
                0.0
            };
            (duration, depth, rng.range(0.01, 0.03), wander)
        }
    };
    let own = |rng: &mut Rng| Depth::drift(rng, wander, 0.01, 0.0);
    let (wander_c, wander_n) = (own(&mut rng), own(&mut rng));
    let control = LogSpec {
        rate_hz: 10.0,
        start: 0.0,
        end: duration,
        clock: 100.0,
        jitter: 0.01,
        noise,
    };
    let nav = LogSpec {
        rate_hz: 20.0,
        start: rng.range(0.0, 0.1 * duration),
        end: duration - rng.range(0.0, 0.1 * duration),
        clock: 100.0 - offset,
        jitter: 0.01,
        noise,
    };
    let c = control.sample(|t| depth.eval(t) + wander_c.eval(t), &mut rng);
    let n = nav.sample(|t| depth.eval(t) + wander_n.eval(t), &mut rng);
    Case {
        offset,
        control: c,
        nav: n,
        dt_slow: 0.1,
    }
}

/// A [`LogTable`] from a time vector and named columns.
pub(crate) fn table(t: Vec<f64>, cols: Vec<(&str, Vec<f64>)>) -> LogTable {
    let (names, data) = cols.into_iter().map(|(n, v)| (n.to_owned(), v)).unzip();
    LogTable { t, names, data }
}
