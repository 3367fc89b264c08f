//! A tiny deterministic ROV simulator for the API tests: decoupled
//! first-order DOFs T_i·ν̇_i = −ν_i + τ_i/d_i, driven by held random-binary
//! forces, with small measurement noise, written as the log contract's CSV.

#![allow(dead_code)]

/// SplitMix64: deterministic, seedable.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        let out = seatrial_core::rng::mix(self.0);
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        out
    }
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

pub const FORCES: [&str; 6] = ["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N"];
pub const VELS: [&str; 6] = ["u", "v", "w", "p", "q", "r"];
pub const POSE: [&str; 6] = ["x", "y", "z", "phi", "theta", "psi"];

/// A simulated run: time, forces, velocities, pose (all at `fs`).
pub struct SimRun {
    pub t: Vec<f64>,
    pub tau: [Vec<f64>; 6],
    pub nu: [Vec<f64>; 6],
    pub eta: [Vec<f64>; 6],
}

/// Simulates `duration` s at `fs` Hz. `amp[i]` is the force amplitude of DOF i
/// (0 holds it still), forces switch every `clock` s.
pub fn simulate(
    seed: u64,
    fs: f64,
    duration: f64,
    amp: [f64; 6],
    clock: f64,
    noise: f64,
) -> SimRun {
    let n = (duration * fs) as usize;
    let h = 1.0 / fs;
    let tc = [4.0, 3.0, 3.0, 1.5, 1.5, 2.0];
    let d = [2000.0, 4000.0, 4000.0, 3000.0, 3000.0, 3000.0];
    // Righting moments of roll and pitch (N·m/rad): attitudes stay within a
    // few degrees, as a real ROV's (a free pitch wandered past 90°).
    let g = [0.0, 0.0, 0.0, 6000.0, 6000.0, 0.0];
    let mut rng = Rng(seed);
    let mut run = SimRun {
        t: (0..n).map(|k| k as f64 * h).collect(),
        tau: Default::default(),
        nu: Default::default(),
        eta: Default::default(),
    };
    for i in 0..6 {
        let hold = (clock * fs).round().max(1.0) as usize;
        let mut level = 0.0;
        let mut v = if i == 0 { 0.5 } else { 0.0 };
        let mut pos = if i == 2 { 20.0 } else { 0.0 };
        let a = (-h / tc[i]).exp();
        for k in 0..n {
            if k % hold == 0 {
                level = if rng.uniform() < 0.5 { -amp[i] } else { amp[i] };
            }
            let bias = if i == 0 { 0.5 * d[0] } else { 0.0 };
            let tau = bias + level;
            run.tau[i].push(tau);
            run.nu[i].push(v + noise * rng.normal());
            run.eta[i].push(pos + noise * rng.normal());
            v = a * v + (1.0 - a) * (tau - g[i] * pos) / d[i];
            pos += v * h;
        }
    }
    // Depth gets a slow dive profile so two-file runs have a shared channel that varies.
    for k in 0..n {
        let t = run.t[k];
        run.eta[2][k] += 3.0 * (t / 40.0).sin() + 1.5 * (t / 13.0).sin();
    }
    run
}

/// CSV with the given columns (`t` first), optional clock offset added to t.
pub fn csv(run: &SimRun, cols: &[&str], t_offset: f64, every: usize) -> String {
    let mut s = String::from("t");
    for c in cols {
        s.push(',');
        s.push_str(c);
    }
    s.push('\n');
    for k in (0..run.t.len()).step_by(every.max(1)) {
        s.push_str(&format!("{}", run.t[k] + t_offset));
        for c in cols {
            let v = if let Some(i) = FORCES.iter().position(|x| x == c) {
                run.tau[i][k]
            } else if let Some(i) = VELS.iter().position(|x| x == c) {
                run.nu[i][k]
            } else if let Some(i) = POSE.iter().position(|x| x == c) {
                run.eta[i][k]
            } else {
                0.0
            };
            s.push_str(&format!(",{v}"));
        }
        s.push('\n');
    }
    s
}

/// The controller's log of a two-file run: forces and the shared depth.
pub const CONTROL_COLUMNS: [&str; 7] = ["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N", "z"];
/// The navigation computer's log of a two-file run: velocities and pose.
pub const NAV_COLUMNS: [&str; 12] = [
    "u", "v", "w", "p", "q", "r", "x", "y", "z", "phi", "theta", "psi",
];

/// The (control, nav) CSVs of a two-file run: the controller's clock
/// `offset_s` ahead of the navigation computer's, control every
/// `control_every`-th sample.
pub fn two_file_csv(run: &SimRun, offset_s: f64, control_every: usize) -> (String, String) {
    (
        csv(run, &CONTROL_COLUMNS, offset_s, control_every),
        csv(run, &NAV_COLUMNS, 0.0, 1),
    )
}

/// All 18 columns of a 6-DOF single-file log.
pub fn all_columns() -> Vec<&'static str> {
    FORCES
        .iter()
        .chain(VELS.iter())
        .chain(POSE.iter())
        .copied()
        .collect()
}

/// A multipart/form-data body.
pub fn multipart(parts: &[(&str, Option<&str>, &str)]) -> (String, String) {
    let boundary = "----seatrialtestboundary7MA4YWxk";
    let mut body = String::new();
    for (name, filename, content) in parts {
        body.push_str(&format!("--{boundary}\r\n"));
        match filename {
            Some(f) => body.push_str(&format!(
                "Content-Disposition: form-data; name=\"{name}\"; filename=\"{f}\"\r\nContent-Type: text/csv\r\n\r\n"
            )),
            None => body.push_str(&format!("Content-Disposition: form-data; name=\"{name}\"\r\n\r\n")),
        }
        body.push_str(content);
        body.push_str("\r\n");
    }
    body.push_str(&format!("--{boundary}--\r\n"));
    (format!("multipart/form-data; boundary={boundary}"), body)
}
