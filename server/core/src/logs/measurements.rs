//! What a DP log measures: its pose (x, y, ψ), its body velocities
//! (u, v, r), or both ([`super::schema::measurement_groups`]), and the unit
//! of its heading.
//!
//! A position-only log is what a DP system records and what the parallel
//! EKF of Fossen et al. (1995) identifies from. The quality report and the
//! run description score input→velocity pairs, so for them the body
//! velocities are derived from the pose ([`derive_body_velocities`]):
//! η̇ by a local linear least-squares fit over a window of ±`half_window_s`
//! (the Savitzky–Golay first derivative, exact for a quadratic track), then
//! ν = R(ψ)ᵀ·η̇ (Fossen eq. 2.40 for 3 DOF).

use std::collections::HashMap;

use super::checks::LogWarning;
use super::error::{LogError, LogErrorKind};
use super::parse::ParseOptions;
use crate::numbers::echoed;
use crate::timeseries::{LogTable, UniformRecord};

/// At least one of `opts.one_of` complete, else every group's missing
/// columns named.
pub(super) fn check_groups(
    present: &HashMap<&str, usize>,
    line: u64,
    opts: &ParseOptions,
) -> Result<(), LogError> {
    if opts.one_of.is_empty()
        || opts
            .one_of
            .iter()
            .any(|g| g.iter().all(|c| present.contains_key(c.as_str())))
    {
        return Ok(());
    }
    let each: Vec<String> = opts
        .one_of
        .iter()
        .map(|g| {
            let missing: Vec<&str> = g
                .iter()
                .map(String::as_str)
                .filter(|c| !present.contains_key(c))
                .collect();
            format!("{} (missing {})", g.join(", "), missing.join(", "))
        })
        .collect();
    let who = opts.needed_by.as_deref().unwrap_or("this log");
    Err(LogError::new(
        opts.file.as_str(),
        LogErrorKind::MissingColumns,
        format!(
            "{who} needs one complete group of measurements: {}",
            each.join(" or ")
        ),
    )
    .at_line(line))
}

/// Converts `psi` from degrees to radians in place; a warning when the
/// values never leave ±(2π + 0.1), which reads like radians declared as
/// degrees (a heading in degrees that turns by less than ~6° looks the same).
pub(super) fn heading_from_degrees(table: &mut LogTable) -> Option<LogWarning> {
    let i = table.names.iter().position(|n| n == "psi")?;
    let col = &mut table.data[i];
    let amax = col.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    col.iter_mut().for_each(|x| *x = x.to_radians());
    (amax <= std::f64::consts::TAU + 0.1).then(|| {
        LogWarning::column(
            "psi",
            format!(
                "psi is declared in degrees (heading_unit deg) but never exceeds {} in \
                 magnitude: it looks like radians; if so, declare heading_unit rad",
                echoed(amax)
            ),
        )
    })
}

/// Slope of a local linear least-squares fit to `y` at every sample
/// (sample interval `h`), over ±`m` samples, the window shrinking
/// symmetrically at the ends; the end samples take the one-sided difference.
pub fn local_slope(y: &[f64], h: f64, m: usize) -> Vec<f64> {
    let n = y.len();
    (0..n)
        .map(|k| {
            let mk = m.min(k).min(n - 1 - k);
            if mk == 0 {
                return match (k, n) {
                    (_, 0 | 1) => 0.0,
                    (0, _) => (y[1] - y[0]) / h,
                    _ => (y[k] - y[k - 1]) / h,
                };
            }
            let mut num = 0.0;
            let mut den = 0.0;
            for j in 1..=mk {
                let jf = j as f64;
                num += jf * (y[k + j] - y[k - j]);
                den += 2.0 * jf * jf;
            }
            num / (den * h)
        })
        .collect()
}

/// Adds body velocities `u`, `v` (m/s) and `r` (rad/s) derived from `x`,
/// `y`, `psi` to `rec` (see the module documentation), block by valid
/// block; samples outside valid blocks are 0 and unused. The window is at
/// least one sample each side. Errors name a missing pose column or a
/// velocity column already present.
pub fn derive_body_velocities(rec: &mut UniformRecord, half_window_s: f64) -> Result<(), String> {
    for c in ["u", "v", "r"] {
        if rec.column(c).is_some() {
            return Err(format!("the record already has the velocity {c}"));
        }
    }
    let col = |n: &str| {
        rec.column(n)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| format!("the pose column {n} is missing"))
    };
    let (x, y, psi) = (col("x")?, col("y")?, col("psi")?);
    let h = 1.0 / rec.sample_rate_hz;
    let m = ((half_window_s / h).round() as usize).max(1);
    let n = rec.len();
    let (mut u, mut v, mut r) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for b in &rec.valid {
        let mut heading = psi[b.clone()].to_vec();
        unwrap(&mut heading);
        let xd = local_slope(&x[b.clone()], h, m);
        let yd = local_slope(&y[b.clone()], h, m);
        let rd = local_slope(&heading, h, m);
        for (i, k) in b.clone().enumerate() {
            let (s, c) = heading[i].sin_cos();
            u[k] = c * xd[i] + s * yd[i];
            v[k] = -s * xd[i] + c * yd[i];
            r[k] = rd[i];
        }
    }
    for (name, data) in [("u", u), ("v", v), ("r", r)] {
        rec.names.push(name.to_string());
        rec.data.push(data);
    }
    Ok(())
}

/// Removes 2π jumps between consecutive samples.
fn unwrap(a: &mut [f64]) {
    use std::f64::consts::{PI, TAU};
    let mut offset = 0.0;
    for k in 1..a.len() {
        let raw = a[k] + offset;
        let d = raw - a[k - 1];
        if d > PI {
            offset -= TAU * ((d + PI) / TAU).floor();
        } else if d < -PI {
            offset += TAU * ((-d + PI) / TAU).floor();
        }
        a[k] += offset;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::logs::{LogRole, parse_log, to_uniform};
    use crate::planning::examples::supply_vessel;
    use crate::planning::vessel::HeadingUnit;

    /// A turning circle: speed U along a heading that turns at rate ω,
    /// sampled at 1 Hz, heading wrapped to (−π, π]. Body velocities are
    /// u = U, v = 0, r = ω exactly; x, y are sinusoids.
    fn circle(n: usize, deg: bool, columns: &str) -> String {
        let (speed, omega) = (2.0, 0.02);
        let mut csv = format!("t,thr_1,thr_2,thr_3,thr_4,thr_5,thr_6,{columns}\n");
        for k in 0..n {
            let t = k as f64;
            let psi = omega * t;
            let x = speed / omega * psi.sin();
            let y = speed / omega * (1.0 - psi.cos());
            let wrapped = (psi + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            let heading = if deg { wrapped.to_degrees() } else { wrapped };
            let row = match columns {
                "x,y,psi" => format!("{x},{y},{heading}"),
                "u,v,r" => format!("{speed},0,{omega}"),
                _ => format!("{x},{y}"),
            };
            csv.push_str(&format!(
                "{t},0.1,0.1,{},0,0,0,{row}\n",
                0.2 * (t / 50.0).sin()
            ));
        }
        csv
    }

    fn opts(deg: bool) -> ParseOptions {
        let mut v = supply_vessel();
        v.heading_unit = deg.then_some(HeadingUnit::Deg);
        ParseOptions::for_vessel(&v, LogRole::Single, None)
    }

    #[test]
    fn position_only_and_velocity_only_dp_logs_are_accepted() {
        let p = parse_log(circle(400, false, "x,y,psi").as_bytes(), &opts(false)).unwrap();
        assert!(p.table.column("u").is_none());
        assert!(p.table.column("psi").is_some());
        let p = parse_log(circle(400, false, "u,v,r").as_bytes(), &opts(false)).unwrap();
        assert!(p.table.column("x").is_none());
        let e = parse_log(circle(400, false, "x,y").as_bytes(), &opts(false)).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::MissingColumns);
        assert!(
            e.message
                .contains("u, v, r (missing u, v, r) or x, y, psi (missing psi)"),
            "{}",
            e.message
        );
    }

    #[test]
    fn body_velocities_from_a_turning_circle_are_exact_to_the_curvature() {
        for deg in [false, true] {
            let p = parse_log(circle(400, deg, "x,y,psi").as_bytes(), &opts(deg)).unwrap();
            assert!(
                p.warnings.iter().all(|w| !w.message.contains("psi")),
                "{:?}",
                p.warnings
            );
            let (mut rec, _) = to_uniform(&p.table, None).unwrap();
            derive_body_velocities(&mut rec, 3.0).unwrap();
            let (u, v, r) = (
                rec.column("u").unwrap(),
                rec.column("v").unwrap(),
                rec.column("r").unwrap(),
            );
            // Inside the window: the local linear fit of a sinusoid of
            // frequency ω over ±3 samples errs by ≈ ω²·(Σj⁴/Σj²)/6 ≈ 0.1 % of U.
            for k in 3..397 {
                assert!((u[k] - 2.0).abs() < 2e-3, "u[{k}] = {}", u[k]);
                assert!(v[k].abs() < 1e-9, "v[{k}] = {}", v[k]);
                assert!((r[k] - 0.02).abs() < 1e-9, "r[{k}] = {}", r[k]);
            }
            // The wrap of ψ through ±π (at t ≈ 157 s) leaves no spike.
            assert!(r.iter().all(|x| (x - 0.02).abs() < 1e-6));
            assert!(derive_body_velocities(&mut rec, 3.0).is_err());
        }
    }

    #[test]
    fn heading_declared_in_degrees_that_looks_like_radians_warns() {
        let p = parse_log(circle(100, false, "x,y,psi").as_bytes(), &opts(true)).unwrap();
        let w: Vec<_> = p
            .warnings
            .iter()
            .filter(|w| w.column.as_deref() == Some("psi"))
            .collect();
        assert_eq!(w.len(), 1, "{:?}", p.warnings);
        assert!(
            w[0].message.contains("looks like radians"),
            "{}",
            w[0].message
        );
        // Radians declared for a log in degrees: the contract's warning.
        let p = parse_log(circle(400, true, "x,y,psi").as_bytes(), &opts(false)).unwrap();
        assert!(
            p.warnings
                .iter()
                .any(|w| w.message.starts_with("psi looks like degrees"))
        );
    }
}
