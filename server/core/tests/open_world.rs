//! The λ-filter campaign identification on campaigns it did not plan or
//! simulate: five vessels drawn from seeded ranges by the independent truth
//! (`seatrial-truth`), flown by another team's 20 Hz PI controller with a
//! wrong nominal g(η) feed-forward, logged at 10 Hz, statics at grid speed
//! with no attitude holds, a validation run stepping between and beyond the
//! grid. Run `cargo run --release -p seatrial-core --example open_world_table`
//! for the full table.

mod support;

use seatrial_core::identification::LambdaCampaignSettings;
use support::open_world::{SeedReport, evaluate};

const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

/// The five identifications, computed once for all tests.
fn reports() -> &'static [SeedReport] {
    static REPORTS: std::sync::OnceLock<Vec<SeedReport>> = std::sync::OnceLock::new();
    REPORTS.get_or_init(|| evaluate_all(&LambdaCampaignSettings::default()))
}

/// The five vessels identified with `settings`.
fn evaluate_all(settings: &LambdaCampaignSettings) -> Vec<SeedReport> {
    SEEDS.iter().map(|&s| evaluate(s, true, settings)).collect()
}

/// The same with M's rows fitted freely and the nearest symmetric M
/// stored (`symmetric_inertia: false`).
fn projected_reports() -> &'static [SeedReport] {
    static REPORTS: std::sync::OnceLock<Vec<SeedReport>> = std::sync::OnceLock::new();
    REPORTS.get_or_init(|| {
        evaluate_all(&LambdaCampaignSettings {
            symmetric_inertia: false,
            ..LambdaCampaignSettings::default()
        })
    })
}

/// With linear damping only (`quadratic_damping: false`, the thesis's
/// model).
fn linear_damping_reports() -> &'static [SeedReport] {
    static REPORTS: std::sync::OnceLock<Vec<SeedReport>> = std::sync::OnceLock::new();
    REPORTS.get_or_init(|| evaluate_all(&linear_damping()))
}

fn linear_damping() -> LambdaCampaignSettings {
    LambdaCampaignSettings {
        quadratic_damping: false,
        ..LambdaCampaignSettings::default()
    }
}

/// The same without the second-order Coriolis force (`coriolis_second_order`).
fn linear_reports() -> &'static [SeedReport] {
    static REPORTS: std::sync::OnceLock<Vec<SeedReport>> = std::sync::OnceLock::new();
    REPORTS.get_or_init(|| {
        evaluate_all(&LambdaCampaignSettings {
            coriolis_second_order: false,
            ..LambdaCampaignSettings::default()
        })
    })
}

/// g(η) comes from ordinary runs (no attitude holds were flown) and the
/// controller's nominal feed-forward is not mistaken for it: W − B and
/// z_G·W − z_B·B within 3σ or 1 % of the truth on every vessel.
#[test]
fn restoring_forces_come_from_ordinary_runs() {
    for r in reports() {
        for name in ["W−B", "z_G·W − z_B·B"] {
            let z =
                r.z.iter()
                    .find(|z| z.name == name)
                    .unwrap_or_else(|| panic!("seed {}: no {name} in {:?}", r.seed, r.notes));
            let rel = (z.estimate - z.truth).abs() / z.truth.abs().max(1.0);
            assert!(
                z.z().abs() <= 3.0 || rel <= 0.01,
                "seed {}: {name} = {:.3} ± {:.3} against {:.3}",
                r.seed,
                z.estimate,
                z.std,
                z.truth
            );
        }
    }
}

/// The attitude's noise, which γ = τ − g(η) carries as a force the vehicle
/// never felt, is found (the truth's 2 mrad within 15 %) and discounted:
/// the roll inertia at every grid speed within 3σ and 4 % of the truth
/// (least squares without the discount: high at 19 of 20, by up to 8.5 %), the pitch inertia
/// within 3σ (at speed it stays up to 25 % high, within 2σ).
#[test]
fn the_attitude_noise_does_not_inflate_roll_and_pitch_inertia() {
    for r in reports() {
        let note = r
            .notes
            .iter()
            .find(|n| n.contains("mrad in roll"))
            .unwrap_or_else(|| panic!("seed {}: no attitude noise in {:?}", r.seed, r.notes));
        let found: Vec<f64> = note
            .split_whitespace()
            .filter_map(|w| w.parse::<f64>().ok())
            .take(2)
            .collect();
        assert!(
            found.len() == 2 && found.iter().all(|v| (v - 2.0).abs() <= 0.3),
            "seed {}: {note}",
            r.seed
        );
        for z in r
            .z
            .iter()
            .filter(|z| z.name.starts_with("M[roll,roll]") || z.name.starts_with("M[pitch,pitch]"))
        {
            let rel = (z.estimate - z.truth).abs() / z.truth;
            let bound = if z.name.starts_with("M[roll") {
                0.04
            } else {
                f64::INFINITY
            };
            assert!(
                z.z().abs() <= 3.0 && rel <= bound,
                "seed {}: {} = {:.3} ± {:.3} against {:.3}",
                r.seed,
                z.name,
                z.estimate,
                z.std,
                z.truth
            );
        }
    }
}

/// Every stored sub-model is physical: M symmetric positive definite and
/// the damping D = D̄ − J_C(M, u₀) dissipative, and its free run on the
/// held-out run is finite.
#[test]
fn every_stored_sub_model_is_physical_and_simulable() {
    for r in reports() {
        assert!(!r.physical.is_empty());
        for (speed, ok, why) in &r.physical {
            assert!(ok, "seed {} at {speed:.2} m/s: {why}", r.seed);
        }
        for c in &r.fits {
            assert!(
                c.free_run.is_some_and(f64::is_finite),
                "seed {} {}",
                r.seed,
                c.channel
            );
        }
    }
}

/// One-step predictions on the held-out run: never worse than the affine
/// least-squares baseline, and within 0.02 of the true model in surge,
/// sway, heave and yaw.
#[test]
fn one_step_fits_beat_the_affine_baseline_and_approach_the_truth() {
    for r in reports() {
        for c in &r.fits {
            let (est, truth, affine) = (
                c.one_step.expect("a 1-step fit"),
                c.one_step_true.expect("the true model's fit"),
                c.one_step_affine.expect("the baseline's fit"),
            );
            assert!(
                est >= affine - 0.005,
                "seed {} {}: {est:.3} below the affine baseline {affine:.3}",
                r.seed,
                c.channel
            );
            if ["u", "v", "w", "r"].contains(&c.channel.as_str()) {
                assert!(
                    est >= truth - 0.02,
                    "seed {} {}: {est:.3} against the true model's {truth:.3}",
                    r.seed,
                    c.channel
                );
            }
        }
    }
}

/// Reported σ are honest enough to bet on, the issue's ≥ 95 % within ±3σ
/// of the truth's best linear fit (a symmetric pair of M counted once) on
/// every vessel: the 20 Hz controller's unlogged commands corrected with
/// their own σ (half the correction c·K), σ of M inflated by its spread
/// across the grid and scaled by the rows' disagreement with M = Mᵀ
/// (97–100 % measured on vessels 1–12; 96–100 % on 1–5 and 94.5–100 %
/// on 1–12 with linear damping only).
#[test]
fn most_parameters_lie_within_three_reported_sigma() {
    for (floor, reports) in [(0.95, reports()), (0.95, linear_damping_reports())] {
        for r in reports {
            let within = r.z.iter().filter(|z| z.z().abs() <= 3.0).count();
            assert!(
                within as f64 >= floor * r.z.len() as f64,
                "seed {}: {within}/{} within ±3σ (floor {floor})",
                r.seed,
                r.z.len()
            );
        }
    }
}

/// Fitting M symmetric (the rows re-estimated under M = Mᵀ over their joint
/// posterior, D̄ moving with M) against fitting the rows freely and storing
/// the nearest symmetric M with D̄ unchanged: the whole-run free runs on the
/// held-out staircase gain summed over the five vessels' 30 channels
/// (+0.86 when measured with the model held above the grid; vessel 5 pitch
/// 0.54 → 0.79), no channel loses more than 0.02, and the share within ±3σ
/// falls by no more than 0.01 on any vessel. Its sub-models are physical.
#[test]
fn fitting_m_symmetric_beats_projecting_it() {
    let within = |r: &SeedReport| {
        r.z.iter().filter(|z| z.z().abs() <= 3.0).count() as f64 / r.z.len() as f64
    };
    let mut gain = 0.0;
    for (r, p) in reports().iter().zip(projected_reports()) {
        for (speed, ok, why) in &r.physical {
            assert!(ok, "seed {} at {speed:.2} m/s: {why}", r.seed);
        }
        for (a, b) in r.fits.iter().zip(&p.fits) {
            let (fa, fb) = (a.free_run.unwrap(), b.free_run.unwrap());
            assert!(
                fa >= fb - 0.02,
                "seed {} {}: free run {fa:.3} fitted symmetric, {fb:.3} projected",
                r.seed,
                a.channel
            );
            gain += fa - fb;
        }
        assert!(
            within(r) >= within(p) - 0.01,
            "seed {}: {:.3} within ±3σ fitted symmetric, {:.3} projected",
            r.seed,
            within(r),
            within(p)
        );
    }
    assert!(gain > 0.5, "summed free-run gain {gain:.3}");
}

/// C(δ)δ of the estimated M (no parameter added) carries the centripetal
/// forces of turning, heaving and rolling the linear sub-models cannot:
/// on the held-out staircase the whole-run free runs gain +0.89 summed
/// over the five vessels' 30 channels (surge 0.04–0.08 below the true
/// model before, 0.01–0.06 after; vessel 5 roll −0.40 → −0.18), no channel
/// loses more than 0.002, and surge is within 0.03 of the true model on
/// four of the five vessels. Where it would cost, the identification leaves it out
/// and says so.
#[test]
fn the_second_order_coriolis_force_closes_the_free_run_gap() {
    let mut gain = 0.0;
    let mut surge_close = 0;
    for (r, l) in reports().iter().zip(linear_reports()) {
        for (a, b) in r.fits.iter().zip(&l.fits) {
            let (fa, fb) = (a.free_run.unwrap(), b.free_run.unwrap());
            assert!(
                fa >= fb - 0.02,
                "seed {} {}: free run {fa:.3} with C(δ)δ, {fb:.3} without",
                r.seed,
                a.channel
            );
            gain += fa - fb;
        }
        let u = &r.fits[0];
        assert_eq!(u.channel, "u");
        if u.free_run.unwrap() >= u.free_run_true.unwrap() - 0.03 {
            surge_close += 1;
        }
        let carried = r
            .notes
            .iter()
            .any(|n| n.contains("carries the second-order"));
        let left_out = r.notes.iter().any(|n| n.contains("was left out"));
        assert!(carried != left_out, "seed {}: {:?}", r.seed, r.notes);
    }
    assert!(gain > 0.5, "summed free-run gain {gain:.3}");
    assert!(
        surge_close >= 4,
        "surge within 0.03 of the truth on {surge_close} of 5"
    );
}

/// Free runs keep the restoring spring (g(η) of the simulated attitude),
/// never the open-loop drift of a γ taken from the measured attitude (roll
/// −6.0…0.08 before): roll and pitch free runs stay above 0.25 on every
/// vessel and above 0.7 on four of the five (0.30–0.86 measured; the small,
/// fast vessel 5 is the weak one).
#[test]
fn roll_and_pitch_free_runs_keep_their_restoring_spring() {
    let mut good = 0;
    for r in reports() {
        let attitude: Vec<f64> = r
            .fits
            .iter()
            .filter(|c| ["p", "q"].contains(&c.channel.as_str()))
            .map(|c| c.free_run.expect("a free-run fit"))
            .collect();
        assert_eq!(attitude.len(), 2);
        let worst = attitude.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(
            worst > 0.25,
            "seed {}: roll/pitch free run {worst:.3}",
            r.seed
        );
        good += usize::from(worst > 0.7);
    }
    assert!(good >= 4, "{good} of 5 vessels above 0.7");
}

/// Below the grid the model extends its lowest sub-models (damping
/// linear, load quadratic in speed) instead of holding the 0.5 m/s one: on
/// the staircase's 0.3 m/s leg (a fifth of the validation run) the
/// free runs gain in sway, heave and yaw on every vessel (+0.006…+0.10
/// measured) and lose nowhere more than surge's 0.03; over all channels and
/// vessels +0.6 in sum. The stored document reproduces the identification's
/// own validation, extension included.
#[test]
fn the_extension_below_the_grid_improves_free_runs() {
    let mut total = 0.0;
    for r in reports() {
        for c in &r.fits {
            let (ext, held) = (c.free_run_stored.unwrap(), c.free_run_held.unwrap());
            assert!(
                (ext - c.free_run.unwrap()).abs() < 1e-9,
                "seed {} {}: stored {ext} against the job's {:?}",
                r.seed,
                c.channel,
                c.free_run
            );
            assert!(
                ext > held - 0.045,
                "seed {} {}: {held:.3} held → {ext:.3} extended",
                r.seed,
                c.channel
            );
            if ["v", "w", "r"].contains(&c.channel.as_str()) {
                assert!(
                    ext > held,
                    "seed {} {}: {held:.3} → {ext:.3}",
                    r.seed,
                    c.channel
                );
            }
            total += ext - held;
        }
        assert!(
            r.notes.iter().any(|n| n.contains("down to 0.20 m/s")),
            "seed {}: {:?}",
            r.seed,
            r.notes
        );
    }
    assert!(total > 0.4, "sum of free-run gains {total:.3}");
}

/// Quadratic damping D_q|δ|δ (default), one per campaign (pooled over the grid
/// points' joint estimates, the sub-models then fitted with it known):
/// the truth's hulls damp 30–70 % quadratically, so a linear sub-model
/// fitted to the estimation runs' amplitudes over- or under-damps the
/// validation staircase's. On vessels 1–5 the whole-run free runs gain
/// over the 30 channels, no channel losing more than 0.025; on vessel 7,
/// whose yaw damping is 67 % quadratic, yaw gains 0.892 → 0.967 and sway
/// 0.913 → 0.955, within 0.02 of the true model. The pooled D_q lie within
/// 3σ of the truth's own on all but one DOF per vessel.
#[test]
fn quadratic_damping_follows_the_amplitude_of_the_motion() {
    let mut gain = 0.0;
    for (r, l) in reports().iter().zip(linear_damping_reports()) {
        for (a, b) in r.fits.iter().zip(&l.fits) {
            let (fa, fb) = (a.free_run.unwrap(), b.free_run.unwrap());
            assert!(
                fa >= fb - 0.025,
                "seed {} {}: free run {fa:.3} with D_q, {fb:.3} without",
                r.seed,
                a.channel
            );
            gain += fa - fb;
        }
        let d_q: Vec<_> = r.z.iter().filter(|z| z.name.starts_with("D_q")).collect();
        assert!(!d_q.is_empty(), "seed {}: no D_q graded", r.seed);
        let off = d_q.iter().filter(|z| z.z().abs() > 3.0).count();
        assert!(off <= 1, "seed {}: {off} D_q beyond 3σ", r.seed);
    }
    assert!(gain > 0.05, "summed free-run gain {gain:.3}");
    let with = evaluate(7, true, &LambdaCampaignSettings::default());
    let without = evaluate(7, true, &linear_damping());
    for (a, b) in with.fits.iter().zip(&without.fits) {
        let (fa, fb) = (a.free_run.unwrap(), b.free_run.unwrap());
        if ["v", "r"].contains(&a.channel.as_str()) {
            assert!(fa > fb + 0.03, "vessel 7 {}: {fb:.3} → {fa:.3}", a.channel);
            assert!(
                fa >= a.free_run_true.unwrap() - 0.03,
                "vessel 7 {}: {fa:.3} against the true model's {:.3}",
                a.channel,
                a.free_run_true.unwrap()
            );
        }
    }
}

/// The issue's criteria on the five vessels: ≥ 95 % of parameters within
/// ±3σ, 1-step within 0.02 and whole-run free run within 0.05 of the true
/// model in every channel (met on all 12 seeded vessels: `open_world_table
/// 1 … 12`; closest, vessel 5 pitch free run 0.849 against 0.899). With
/// linear damping only, vessel 5 misses (free runs 0.06–0.12 below in
/// surge, sway, heave and pitch: the surge drag below the grid, see
/// `identification/lambda_quadratic.rs`).
#[test]
fn the_issue_criteria_on_five_vessels() {
    for r in reports() {
        let within = r.z.iter().filter(|z| z.z().abs() <= 3.0).count();
        assert!(
            within as f64 >= 0.95 * r.z.len() as f64,
            "seed {}: {within}/{}",
            r.seed,
            r.z.len()
        );
        for c in &r.fits {
            let (one, one_true) = (c.one_step.unwrap(), c.one_step_true.unwrap());
            let (free, free_true) = (c.free_run.unwrap(), c.free_run_true.unwrap());
            assert!(
                one >= one_true - 0.02 && free >= free_true - 0.05,
                "seed {} {}: 1-step {one:.4} against {one_true:.4}, free run {free:.4} against {free_true:.4}",
                r.seed,
                c.channel
            );
        }
    }
}
