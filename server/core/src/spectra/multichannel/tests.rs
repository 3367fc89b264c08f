use super::super::test_support::{Gaussian, assert_rel_close, cross_fixture, welch_fixture};
use super::super::{coherence, cross_spectra, csd, welch};
use super::*;

fn whole(n: usize) -> Vec<Range<usize>> {
    vec![0..n]
}

#[test]
fn one_block_matches_scipy_cross_fixtures() {
    let fx = cross_fixture();
    for case in &fx.cases {
        let name = &case.params.name;
        let (x, y) = (&fx.signals[&case.x], &fx.signals[&case.y]);
        let cfg = case.params.config();
        let s = multi_welch(&[x, y], &whole(x.len()), &[(0, 1), (1, 0)], &cfg).unwrap();
        assert_eq!(s.n_segments, cfg.n_segments(x.len()));
        assert_rel_close(&s.freqs, &case.freqs, 1e-12, &format!("{name} freqs"));
        assert_rel_close(&s.auto[0], &case.pxx, 1e-12, &format!("{name} pxx"));
        assert_rel_close(&s.auto[1], &case.pyy, 1e-12, &format!("{name} pyy"));
        let scale = case
            .pxy_re
            .iter()
            .zip(&case.pxy_im)
            .fold(0.0f64, |m, (r, i)| m.max(r.hypot(*i)));
        for (k, p) in s.cross[0].iter().enumerate() {
            let err = (p - Complex::new(case.pxy_re[k], case.pxy_im[k])).norm();
            assert!(err <= 1e-12 * scale, "{name} pxy[{k}]: err {err:e}");
            // The reversed pair is the conjugate (to the rounding of the
            // fused multiply–adds on CPUs that have them).
            let mirror = (s.cross[1][k] - p.conj()).norm();
            assert!(mirror <= 1e-15 * scale, "{name} pyx[{k}]: {mirror:e}");
        }
        assert_rel_close(
            &s.coherence(0),
            &case.coherence,
            1e-12,
            &format!("{name} coherence"),
        );
        let h1 = s.h1(0);
        let hscale = h1.iter().fold(0.0f64, |m, h| m.max(h.norm()));
        for (k, h) in h1.iter().enumerate() {
            let err = (h - Complex::new(case.h1_re[k], case.h1_im[k])).norm();
            assert!(err <= 1e-12 * hscale, "{name} h1[{k}]: err {err:e}");
        }
    }
}

#[test]
fn one_block_matches_scipy_welch_fixtures() {
    let fx = welch_fixture();
    for case in &fx.cases {
        let x = &fx.signals[&case.x];
        let cfg = case.params.config();
        let s = multi_welch(&[x], &whole(x.len()), &[], &cfg).unwrap();
        assert_rel_close(&s.auto[0], &case.pxx, 1e-12, &case.params.name);
        assert!(s.cross.is_empty());
    }
}

/// Asserts `|a − e| ≤ tol · max|e|` for complex vectors.
fn assert_complex_close(a: &[Complex<f64>], e: &[Complex<f64>], tol: f64, what: &str) {
    assert_eq!(a.len(), e.len(), "{what}");
    let scale = e.iter().fold(0.0f64, |m, v| m.max(v.norm()));
    for (k, (x, y)) in a.iter().zip(e).enumerate() {
        assert!((x - y).norm() <= tol * scale, "{what}[{k}]: {x} vs {y}");
    }
}

#[test]
fn one_block_matches_single_channel_functions() {
    // Linear and no detrend go through the shared engine unchanged: bit
    // for bit without fused multiply–adds. Constant detrend uses the
    // vectorised mean: equal to the rounding of the mean.
    let mut g = Gaussian::new(31);
    let n = 5000;
    let chans: Vec<Vec<f64>> = (0..4)
        .map(|c| {
            (0..n)
                .map(|i| g.sample() + (c as f64) * 3.0 + 0.001 * i as f64)
                .collect()
        })
        .collect();
    let refs: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
    let pairs = [(0, 1), (0, 3), (2, 1), (3, 3)];
    for cfg in [
        WelchConfig::hann(10.0, 256),
        WelchConfig::hann(2.0, 333).with_detrend(Detrend::Linear),
        WelchConfig::hann(1.0, 100)
            .with_noverlap(0)
            .with_detrend(Detrend::None),
    ] {
        let exact = cfg.detrend != Detrend::Constant && !crate::kernels::has_avx2_fma();
        let s = multi_welch(&refs, &whole(n), &pairs, &cfg).unwrap();
        for (c, x) in refs.iter().enumerate() {
            let w = welch(x, &cfg).unwrap().values;
            if exact {
                assert_eq!(s.auto[c], w);
            } else {
                assert_rel_close(&s.auto[c], &w, 1e-13, "auto");
            }
        }
        for (p, &(i, j)) in pairs.iter().enumerate() {
            let cs = cross_spectra(refs[i], refs[j], &cfg).unwrap();
            let c = csd(refs[i], refs[j], &cfg).unwrap().values;
            if exact {
                assert_eq!(s.cross[p], c);
                assert_eq!(s.h1(p), cs.h1().values);
            } else {
                assert_complex_close(&s.cross[p], &c, 1e-13, "csd");
                assert_complex_close(&s.h1(p), &cs.h1().values, 1e-12, "h1");
            }
            assert_rel_close(
                &s.coherence(p),
                &coherence(refs[i], refs[j], &cfg).unwrap().values,
                1e-12,
                "coherence",
            );
        }
        assert_eq!(s.freqs, cfg.frequencies());
    }
}

#[test]
fn kernels_match_their_plain_versions() {
    let x: Vec<f64> = (0..37).map(|i| 1e6 + (i as f64 * 0.7).sin()).collect();
    assert!(all_finite(&x) && all_finite(&[]));
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for at in [0, 7, 8, 36] {
            let mut y = x.clone();
            y[at] = bad;
            assert!(!all_finite(&y), "{bad} at {at}");
        }
    }
}

#[test]
fn blocks_average_segments_as_scipy_per_block() {
    // Two blocks separated by a gap of NaNs: the result is the
    // segment-weighted mean of scipy's estimate on each block alone.
    let mut g = Gaussian::new(5);
    let n = 3000;
    let mut x = g.vec(n, 1.0);
    let mut y: Vec<f64> = x.iter().map(|v| 0.5 * v + 0.2 * g.sample()).collect();
    for i in 1100..1400 {
        x[i] = f64::NAN;
        y[i] = f64::INFINITY;
    }
    let blocks = vec![0..1100, 1400..2999, 2999..3000];
    let cfg = WelchConfig::hann(4.0, 128).with_detrend(Detrend::Linear);
    let s = multi_welch(&[&x, &y], &blocks, &[(0, 1)], &cfg).unwrap();
    let (a, b) = (&blocks[0], &blocks[1]);
    let (na, nb) = (cfg.n_segments(a.len()), cfg.n_segments(b.len()));
    assert_eq!(s.n_segments, na + nb);
    let ca = cross_spectra(&x[a.clone()], &y[a.clone()], &cfg).unwrap();
    let cb = cross_spectra(&x[b.clone()], &y[b.clone()], &cfg).unwrap();
    let w = |p: f64, q: f64| (na as f64 * p + nb as f64 * q) / (na + nb) as f64;
    let pxx: Vec<f64> = ca.pxx.iter().zip(&cb.pxx).map(|(p, q)| w(*p, *q)).collect();
    let pyy: Vec<f64> = ca.pyy.iter().zip(&cb.pyy).map(|(p, q)| w(*p, *q)).collect();
    assert_rel_close(&s.auto[0], &pxx, 1e-12, "pxx");
    assert_rel_close(&s.auto[1], &pyy, 1e-12, "pyy");
    let scale = s.cross[0].iter().fold(0.0f64, |m, p| m.max(p.norm()));
    for k in 0..pxx.len() {
        let e = Complex::new(w(ca.pxy[k].re, cb.pxy[k].re), w(ca.pxy[k].im, cb.pxy[k].im));
        assert!((s.cross[0][k] - e).norm() <= 1e-12 * scale, "bin {k}");
    }
}

#[test]
fn errors_name_the_offending_input() {
    let x = vec![0.5; 100];
    let y = vec![0.5; 99];
    let cfg = WelchConfig::hann(1.0, 16);
    let field = |r: Result<MultiSpectra, SpectraError>| r.unwrap_err().field().to_owned();
    assert_eq!(field(multi_welch(&[], &whole(100), &[], &cfg)), "channels");
    assert_eq!(
        field(multi_welch(&[&x, &y], &whole(100), &[], &cfg)),
        "channels[1]"
    );
    assert_eq!(field(multi_welch(&[&x], &[], &[], &cfg)), "blocks");
    assert_eq!(
        field(multi_welch(&[&x], &[0..10, 50..101], &[], &cfg)),
        "blocks[1]"
    );
    #[allow(clippy::reversed_empty_ranges)]
    let reversed = [20..10];
    assert_eq!(field(multi_welch(&[&x], &reversed, &[], &cfg)), "blocks[0]");
    assert_eq!(
        field(multi_welch(&[&x], &whole(100), &[(0, 0), (0, 1)], &cfg)),
        "pairs[1]"
    );
    assert_eq!(
        field(multi_welch(&[&x], &[0..15, 20..35], &[], &cfg)),
        "nperseg"
    );
    assert_eq!(
        field(multi_welch(
            &[&x],
            &whole(100),
            &[],
            &WelchConfig::hann(0.0, 16)
        )),
        "fs"
    );
    assert_eq!(
        field(multi_welch(
            &[&x],
            &whole(100),
            &[],
            &WelchConfig::hann(1.0, 16).with_noverlap(16)
        )),
        "noverlap"
    );
    let mut bad = x.clone();
    bad[42] = f64::NAN;
    match multi_welch(&[&x, &bad], &[0..40, 41..100], &[], &cfg).unwrap_err() {
        SpectraError::NonFinite { field, index, .. } => {
            assert_eq!((field.as_str(), index), ("channels[1]", 42))
        }
        e => panic!("{e:?}"),
    }
    // Outside the blocks a NaN is never read.
    assert!(multi_welch(&[&x, &bad], &[0..40, 43..100], &[(0, 1)], &cfg).is_ok());
    // Inside a segment of a later batch, in a block's tail that no
    // segment reads, and with the other detrends: still found.
    let long: Vec<f64> = (0..400).map(|i| (i as f64 * 0.37).sin()).collect();
    for (at, block_end) in [(0, 400), (130, 400), (391, 400), (399, 400)] {
        for bad_value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut y = long.clone();
            y[at] = bad_value;
            for detrend in [Detrend::Constant, Detrend::Linear, Detrend::None] {
                let cfg = WelchConfig::hann(1.0, 16).with_detrend(detrend);
                // 400 samples: 48 segments cover 0..392, 392..400 is a tail.
                match multi_welch(&[&long, &y], &[0..block_end], &[(0, 1)], &cfg) {
                    Err(SpectraError::NonFinite { field, index, .. }) => {
                        assert_eq!((field.as_str(), index), ("channels[1]", at))
                    }
                    other => panic!("{at} {bad_value} {detrend:?}: {other:?}"),
                }
            }
        }
    }
}

#[test]
fn out_of_range_pair_index_gives_empty_vectors() {
    let x = vec![1.0; 64];
    let s = multi_welch(&[&x], &whole(64), &[(0, 0)], &WelchConfig::hann(1.0, 16)).unwrap();
    assert!(s.coherence(1).is_empty() && s.h1(7).is_empty());
    assert_eq!(s.coherence(0).len(), 9);
}
