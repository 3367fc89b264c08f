//! A campaign's runs share one clock offset: strong runs lend it to weak
//! ones through the pool, an outlier run is left out and named.

use super::super::test_support::{Case, RunKind, make_run, table};
use super::super::*;
use crate::timeseries::LogTable;

/// The campaign's true offset (s) and an outlier run's (its navigation
/// computer rebooted).
const TRUTH: f64 = 7.43;
const OUTLIER: f64 = 19.2;

/// Runs of one campaign: four lively, two slow dives, two short noisy, two
/// static holds, one with a wandering sensor, one heave — and a lively run
/// whose clock was reset. Returns (case, shares the campaign offset).
fn campaign(seed: u64) -> Vec<(Case, bool)> {
    use RunKind::*;
    let kinds = [
        Lively,
        Lively,
        Lively,
        Lively,
        SlowDive,
        SlowDive,
        ShortNoisy,
        ShortNoisy,
        StaticHold,
        StaticHold,
        StaticWander,
        Heave,
    ];
    let mut runs: Vec<(Case, bool)> = kinds
        .iter()
        .enumerate()
        .map(|(i, &k)| (make_run(k, 100 * seed + i as u64, TRUTH), true))
        .collect();
    runs.push((make_run(Lively, 100 * seed + 99, OUTLIER), false));
    runs
}

fn estimate(c: &Case) -> OffsetEstimate {
    estimate_offset(
        &c.control.0,
        &c.control.1,
        &c.nav.0,
        &c.nav.1,
        &OffsetOptions::default(),
    )
    .unwrap()
}

/// The control and navigation logs of a run of `kind`: the shared depth.
fn shared_depth(kind: RunKind, seed: u64) -> (LogTable, LogTable) {
    let c = make_run(kind, seed, TRUTH);
    (
        table(c.control.0, vec![("z", c.control.1)]),
        table(c.nav.0, vec![("z", c.nav.1)]),
    )
}

/// Asserts that one of `rep`'s warnings contains `words`.
fn assert_warns(rep: &AlignmentReport, words: &str) {
    assert!(
        rep.warnings.iter().any(|w| w.contains(words)),
        "{words:?} not in {:?}",
        rep.warnings
    );
}

// Measured (release build) over campaigns 1–8: worst pooled error and worst
// per-run error as printed; the README quotes them.
#[test]
fn every_run_of_a_campaign_gets_within_50_ms_through_the_pool() {
    let (mut worst_pooled, mut worst_run): (f64, f64) = (0.0, 0.0);
    let (mut pooled_runs, mut weak_runs) = (0, 0);
    for seed in 1..=8 {
        let runs = campaign(seed);
        let estimates: Vec<OffsetEstimate> = runs.iter().map(|(c, _)| estimate(c)).collect();
        let offsets: Vec<RunOffset> = estimates
            .iter()
            .enumerate()
            .map(|(i, e)| RunOffset {
                run_id: format!("r{i}"),
                name: format!("run {i}"),
                offset_s: e.offset_s,
                std_s: e.std_error_s,
                informative: e.informative,
            })
            .collect();
        let pooled = pool_offsets(&offsets).expect("strong runs pool");
        let err = (pooled.offset_s - TRUTH).abs();
        assert!(err < 0.05, "campaign {seed}: {pooled:?}");
        assert!(err < 3.0 * pooled.std_s, "campaign {seed}: {pooled:?}");
        worst_pooled = worst_pooled.max(err);
        let outlier = format!("r{}", runs.len() - 1);
        assert!(
            pooled.runs_rejected.iter().any(|r| r.run_id == outlier),
            "campaign {seed}: the outlier is pooled: {pooled:?}"
        );
        assert!(!pooled.runs_used.contains(&outlier));
        for (i, ((c, shares), e)) in runs.iter().zip(&estimates).enumerate() {
            // As the service reads a stored run: the pool says whether it
            // holds this run's own estimate.
            let includes_own = pooled.runs_used.contains(&format!("r{i}"));
            let priors = OffsetPriors {
                pooled: Some(PooledValue {
                    offset_s: pooled.offset_s,
                    std_s: pooled.std_s,
                    runs: pooled.runs_used.len(),
                    includes_own,
                }),
                ..OffsetPriors::default()
            };
            let chosen = choose_offset(Some(e), &priors).unwrap().unwrap();
            // A pooled run takes the pool; the outlier keeps its own.
            let expected = if includes_own || !e.informative {
                OffsetSource::Pooled
            } else {
                OffsetSource::Own
            };
            assert_eq!(chosen.source, expected, "campaign {seed} run {i}: {e:?}");
            let err = (chosen.offset_s - c.offset).abs();
            assert!(
                err < 0.05,
                "campaign {seed}: run with truth {} got {chosen:?} from {e:?}",
                c.offset
            );
            if *shares {
                worst_run = worst_run.max(err);
            }
            if chosen.source == OffsetSource::Pooled {
                pooled_runs += 1;
            }
            if !e.informative {
                weak_runs += 1;
            }
        }
    }
    eprintln!(
        "pool: worst pooled error {worst_pooled:.4} s, worst run error {worst_run:.4} s; {pooled_runs} runs used the pooled offset ({weak_runs} uninformative)"
    );
    assert!(pooled_runs >= 8 * 4, "weak runs should use the pool");
}

#[test]
fn a_weak_run_is_merged_with_the_pooled_offset_and_says_so() {
    let (control, nav) = shared_depth(RunKind::StaticHold, 7);
    let opts = OffsetOptions::default();
    // Alone, the run is merged with its weak estimate and warns loudly.
    let (_, rep) = align_logs(&control, &nav, "z", None, &opts).unwrap();
    assert_eq!(rep.offset_source, OffsetSource::WeakOwn);
    assert!(!rep.offset.as_ref().unwrap().informative);
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.starts_with("THE CLOCK OFFSET IS NOT RELIABLE")),
        "{:?}",
        rep.warnings
    );
    // With the campaign's pooled offset it uses that and reports both.
    let pooled = PooledValue {
        offset_s: 7.4301,
        std_s: 0.0008,
        runs: 5,
        includes_own: false,
    };
    let priors = OffsetPriors {
        pooled: Some(pooled),
        ..OffsetPriors::default()
    };
    let (rec, rep) = align_logs_with(&control, &nav, "z", None, &opts, &priors).unwrap();
    assert_eq!(rep.offset_source, OffsetSource::Pooled);
    assert_eq!(rep.offset_used_s, 7.4301);
    assert_eq!(rep.offset_used_std_s, Some(0.0008));
    assert_eq!(rep.pooled, Some(pooled));
    assert!(rep.offset.is_some());
    assert_warns(&rep, "pooled clock offset is used");
    assert!(rec.len() > 100);
    // A hand-set run offset wins over everything; a hand-set campaign offset
    // over the own and pooled ones.
    let by_hand = OffsetPriors {
        user_run_s: Some(7.5),
        user_campaign_s: Some(7.4),
        pooled: Some(pooled),
    };
    let (_, rep) = align_logs_with(&control, &nav, "z", None, &opts, &by_hand).unwrap();
    assert_eq!(
        (rep.offset_source, rep.offset_used_s, rep.offset_used_std_s),
        (OffsetSource::UserRun, 7.5, None)
    );
    let campaign_only = OffsetPriors {
        user_run_s: None,
        ..by_hand
    };
    let (_, rep) = align_logs_with(&control, &nav, "z", None, &opts, &campaign_only).unwrap();
    assert_eq!(rep.offset_source, OffsetSource::UserCampaign);
    // An offset that leaves no overlap, or is absurd, names the prior.
    let apart = OffsetPriors {
        user_run_s: Some(80_000.0),
        ..OffsetPriors::default()
    };
    let err = align_logs_with(&control, &nav, "z", None, &opts, &apart).unwrap_err();
    assert_eq!(err.field(), "priors.user_run_s", "{err}");
    let absurd = OffsetPriors {
        user_campaign_s: Some(1e7),
        ..OffsetPriors::default()
    };
    let err = align_logs_with(&control, &nav, "z", None, &opts, &absurd).unwrap_err();
    assert_eq!(err.field(), "priors.user_campaign_s", "{err}");
}

#[test]
fn a_flat_shared_channel_is_merged_with_a_prior_offset() {
    let t: Vec<f64> = (0..600).map(|k| k as f64 * 0.1).collect();
    let control = table(
        t.clone(),
        vec![("z", vec![12.5; 600]), ("tau_x", vec![1.0; 600])],
    );
    let nav = table(
        t.iter().map(|v| v - 2.0).collect(),
        vec![("z", vec![12.5; 600]), ("u", vec![0.3; 600])],
    );
    let opts = OffsetOptions::default();
    let err = align_logs(&control, &nav, "z", None, &opts).unwrap_err();
    assert!(matches!(err, AlignError::FlatSignal { .. }));
    let priors = OffsetPriors {
        user_campaign_s: Some(2.0),
        ..OffsetPriors::default()
    };
    let (rec, rep) = align_logs_with(&control, &nav, "z", None, &opts, &priors).unwrap();
    assert_eq!(rep.offset, None);
    assert_eq!(rep.offset_source, OffsetSource::UserCampaign);
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.starts_with("no own estimate"))
    );
    assert!((rec.t0 - 0.0).abs() < 1e-9 && rec.len() > 500);
}

#[test]
fn an_informative_run_takes_the_pool_that_holds_its_estimate() {
    let (control, nav) = shared_depth(RunKind::Lively, 5);
    let opts = OffsetOptions::default();
    let pooled = |runs, includes_own| OffsetPriors {
        pooled: Some(PooledValue {
            offset_s: 7.4301,
            std_s: 0.0008,
            runs,
            includes_own,
        }),
        ..OffsetPriors::default()
    };
    // A pool of other runs (at upload, or one that left this run out):
    // the run's own informative estimate.
    let (_, rep) = align_logs_with(&control, &nav, "z", None, &opts, &pooled(4, false)).unwrap();
    assert!(rep.offset.as_ref().unwrap().informative);
    assert_eq!(rep.offset_source, OffsetSource::Own);
    // A pool of itself alone adds nothing.
    let (_, rep) = align_logs_with(&control, &nav, "z", None, &opts, &pooled(1, true)).unwrap();
    assert_eq!(rep.offset_source, OffsetSource::Own);
    // A pool that holds its estimate and others': the pool, and it says so.
    let (_, rep) = align_logs_with(&control, &nav, "z", None, &opts, &pooled(5, true)).unwrap();
    assert_eq!(
        (rep.offset_source, rep.offset_used_s, rep.offset_used_std_s),
        (OffsetSource::Pooled, 7.4301, Some(0.0008))
    );
    assert_warns(&rep, "combines this run's own informative estimate");
}
