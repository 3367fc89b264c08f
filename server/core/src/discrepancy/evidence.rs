//! Plain-words effects and the evidence that separates look-alikes:
//! lag vs delay (the lag of the peak input–residual cross-correlation),
//! current vs tether (does the load turn with heading?), quadratic damping
//! vs saturation (does the misfit follow ν or τ?), cubic vs quadratic
//! damping (is the speed range wide enough for ν³ and |ν|ν to differ?),
//! cross-flow damping |ν_j|ν_i vs a Coriolis product ν_j·ν_i (sign of ν_j)
//! and vs |ν_i|ν_i.

use super::candidates::Effect;
use super::data::Record;
use super::model::ModelTerm;
use crate::planning::Dof;

fn pm(v: f64, s: Option<f64>) -> String {
    match s.filter(|x| x.is_finite()) {
        Some(s) => format!("{} ± {}", sig(v), sig(s)),
        None => sig(v),
    }
}

/// Three significant digits without noise (`—` for no number, `2.5e7`
/// beyond 10⁶: [`crate::numbers::sig3`]).
fn sig(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() || v.abs() >= 1e6 {
        return crate::numbers::sig3(v);
    }
    let d = (3 - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.d$}")
}

fn std_of(t: &ModelTerm, i: usize) -> Option<f64> {
    t.covariance
        .get(i)
        .and_then(|r| r.get(i))
        .map(|v| v.max(0.0).sqrt())
}

/// What a chosen term does, in one sentence.
pub(crate) fn effect_text(t: &ModelTerm, h: f64) -> String {
    let c = |i: usize| t.coefficients.get(i).copied().unwrap_or(f64::NAN);
    match t.effect {
        Effect::QuadraticDamping { dof } => format!(
            "Damping in {} grows with speed: an extra {}·|{s}|{s} of {} {}·s²/{}².",
            dof.name(),
            dof.force_column(),
            pm(c(0), std_of(t, 0)),
            dof.force_unit(),
            if dof.is_angular() { "rad" } else { "m" },
            s = dof.velocity_symbol()
        ),
        Effect::CubicDamping { dof } => format!(
            "Damping in {} grows steeply at the top of the speed range: an extra {}·{s}³ of {} {}·s³/{}³.",
            dof.name(),
            dof.force_column(),
            pm(c(0), std_of(t, 0)),
            dof.force_unit(),
            if dof.is_angular() { "rad" } else { "m" },
            s = dof.velocity_symbol()
        ),
        Effect::CrossDamping { dof, from } => format!(
            "Damping in {} grows with the size of {} ({}, either sign): an extra {}·|{j}|{i} of {} {}/(({})·({})).",
            dof.name(),
            from.velocity_symbol(),
            from.name(),
            dof.force_column(),
            pm(c(0), std_of(t, 0)),
            dof.force_unit(),
            dof.velocity_unit(),
            from.velocity_unit(),
            i = dof.velocity_symbol(),
            j = from.velocity_symbol()
        ),
        Effect::CoriolisFromM => format!(
            "Coriolis–centripetal forces C(ν)ν built from the model's M act, at scale {} (1 = as M predicts).",
            pm(c(0), std_of(t, 0))
        ),
        Effect::CoriolisProduct { dof, a, b } => format!(
            "{} feels a Coriolis-type force {}·{}·{} {}.",
            super::locate::capital(dof.name()),
            pm(c(0), std_of(t, 0)),
            a.velocity_symbol(),
            b.velocity_symbol(),
            dof.force_unit()
        ),
        Effect::Restoring { dof, .. } => format!(
            "{} has a restoring term the baseline's g(η) lacks: {} {} per unit of the attitude shape.",
            super::locate::capital(dof.name()),
            pm(c(0), std_of(t, 0)),
            dof.force_unit()
        ),
        Effect::ConstantLoad { dof } => format!(
            "A constant {} of {} {} acts in {} (a tether or mooring pull along the body axes, a buoyancy or trim error, or a thrust bias).",
            if dof.is_angular() { "moment" } else { "force" },
            pm(c(0), std_of(t, 0)),
            dof.force_unit(),
            dof.name()
        ),
        Effect::Current => {
            let (n, e) = (c(0), c(1));
            let speed = n.hypot(e);
            let to = e.atan2(n).to_degrees().rem_euclid(360.0);
            format!(
                "A current of {} m/s setting towards {:.0}° (north {}, east {} m/s) acts through the damping.",
                sig(speed),
                to,
                pm(n, std_of(t, 0)),
                pm(e, std_of(t, 1))
            )
        }
        Effect::TetherPull => {
            let (n, e) = (c(0), c(1));
            let to = e.atan2(n).to_degrees().rem_euclid(360.0);
            format!(
                "A pull of {} N fixed in NED towards {:.0}° (north {}, east {} N) acts on the hull, as a tether to the ship, a towline or a mooring line does.",
                sig(n.hypot(e)),
                to,
                pm(n, std_of(t, 0)),
                pm(e, std_of(t, 1))
            )
        }
        Effect::Coupling { dof, from } => format!(
            "{} couples into {}: M_{i}{j} = {}, D̄_{i}{j} = {}.",
            super::locate::capital(from.name()),
            dof.name(),
            pm(c(0), std_of(t, 0)),
            pm(c(1), std_of(t, 1)),
            i = dof.velocity_symbol(),
            j = from.velocity_symbol()
        ),
        Effect::ActuatorLag { dof } => format!(
            "Thrust in {} follows the command through a first-order lag T_a = {} s.",
            dof.name(),
            pm(t.shape.unwrap_or(f64::NAN), t.shape_std)
        ),
        Effect::CommonActuatorLag => format!(
            "Thrust in every DOF follows the command through one first-order lag T_a = {} s: thrusters of one kind answering alike.",
            pm(t.shape.unwrap_or(f64::NAN), t.shape_std)
        ),
        Effect::InputDelay { dof } => {
            let d = t.shape.unwrap_or(0.0);
            format!(
                "Thrust in {} acts {:.0} samples ({} s) after the command.",
                dof.name(),
                d,
                sig(d * h)
            )
        }
        Effect::CommonInputDelay => {
            let d = t.shape.unwrap_or(0.0);
            format!(
                "Thrust in every DOF acts {:.0} samples ({} s) after the command: a delay of the command link or of the log's time stamps.",
                d,
                sig(d * h)
            )
        }
        Effect::Saturation { dof } => format!(
            "Thrust in {} saturates at ±{} {}.",
            dof.name(),
            pm(t.shape.unwrap_or(f64::NAN), t.shape_std),
            dof.force_unit()
        ),
        Effect::DeadZone { dof } => format!(
            "Commands in {} below {} {} produce no thrust.",
            dof.name(),
            pm(t.shape.unwrap_or(f64::NAN), t.shape_std),
            dof.force_unit()
        ),
    }
}

/// Lag (samples) of the peak cross-correlation between the input changes
/// Δτ_i and the residual e_i, over 0..=max_lag: a delay d puts it at d,
/// a first-order lag at 0–1 samples with a slow tail.
pub(crate) fn xcorr_peak(
    runs: &[&Record],
    resid: &[Vec<f64>],
    row: usize,
    max_lag: usize,
) -> Option<(usize, f64)> {
    let mut acc = vec![0.0; max_lag + 1];
    let (mut ee, mut tt) = (0.0, 0.0);
    for (rec, e) in runs.iter().zip(resid) {
        let tau = rec.tau.column(row);
        let n = rec.len();
        for k in max_lag + 1..n {
            if !e[k].is_finite() {
                continue;
            }
            ee += e[k] * e[k];
            let dt = tau[k] - tau[k - 1];
            tt += dt * dt;
            for (l, a) in acc.iter_mut().enumerate() {
                // e[k] against Δτ[k − l]: the residual after the change.
                let dtl = tau[k - l] - tau[k - l - 1];
                *a += e[k] * dtl;
            }
        }
    }
    if ee <= 0.0 || tt <= 0.0 {
        return None;
    }
    let norm = (ee * tt).sqrt();
    acc.iter()
        .enumerate()
        .map(|(l, a)| (l, (a / norm).abs()))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// [`xcorr_peak`] of row `r`'s baseline 1-step residual, over 20 samples.
fn row_peak(runs: &[&Record], baseline_resid: &[Vec<Vec<f64>>], r: usize) -> Option<(usize, f64)> {
    let resid: Vec<Vec<f64>> = baseline_resid.iter().map(|v| v[r].clone()).collect();
    xcorr_peak(runs, &resid, r, 20)
}

/// A peak two samples or more after the command's change: a pure delay's
/// answer (a first-order lag answers at 0–1 samples and fades).
fn answers_late(lag: usize) -> bool {
    lag >= 2
}

/// For an actuator effect on every DOF (a common lag or delay): after how
/// many samples each DOF's baseline 1-step residual follows a change of
/// its command most strongly ([`xcorr_peak`]), and how many answer late,
/// as a pure delay does, rather than at once and fading, as a first-order
/// lag does.
fn answer_delays(
    runs: &[&Record],
    baseline_resid: &[Vec<Vec<f64>>],
    dofs: &[Dof],
    h: f64,
) -> Option<String> {
    let peaks: Vec<(Dof, usize, f64)> = dofs
        .iter()
        .enumerate()
        .filter_map(|(r, &d)| row_peak(runs, baseline_resid, r).map(|(lag, rho)| (d, lag, rho)))
        .collect();
    if peaks.is_empty() {
        return None;
    }
    let late = peaks.iter().filter(|p| answers_late(p.1)).count();
    let each: Vec<String> = peaks
        .iter()
        .map(|(d, lag, rho)| {
            format!(
                "{} {lag} ({} s, ρ = {rho:.2})",
                d.name(),
                sig(*lag as f64 * h)
            )
        })
        .collect();
    Some(format!(
        "The baseline's 1-step residuals follow a change of the command most strongly after: {}. {late} of {} DOFs answer late, as a pure delay shows; the others at once and fading, as a first-order lag gives.",
        each.join(", "),
        peaks.len()
    ))
}

/// Fraction of the circle of headings the runs cover (8 sectors).
pub(crate) fn heading_coverage(runs: &[&Record]) -> f64 {
    let mut sectors = [false; 8];
    for r in runs {
        for k in 0..r.len() {
            let s = (r.eta[(k, 5)].rem_euclid(std::f64::consts::TAU)
                / (std::f64::consts::TAU / 8.0)) as usize;
            sectors[s.min(7)] = true;
        }
    }
    sectors.iter().filter(|&&s| s).count() as f64 / 8.0
}

/// Correlation of |ν_i| with |τ_i| in the runs: near 1, speed- and
/// thrust-dependent effects cannot be told apart.
pub(crate) fn speed_thrust_correlation(runs: &[&Record], row: usize) -> f64 {
    let pairs: Vec<(f64, f64)> = runs
        .iter()
        .flat_map(|r| (0..r.len()).map(move |k| (r.nu[(k, row)].abs(), r.tau[(k, row)].abs())))
        .collect();
    let n = pairs.len() as f64;
    if n < 3.0 {
        return f64::NAN;
    }
    let mx = pairs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pairs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pairs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pairs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = pairs.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx > 0.0 && syy > 0.0 {
        sxy / (sxx * syy).sqrt()
    } else {
        f64::NAN
    }
}

/// Sentences specific to the look-alike pairs of `e`.
pub(crate) fn separating_evidence(
    e: Effect,
    runs: &[&Record],
    baseline_resid: &[Vec<Vec<f64>>],
    dofs: &[Dof],
    h: f64,
) -> Vec<String> {
    let row = e.dof().and_then(|d| dofs.iter().position(|&x| x == d));
    let mut out = Vec::new();
    match (e, row) {
        (Effect::ActuatorLag { dof } | Effect::InputDelay { dof }, Some(r)) => {
            if let Some((lag, rho)) = row_peak(runs, baseline_resid, r) {
                out.push(format!(
                    "The baseline's 1-step residual in {} follows a change of {} most strongly after {lag} samples ({} s, ρ = {:.2}): {}.",
                    dof.name(),
                    dof.force_column(),
                    sig(lag as f64 * h),
                    rho,
                    if answers_late(lag) {
                        "a pure delay shows this way; a lag would answer at once and fade"
                    } else {
                        "an immediate, fading answer, as a first-order lag gives; a delay would answer later"
                    }
                ));
            }
        }
        (e, _) if e.on_every_command() => {
            out.extend(answer_delays(runs, baseline_resid, dofs, h));
        }
        (Effect::Current, _) => {
            out.push(format!(
                "The runs cover {:.0} % of the compass; the fitted load turns with heading in the body frame, which a bias cannot, and scales with the damping, which a tether's pull does not.",
                100.0 * heading_coverage(runs)
            ));
        }
        (Effect::TetherPull, _) => {
            out.push(format!(
                "The runs cover {:.0} % of the compass; the fitted pull turns with heading in the body frame, which a bias cannot, and does not scale with the damping, which a current would.",
                100.0 * heading_coverage(runs)
            ));
        }
        (
            Effect::ConstantLoad {
                dof: Dof::Surge | Dof::Sway,
            },
            _,
        ) => {
            out.push(format!(
                "The runs cover {:.0} % of the compass and the load stays fixed in the body frame, which a current would not.",
                100.0 * heading_coverage(runs)
            ));
        }
        (
            Effect::QuadraticDamping { dof }
            | Effect::Saturation { dof }
            | Effect::DeadZone { dof },
            Some(r),
        ) => {
            let c = speed_thrust_correlation(runs, r);
            out.push(format!(
                "|{}| and |{}| correlate at {:.2} in these runs, {}.",
                dof.velocity_symbol(),
                dof.force_column(),
                c,
                if c < 0.8 {
                    "so a misfit that follows speed is told from one that follows thrust"
                } else {
                    "too closely to tell speed- from thrust-dependence"
                }
            ));
        }
        (Effect::CubicDamping { dof }, Some(r)) => {
            let (lo, hi) = speed_spread(runs, r);
            out.push(format!(
                "|{s}| spans {} to {} {} (10th to 90th percentile) in these runs: {}.",
                sig(lo),
                sig(hi),
                dof.velocity_unit(),
                if hi > 2.0 * lo.max(f64::MIN_POSITIVE) {
                    "a spread over which c·{s}³ bends away from d·|{s}|{s} (ν³/|ν|ν grows as |ν|), so the two shapes can be told apart"
                } else {
                    "too narrow a band for c·{s}³ and d·|{s}|{s} to look different; a run over a wider speed range decides"
                }
                .replace("{s}", dof.velocity_symbol()),
                s = dof.velocity_symbol()
            ));
        }
        (Effect::CrossDamping { dof, from }, Some(r)) => {
            let j = dofs.iter().position(|&x| x == from);
            let (u, w) = (dof.velocity_symbol(), from.velocity_symbol());
            if let Some(j) = j {
                let (sym, odd) = sign_symmetry(runs, r, j);
                out.push(format!(
                    "The term depends on |{w}|, not on the sign of {w}: a Coriolis-type product {w}·{u} would change sign with {w}, quadratic damping |{u}|{u} would not depend on {w} at all. In these runs |{w}|·{u} and {w}·{u} correlate at {:.2} and |{w}|·{u} and |{u}|{u} at {:.2}, {}.",
                    odd,
                    sym,
                    if odd.abs() < 0.8 && sym.abs() < 0.9 {
                        "so the three shapes are told apart"
                    } else {
                        "too closely to tell the shapes apart; a run with both signs of the other velocity decides"
                    }
                ));
            }
        }
        _ => {}
    }
    out
}

/// 10th and 90th percentile of |ν_row| over the runs.
fn speed_spread(runs: &[&Record], row: usize) -> (f64, f64) {
    let mut v: Vec<f64> = runs
        .iter()
        .flat_map(|r| r.nu.column(row).iter().map(|x| x.abs()).collect::<Vec<_>>())
        .filter(|x| x.is_finite())
        .collect();
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p) as usize];
    (q(0.1), q(0.9))
}

/// Correlations of the cross-flow regressor |ν_j|ν_i with the quadratic
/// |ν_i|ν_i and with the Coriolis-type product ν_j·ν_i.
fn sign_symmetry(runs: &[&Record], i: usize, j: usize) -> (f64, f64) {
    let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
    for r in runs {
        for k in 0..r.len() {
            let (vi, vj) = (r.nu[(k, i)], r.nu[(k, j)]);
            a.push(vj.abs() * vi);
            b.push(vi.abs() * vi);
            c.push(vj * vi);
        }
    }
    (correlation(&a, &b), correlation(&a, &c))
}

fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    if n < 3.0 {
        return f64::NAN;
    }
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let syy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    if sxx > 0.0 && syy > 0.0 {
        sxy / (sxx * syy).sqrt()
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A residual that is the command's change three samples earlier peaks
    /// at lag 3 with |ρ| near 1 (the sums' ends differ by the window); one that answers at once and fades (a
    /// first-order lag's) peaks at 0.
    #[test]
    fn the_residual_follows_the_command_after_its_delay() {
        let n = 400;
        // A random binary command held 5–14 samples (no period for the
        // correlation to alias on).
        let mut rng = crate::rng::SplitMix64::new(7);
        let (mut level, mut left) = (1.0, 0);
        let tau = DMatrix::from_fn(n, 1, |_, _| {
            if left == 0 {
                level = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                left = 5 + (rng.uniform() * 10.0) as usize;
            }
            left -= 1;
            level
        });
        let rec = Record {
            name: "r".into(),
            h: 0.1,
            tau: tau.clone(),
            nu: DMatrix::zeros(n, 1),
            eta: DMatrix::zeros(n, 6),
        };
        let dtau = |k: usize| {
            if k == 0 {
                0.0
            } else {
                tau[(k, 0)] - tau[(k - 1, 0)]
            }
        };
        let delayed: Vec<f64> = (0..n)
            .map(|k| if k >= 3 { dtau(k - 3) } else { 0.0 })
            .collect();
        let (lag, rho) = xcorr_peak(&[&rec], &[delayed], 0, 10).expect("a peak");
        assert_eq!(lag, 3);
        assert!(rho > 0.95, "ρ = {rho}");
        // e[k] = Σ_j a^j Δτ[k − j]: the answer of a lag, largest at once.
        let mut e = vec![0.0; n];
        for k in 1..n {
            e[k] = 0.6 * e[k - 1] + dtau(k);
        }
        let (lag, _) = xcorr_peak(&[&rec], &[e.clone()], 0, 10).expect("a peak");
        assert_eq!(lag, 0);
        let text = answer_delays(&[&rec], &[vec![e]], &[Dof::Sway], 0.1).expect("a sentence");
        assert!(
            text.contains("sway 0 (0 s") && text.contains("0 of 1 DOFs answer late"),
            "{text}"
        );
    }
}
