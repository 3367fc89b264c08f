//! Missing-physics discovery on campaigns it did not plan or simulate: the
//! independent truth (`seatrial-truth`) with a concealed effect, flown by
//! another team's controller, identified and examined by the service. The
//! full table: `cargo run --release -p seatrial-core --example
//! open_world_discovery [seeds…]`.
//!
//! What holds today, and is held here: a steady current is named first at
//! every grid speed; no augmented model worse than its baseline on a
//! held-out channel is kept; and a concealed 0.4 s actuator lag is named
//! first as one lag in every DOF and kept, closing most of the 10 s
//! free-run gap to the true model (seed 1: 50–73 % on the five channels
//! with a gap above 0.1); a tether's pull fixed in NED is
//! named first and kept, closing most of the gap; a periodic sway force
//! outside the library is reported unexplained at its frequency and size,
//! and no term fitted through it is kept; on the clean vessel what the
//! held-out runs do not favour is reported as tried, not named; a heave
//! saturation is named first by its held-out advantage.

mod support;

use seatrial_core::identification::LambdaCampaignSettings;
use seatrial_core::planning::Dof;
use support::open_world::identify;
use support::open_world_discovery::{
    Concealed, DiscoveryCase, discover_case, discovery_baseline_settings,
};

/// Nothing kept is worse than the baseline on any held-out channel (1-step
/// or 10 s restarted free run, beyond 0.005), every named effect carries
/// its held-out verdict, and a refused model's verdict says why.
fn gate_holds(c: &DiscoveryCase) {
    for (k, (label, _, _)) in c.kept.iter().zip(&c.named) {
        let why = k.1.as_deref().unwrap_or_default();
        assert!(k.0.is_some() && !why.is_empty(), "{label}: {k:?}");
    }
    if c.stored {
        for g in &c.gaps {
            let a = g.augmented.expect("a stored model is validated");
            for i in 0..2 {
                if let (Some(b), Some(a)) = (g.base[i], a[i]) {
                    assert!(
                        a.max(0.0) >= b.max(0.0) - 0.005,
                        "{}: {} worse ({b} → {a})",
                        c.concealed.name(),
                        g.channel
                    );
                }
            }
        }
        assert!(c.kept.iter().any(|k| k.0 == Some(true)), "{}", c.verdict);
    } else {
        assert!(c.kept.iter().all(|k| k.0 != Some(true)), "{:?}", c.kept);
        assert!(
            c.verdict
                .starts_with("The augmented model was not stored: ")
                || c.named.is_empty(),
            "{}",
            c.verdict
        );
    }
}

#[test]
fn a_concealed_current_is_named_first_and_nothing_worse_is_kept() {
    let spec = seatrial_truth::CampaignSpec::default();
    let current = discover_case(1, Concealed::Current, &spec);
    let (label, points, hit) = current.named.first().expect("an effect is named");
    assert_eq!(*hit, Some(true), "{label} named first");
    assert_eq!(*points, current.grid_points, "{label}");
    gate_holds(&current);
    // The campaign is identified again with the NED current estimated and
    // the summary says what that found (seed 1: 0.289 m/s towards 30°; not
    // kept: its heading, integrated from the model's yaw rate over the
    // whole run, turns the current's force away and u's whole-run free run
    // loses 0.04).
    assert!(
        current.summary.iter().any(|l| l.starts_with(
            "Identified again with the NED current estimated, the campaign's current is 0.2"
        )),
        "{:#?}",
        current.summary
    );

    let clean = discover_case(1, Concealed::Clean, &spec);
    gate_holds(&clean);
    // On the clean vessel the estimation runs favour cross-flow |q|r in
    // yaw at 0.50 m/s, and the held-out runs refute it (its fits 1.09
    // lower over 24): tried, not named.
    assert!(clean.named.is_empty(), "{:?}", clean.named);
    assert!(!clean.unconfirmed.is_empty(), "{:#?}", clean.summary);
    assert!(
        clean
            .summary
            .iter()
            .any(|l| l.starts_with("Tried, not confirmed: ")),
        "{:#?}",
        clean.summary
    );
}

/// Asked for (`ned_current: true`), the λ identification of the ROV
/// estimates one current fixed in NED for the campaign through the damping
/// of ν − ν_c(ψ), as it does for surface vessels: on seed 1's concealed
/// current (V = (0.25, 0.15) m/s, 0.292 m/s towards 31.0°) within 3 % and
/// 2° (seed 1: 0.290 m/s towards 30.7°), and the 10 s restarted free runs
/// of all six channels gain on the model without it (seed 1: u 0.87 →
/// 0.90, v −0.88 → 0.60, w 0.73 → 0.82, p −1.34 → 0.69, q 0.46 → 0.69,
/// r 0.02 → 0.59; fitted and stepped on ν_r = ν − R(φ, θ, ψ)ᵀV, the
/// heave and pitch the hull's tilt turns the current into are modelled
/// too). Not asked for, an ROV's model carries none.
#[test]
fn an_rov_current_is_estimated_once_for_the_campaign_when_asked() {
    let spec = seatrial_truth::CampaignSpec::default();
    let seed = 1;
    let mut vessel = seatrial_truth::Vessel::draw(seed);
    let clean = seatrial_truth::fly_campaign(&vessel, &spec, seed);
    Concealed::Current.apply(&mut vessel, &clean);
    let campaign = seatrial_truth::fly_campaign(&vessel, &spec, seed);
    let plain = identify(&campaign, true, &discovery_baseline_settings()).out;
    let lpv = plain.document.lpv.as_ref().expect("an LPV model");
    assert!(lpv.current.is_none(), "{:?}", lpv.current);
    let asked = LambdaCampaignSettings {
        ned_current: Some(true),
        ..discovery_baseline_settings()
    };
    let with = identify(&campaign, true, &asked).out;
    let current = with.document.lpv.as_ref().and_then(|l| l.current.clone());
    let current = current.unwrap_or_else(|| panic!("no current: {:#?}", with.document.notes));
    let truth = vessel.current_ned;
    let (speed, towards) = (truth.x.hypot(truth.y), truth.y.atan2(truth.x).to_degrees());
    assert!(
        (current.speed_mps / speed - 1.0).abs() < 0.03
            && (current.direction_deg - towards).abs() < 2.0,
        "{current:?} for {speed} m/s towards {towards}°"
    );
    let restarted = |v: &[seatrial_core::identification::RunValidation], name: &str| {
        v.iter()
            .flat_map(|r| &r.report.channels)
            .find(|c| c.output == name)
            .and_then(|c| c.fit_restarted)
            .expect("a restarted fit")
    };
    for name in ["u", "v", "w", "p", "q", "r"] {
        let (b, a) = (
            restarted(&plain.validation, name),
            restarted(&with.validation, name),
        );
        assert!(a > b + 0.02, "{name}: 10 s restarted fit {b} → {a}");
    }
}

#[test]
fn a_concealed_actuator_lag_is_modelled_and_closes_the_free_run_gap() {
    let spec = seatrial_truth::CampaignSpec::default();
    let lag = discover_case(1, Concealed::Lag, &spec);
    gate_holds(&lag);
    let (label, points, hit) = lag.named.first().expect("an effect is named");
    assert_eq!(*hit, Some(true), "{label} named first");
    assert!(*points >= 3, "{label} at {points} grid points");
    // One lag for every DOF's thrust, within 25 % of the truth's 0.4 s at
    // three speeds or more (seed 1: 0.363, 0.371, 0.404 s; 0.152 s at
    // 2.00 m/s, with a delay of 2 samples beside it).
    let close = lag
        .first_values
        .iter()
        .filter(|v| v.last().is_some_and(|t| (t / 0.4 - 1.0).abs() < 0.25))
        .count();
    assert!(
        close >= 3,
        "T_a {:?} for the truth's 0.4 s",
        lag.first_values
    );
    assert!(lag.stored, "{}", lag.verdict);
    let mut gapped = 0;
    for g in &lag.gaps {
        let (b, t) = (g.base[1].unwrap().max(0.0), g.truth[1].unwrap());
        if t - b > 0.1 {
            gapped += 1;
            let closed = g.closed()[1].unwrap();
            assert!(
                closed > 0.4,
                "{}: closed {closed:.2} of the free-run gap",
                g.channel
            );
        }
    }
    assert!(
        gapped >= 4,
        "the lag leaves a free-run gap in {gapped} channels"
    );
}

#[test]
fn a_tether_pull_fixed_in_ned_is_named_first_and_closes_the_gap() {
    // The pull turns with the heading in the body frame, so the baseline's
    // constant loads cannot carry it; its estimate must point the truth's
    // way.
    let spec = seatrial_truth::CampaignSpec::default();
    let tether = discover_case(1, Concealed::Tether, &spec);
    gate_holds(&tether);
    let (label, points, hit) = tether.named.first().expect("an effect is named");
    assert_eq!(*hit, Some(true), "{label} named first");
    assert!(*points >= 2, "{label} at {points} grid points");
    assert!(tether.stored, "{}", tether.verdict);
    assert_eq!(tether.kept[0].0, Some(true), "{:?}", tether.kept[0]);
    // Where the pull leaves a gap above 0.1 to the true model: 1-step
    // closed by 80 %, 10 s free run by 60 % (seed 1: v, p, r 95–99 %;
    // u, v, w, p, q, r 64–94 %).
    let mut gapped = 0;
    for g in &tether.gaps {
        for (i, floor) in [(0, 0.8), (1, 0.6)] {
            let (b, t) = (g.base[i].unwrap().max(0.0), g.truth[i].unwrap());
            if t - b > 0.1 {
                gapped += 1;
                let c = g.closed()[i].unwrap();
                assert!(
                    c > floor,
                    "{}: closed {c:.2} of the gap (metric {i})",
                    g.channel
                );
            }
        }
    }
    assert!(
        gapped >= 6,
        "the pull leaves a gap in {gapped} channel metrics"
    );
    // Each speed's pull within 15 % of the truth's in size and 10° in
    // bearing, at most one speed excepted (seed 1 reads −11.1, −5.9 N at
    // 1.00 m/s for −22.4, −5.6 N).
    let truth = tether.vessel.tether_ned;
    let off: Vec<String> = tether
        .first_values
        .iter()
        .filter(|v| {
            let size = v[0].hypot(v[1]) / truth.x.hypot(truth.y);
            let turn = ((v[1].atan2(v[0]) - truth.y.atan2(truth.x)).to_degrees() + 180.0)
                .rem_euclid(360.0)
                - 180.0;
            !((0.85..1.15).contains(&size) && turn.abs() < 10.0)
        })
        .map(|v| format!("{v:?}"))
        .collect();
    assert!(off.len() <= 1, "pulls {off:?} for the truth's {truth}");
    // One pull for the campaign, pooled over the speeds that named it,
    // within 10 % and 5° (seed 1: −21.8, −5.42 N for −22.4, −5.6 N), held
    // at every grid point of the stored model.
    let once = tether
        .campaign_values
        .as_ref()
        .expect("a campaign estimate");
    let size = once[0].hypot(once[1]) / truth.x.hypot(truth.y);
    let turn = ((once[1].atan2(once[0]) - truth.y.atan2(truth.x)).to_degrees() + 180.0)
        .rem_euclid(360.0)
        - 180.0;
    assert!(
        (0.9..1.1).contains(&size) && turn.abs() < 5.0,
        "campaign pull {once:?} for the truth's {truth}"
    );
    assert_eq!(tether.stored_values.len(), tether.grid_points);
    for v in &tether.stored_values {
        assert_eq!(v.as_ref(), Some(once), "{:?}", tether.stored_values);
    }
}

/// Effects are ranked by what their grid speeds' findings gain alone on
/// the held-out runs, not by how many speeds chose them: a heave thrust
/// clipped at 60 % of the clean peak is named first on seeds 1 and 2 (seed
/// 2 chose it at one speed, as it did three look-alikes elsewhere; alone,
/// that speed's findings gain +4.63 over 24 fits, the others' lose).
/// Seed 2's model with every speed's findings passes the gate, but the
/// three terms found at the other speeds add nothing to those speeds
/// refitted without a new term: the stored model keeps the saturation
/// alone, and the summary says why the others are left out.
#[test]
fn a_heave_saturation_is_named_first_by_its_held_out_advantage() {
    let spec = seatrial_truth::CampaignSpec::default();
    for seed in [1, 2] {
        let c = discover_case(seed, Concealed::Saturation, &spec);
        gate_holds(&c);
        let (label, _, hit) = c.named.first().expect("an effect is named");
        assert_eq!(*hit, Some(true), "seed {seed}: {label} named first");
        assert!(
            c.ranking[0] > 0.0 && c.ranking.windows(2).all(|w| w[0] >= w[1]),
            "seed {seed}: ranked {:?}",
            c.ranking
        );
        if seed == 2 {
            assert!(c.stored, "{}", c.verdict);
            let kept: Vec<&str> = c
                .named
                .iter()
                .zip(&c.kept)
                .filter(|(_, k)| k.0 == Some(true))
                .map(|((l, _, _), _)| l.as_str())
                .collect();
            assert_eq!(kept, [label.as_str()], "{}", c.verdict);
            assert_eq!(c.unconfirmed.len(), 3, "{:?}", c.unconfirmed);
            assert!(
                c.verdict.contains(
                    "add nothing over their speed refitted without a new term and are left out"
                ),
                "{}",
                c.verdict
            );
        }
    }
}

/// A narrow-band sway force outside the library (0.08–0.12 Hz, 30 % of the
/// clean campaign's RMS sway command, drawn per seed) is reported as a
/// periodic force in sway at its frequency (within half a bin) and size
/// (within 25 %); no term in sway is kept, or named at more than one grid
/// speed; the clean vessels of the same seeds show no periodic force.
#[test]
fn a_periodic_sway_force_is_reported_unexplained_and_nothing_is_named_for_it() {
    let spec = seatrial_truth::CampaignSpec::default();
    for seed in [1, 2] {
        let c = discover_case(seed, Concealed::Disturbance, &spec);
        let d = c.vessel.disturbance.expect("the case has a disturbance");
        let sway: Vec<_> = c
            .lines
            .iter()
            .filter(|(_, dof, _)| *dof == Dof::Sway)
            .collect();
        assert!(
            !sway.is_empty(),
            "seed {seed}: no sway line; {:?}",
            c.unexplained
        );
        for (speed, _, l) in &sway {
            assert!(
                (l.frequency_hz - d.frequency_hz).abs() <= 0.5 * l.resolution_hz,
                "seed {seed}, {speed} m/s: line at {} Hz, truth {} Hz",
                l.frequency_hz,
                d.frequency_hz
            );
            assert!(
                (l.amplitude / d.amplitude[1] - 1.0).abs() < 0.25,
                "seed {seed}, {speed} m/s: {} N against {} N",
                l.amplitude,
                d.amplitude[1]
            );
        }
        // Where the line shows, nothing is named in sway; at a speed where
        // it does not stand out a sway term may still be named (seed 1:
        // |v|v at 1 of 4 speeds), but none is kept.
        let kept_in_sway: Vec<&str> = c
            .named
            .iter()
            .zip(&c.kept)
            .filter(|((label, _, _), k)| label.contains("in sway") && k.0 == Some(true))
            .map(|((label, _, _), _)| label.as_str())
            .collect();
        assert!(
            kept_in_sway.is_empty(),
            "seed {seed}: kept in sway: {kept_in_sway:?}"
        );
        for (label, points, _) in &c.named {
            assert!(
                !label.contains("in sway") || *points <= 1,
                "seed {seed}: {label} named at {points} grid speeds"
            );
        }
        let clean = discover_case(seed, Concealed::Clean, &spec);
        assert!(
            clean.lines.is_empty(),
            "seed {seed} clean: {:?}",
            clean.lines
        );
    }
}

/// Seed `seed`'s clean vessel through discovery: the gate holds and no
/// effect the truth lacks is named.
fn clean_vessel_named_nothing(seed: u64) -> DiscoveryCase {
    let spec = seatrial_truth::CampaignSpec::default();
    let clean = discover_case(seed, Concealed::Clean, &spec);
    gate_holds(&clean);
    assert!(
        clean.false_labels().is_empty(),
        "seed {seed}: {:?}: {:#?}",
        clean.named,
        clean.summary
    );
    clean
}

/// Each effect is credited only with what it adds to its grid speed
/// refitted without any new term (the null refit: the same rows of M and D̄
/// refitted on the same estimation runs). On seed 3's clean vessel the
/// estimation runs favour an actuator lag in sway at one grid speed, whose
/// findings gain on the held-out runs over the baseline (+0.19 over 24
/// fits) but not over that refit (−0.07): the lag is tried, not named, and
/// nothing the truth lacks is named or kept; the summary says what the
/// plain refit gains.
#[test]
fn a_term_that_adds_nothing_to_a_plain_refit_is_not_named() {
    let clean = clean_vessel_named_nothing(3);
    assert!(
        clean
            .unconfirmed
            .iter()
            .any(|l| l.starts_with("actuator lag in sway")),
        "{:?}",
        clean.unconfirmed
    );
    assert!(
        clean.summary.iter().any(|l| l.starts_with(
            "Refitted on the same estimation runs without any new term, the start model's rows"
        )),
        "{:#?}",
        clean.summary
    );
}

/// A small held-out sum is evidence only when the term's own equations
/// carry it. On seed 9's clean vessel an actuator lag in sway is found at
/// two grid speeds: at one its findings lose a fit, at the other they sum
/// +0.04 over 24 fits (within the fits' noise, 24 × 0.005), with their
/// largest gain in pitch and no sway fit better or worse beyond noise. It
/// is tried, not confirmed — no label on the clean vessel, and the reason
/// gives the tally.
#[test]
fn a_small_gain_its_own_dofs_do_not_carry_names_nothing() {
    let clean = clean_vessel_named_nothing(9);
    assert!(
        clean
            .summary
            .iter()
            .any(|l| l.contains("Tried, not confirmed: actuator lag in sway")
                && l.contains("within their noise")
                && l.contains("in its DOFs 0 fits better")),
        "{:#?}",
        clean.summary
    );
}

/// Seed 3's saturation is found at no speed; the term found instead (|v|v
/// in sway at 2 m/s) makes a model that passes the gate against the
/// identified one (22 of 24 held-out fits better), but it adds nothing to
/// that speed refitted without a new term, and with it the model is worse
/// than with the refits alone (−0.026): nothing is stored, nothing named.
#[test]
fn terms_that_add_nothing_to_their_refits_are_not_stored_when_the_whole_model_passes() {
    let spec = seatrial_truth::CampaignSpec::default();
    let c = discover_case(3, Concealed::Saturation, &spec);
    assert!(!c.stored, "{}", c.verdict);
    assert!(c.named.is_empty(), "{:?}", c.named);
    assert!(!c.unconfirmed.is_empty());
    assert!(
        c.verdict.contains("alone or together") && c.verdict.contains("so no effect is named"),
        "{}",
        c.verdict
    );
}

/// An actuator's lag belongs to the thrusters, not to the forward speed:
/// where the grid speeds' estimates of it agree within their standard
/// deviations they are pooled into one T_a for the campaign and every speed
/// is refitted with it held. Seed 4's concealed 0.4 s lag: one lag in every
/// DOF named first at 4/4 speeds, one T_a (0.373 s) held at all of them.
#[test]
fn an_actuator_lag_the_speeds_agree_on_is_estimated_once_for_the_campaign() {
    let spec = seatrial_truth::CampaignSpec::default();
    let lag = discover_case(4, Concealed::Lag, &spec);
    let (label, points, hit) = lag.named.first().expect("an effect is named");
    assert_eq!(*hit, Some(true), "{label} named first");
    assert_eq!(*points, lag.grid_points, "{label}");
    let t_a = lag
        .campaign_values
        .as_ref()
        .and_then(|v| v.first().copied())
        .unwrap_or_else(|| panic!("no campaign T_a: {:#?}", lag.summary));
    assert!((t_a / 0.4 - 1.0).abs() < 0.1, "T_a {t_a} s against 0.4 s");
    for v in &lag.first_values {
        assert_eq!(v.first().copied(), Some(t_a), "{:?}", lag.first_values);
    }
    gate_holds(&lag);
}
