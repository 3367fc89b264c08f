//! Writing a campaign: CSVs in the service's log contract (SI, radians,
//! header names of seatrial's log schema) and `truth.json`.

use std::fmt::Write as _;
use std::io;
use std::path::Path;

use nalgebra::{DMatrix, Matrix6, Vector3, Vector6};

use super::{CONTROL_COLUMNS, Campaign, NAV_COLUMNS, Role, Run, SINGLE_COLUMNS};
use crate::json::Json;
use crate::linearization::{Linearization, effective_linearization};

/// Decimals per column group: time, τ, ν, position, angles.
const DEC_T_CONTROL: usize = 3;
const DEC_T_NAV: usize = 4;
const DEC_TAU: usize = 4;
const DEC_NU: usize = 6;
const DEC_POS: usize = 4;
const DEC_ANGLE: usize = 6;

fn num(out: &mut String, x: f64, decimals: usize) {
    // no "-0.000": a value that rounds to zero prints as zero
    let x = if x.abs() < 0.5 * 10f64.powi(-(decimals as i32)) {
        0.0
    } else {
        x
    };
    let _ = write!(out, "{x:.decimals$}");
}

fn push_eta(out: &mut String, eta: &DMatrix<f64>, i: usize, cols: std::ops::Range<usize>) {
    for j in cols {
        out.push(',');
        num(out, eta[(i, j)], if j < 3 { DEC_POS } else { DEC_ANGLE });
    }
}

impl Run {
    /// The single-file CSV: t, τ, ν, η at 10 Hz on the control clock.
    pub fn single_csv(&self) -> String {
        let l = &self.log;
        let mut out = SINGLE_COLUMNS.join(",");
        out.push('\n');
        for i in 0..l.t.len() {
            num(&mut out, l.t[i], DEC_T_CONTROL);
            for j in 0..6 {
                out.push(',');
                num(&mut out, l.tau[(i, j)], DEC_TAU);
            }
            for j in 0..6 {
                out.push(',');
                num(&mut out, l.nu[(i, j)], DEC_NU);
            }
            push_eta(&mut out, &l.eta, i, 0..6);
            out.push('\n');
        }
        out
    }

    /// The control file: t, τ and the shared depth z (control clock, 10 Hz).
    pub fn control_csv(&self) -> String {
        let l = &self.log;
        let mut out = CONTROL_COLUMNS.join(",");
        out.push('\n');
        for i in 0..l.t.len() {
            num(&mut out, l.t[i], DEC_T_CONTROL);
            for j in 0..6 {
                out.push(',');
                num(&mut out, l.tau[(i, j)], DEC_TAU);
            }
            push_eta(&mut out, &l.eta, i, 2..3);
            out.push('\n');
        }
        out
    }

    /// The nav file: t (nav clock), ν, η at the nav rate, own noise.
    pub fn nav_csv(&self) -> String {
        let n = &self.nav;
        let mut out = NAV_COLUMNS.join(",");
        out.push('\n');
        for i in 0..n.t.len() {
            num(&mut out, n.t[i], DEC_T_NAV);
            for j in 0..6 {
                out.push(',');
                num(&mut out, n.nu[(i, j)], DEC_NU);
            }
            push_eta(&mut out, &n.eta, i, 0..6);
            out.push('\n');
        }
        out
    }
}

fn v6(v: &Vector6<f64>) -> Json {
    Json::nums(v.iter().copied())
}

fn v3(v: &Vector3<f64>) -> Json {
    Json::nums(v.iter().copied())
}

fn m6(m: &Matrix6<f64>) -> Json {
    Json::Arr(
        (0..6)
            .map(|i| Json::nums(m.row(i).iter().copied()))
            .collect(),
    )
}

fn lin_json(l: &Linearization) -> Json {
    Json::obj([
        ("u0", Json::Num(l.u0)),
        ("M", m6(&l.m)),
        ("D_bar", m6(&l.d_bar)),
        ("bias", v6(&l.bias)),
        ("w_minus_b", Json::Num(l.w_minus_b)),
        ("zg_w_minus_zb_b", Json::Num(l.zg_w_minus_zb_b)),
    ])
}

fn opt(x: Option<f64>) -> Json {
    x.map_or(Json::Null, Json::Num)
}

impl Campaign {
    /// The truth metadata as JSON: vessel, controller, linearizations per
    /// grid speed (tangent and effective over the dynamic runs), runs.
    pub fn truth_json(&self) -> String {
        let v = &self.vessel;
        let c = &self.controller;
        let vessel = Json::obj([
            ("name", Json::str(v.name.clone())),
            ("mass", Json::Num(v.mass)),
            ("inertia_cg", v3(&v.inertia_cg)),
            ("z_g", Json::Num(v.z_g)),
            ("z_b", Json::Num(v.z_b)),
            ("added_mass", v6(&v.added_mass)),
            ("damping_linear", v6(&v.damping_linear)),
            ("damping_linear_per_speed", v6(&v.damping_linear_per_speed)),
            ("damping_quadratic", v6(&v.damping_quadratic)),
            ("w_minus_b", Json::Num(v.w_minus_b)),
            ("zg_w_minus_zb_b", Json::Num(v.zg_w_minus_zb_b())),
            ("gravity", Json::Num(v.gravity)),
            ("current_ned", v3(&v.current_ned)),
            ("tether", v6(&v.tether)),
            ("tether_ned", v3(&v.tether_ned)),
            (
                "actuator_lag_s",
                v.actuator.lag_s.as_ref().map_or(Json::Null, v6),
            ),
            (
                "actuator_limits",
                v.actuator.limits.as_ref().map_or(Json::Null, v6),
            ),
            ("actuator_delay_s", opt(v.actuator.delay_s)),
            (
                "actuator_dead_zone",
                v.actuator.dead_zone.as_ref().map_or(Json::Null, v6),
            ),
            (
                "current_drift",
                v.current_drift.as_ref().map_or(Json::Null, |d| {
                    Json::obj([
                        ("amplitude_ned", v3(&d.amplitude)),
                        ("period_s", v3(&d.period_s)),
                        ("phase_rad", v3(&d.phase)),
                    ])
                }),
            ),
            (
                "disturbance",
                v.disturbance.as_ref().map_or(Json::Null, |d| {
                    Json::obj([
                        ("amplitude", v6(&d.amplitude)),
                        ("frequency_hz", Json::Num(d.frequency_hz)),
                        ("phase_rad", Json::Num(d.phase)),
                    ])
                }),
            ),
            ("size_lbh", v3(&v.size)),
            ("M", m6(&v.m())),
        ]);
        let controller = Json::obj([
            ("rate_hz", Json::Num(20.0)),
            ("log_rate_hz", Json::Num(10.0)),
            ("kp", v6(&c.kp)),
            ("ki", v6(&c.ki)),
            ("kd", v6(&c.kd)),
            ("limits", v6(&c.limits)),
            ("nominal_w_minus_b", Json::Num(c.nominal_w_minus_b)),
            (
                "nominal_zg_w_minus_zb_b",
                Json::Num(c.nominal_zg_w_minus_zb_b),
            ),
        ]);
        let grid = self
            .spec
            .grid_speeds
            .iter()
            .map(|&u0| {
                let dynamic = self.runs_at(u0, Role::Dynamic);
                let eff = if dynamic.is_empty() {
                    Json::Null
                } else {
                    lin_json(&effective_linearization(v, &dynamic))
                };
                Json::obj([
                    ("u0", Json::Num(u0)),
                    ("tangent", lin_json(&v.linearization(u0))),
                    ("effective_dynamic", eff),
                ])
            })
            .collect();
        let runs = self.runs.iter().map(run_json).collect();
        Json::obj([
            ("generator", Json::str("seatrial-truth")),
            ("seed", Json::UInt(self.seed)),
            ("clock_offset_s", Json::Num(self.clock_offset_s)),
            (
                "clock_offset_convention",
                Json::str("nav t + clock_offset_s = control t"),
            ),
            ("vessel", vessel),
            ("controller", controller),
            ("grid", Json::Arr(grid)),
            ("runs", Json::Arr(runs)),
        ])
        .pretty()
    }

    /// Writes `<name>.csv`, `<name>_control.csv`, `<name>_nav.csv` per run and
    /// `truth.json` into `dir` (created if missing).
    pub fn write_dir(&self, dir: &Path) -> io::Result<()> {
        std::fs::create_dir_all(dir)?;
        for r in &self.runs {
            let n = &r.meta.name;
            std::fs::write(dir.join(format!("{n}.csv")), r.single_csv())?;
            std::fs::write(dir.join(format!("{n}_control.csv")), r.control_csv())?;
            std::fs::write(dir.join(format!("{n}_nav.csv")), r.nav_csv())?;
        }
        std::fs::write(dir.join("truth.json"), self.truth_json())
    }
}

fn run_json(r: &Run) -> Json {
    let m = &r.meta;
    Json::obj([
        ("name", Json::str(m.name.clone())),
        ("role", Json::str(m.role.label())),
        ("grid_speed", opt(m.grid_speed)),
        (
            "excited",
            Json::Arr(m.excited.iter().map(|d| Json::str(d.label())).collect()),
        ),
        ("signal", Json::str(m.signal.label())),
        ("amplitude", Json::Num(m.amplitude)),
        ("switch_time_s", opt(m.switch_time_s)),
        ("speeds", Json::nums(m.speeds.iter().copied())),
        ("start_s", Json::Num(m.start_s)),
        ("duration_s", Json::Num(m.duration_s)),
        ("clock_offset_s", Json::Num(m.clock_offset_s)),
        ("saturated_fraction", Json::Num(m.saturated_fraction)),
        ("rows", Json::UInt(r.log.t.len() as u64)),
        ("nav_rows", Json::UInt(r.nav.t.len() as u64)),
        (
            "files",
            Json::obj([
                ("single", Json::str(format!("{}.csv", m.name))),
                ("control", Json::str(format!("{}_control.csv", m.name))),
                ("nav", Json::str(format!("{}_nav.csv", m.name))),
            ]),
        ),
    ])
}
