//! Recovery of known systems: poles, order, transfer function, noise model,
//! multi-experiment sets, validation fits, the LQ path against dense
//! formulas.

use nalgebra::{DMatrix, DVector};

use super::super::hankel::{Layout, LqRoute, dense_hankel, hankel_lq, hankel_lq_qr};
use super::super::projection::{pinv, subspace};
use super::super::{N4sidSettings, Weighting, n4sid};
use super::*;
use crate::estimation::NoProgress;
use crate::validation::{Predictor, ValidationRecord, nrmse_fit_columns};

fn settings(weighting: Weighting, estimate_d: bool) -> N4sidSettings {
    N4sidSettings {
        horizon: 8,
        weighting,
        estimate_d,
        ..N4sidSettings::new(0.1)
    }
}

#[test]
fn noise_free_recovers_poles_order_and_markov_for_every_weighting() {
    for d_nonzero in [false, true] {
        let sys = truth(d_nonzero);
        let (u, y) = simulate(&sys, 2000, 1, 0.0, &DVector::from_element(4, 1.0));
        for w in [Weighting::N4sid, Weighting::Moesp, Weighting::Cva] {
            let est = n4sid(&[(&u, &y)], &settings(w, d_nonzero), &mut NoProgress).unwrap();
            assert_eq!(
                est.order, 4,
                "{w:?}: singular values {:?}",
                est.singular_values
            );
            // The gap: s5/s4 at rounding level.
            let s = &est.singular_values;
            assert!(s[4] < 1e-9 * s[3], "{w:?}: s4 {} s5 {}", s[3], s[4]);
            let pe = eigen_error(&est.eigenvalues(), &sys.eigenvalues());
            let me = markov_error(&est, &sys, 30);
            assert!(pe < 1e-8, "{w:?} D {d_nonzero}: pole error {pe:e}");
            assert!(me < 1e-8, "{w:?} D {d_nonzero}: Markov error {me:e}");
        }
    }
}

#[test]
fn noisy_twenty_thousand_samples_recover_poles_order_markov_and_noise_model() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 20_000, 2, 0.1, &DVector::zeros(4));
    let mut failures = Vec::new();
    for w in [Weighting::N4sid, Weighting::Moesp, Weighting::Cva] {
        let est = n4sid(&[(&u, &y)], &settings(w, false), &mut NoProgress).unwrap();
        assert_eq!(
            est.order, 4,
            "{w:?}: singular values {:?}",
            est.singular_values
        );
        let pe = eigen_error(&est.eigenvalues(), &sys.eigenvalues());
        let me = markov_error(&est, &sys, 30);
        let ne = noise_markov_error(&est, &sys, 30);
        let re = (&est.innovation_covariance - innovation_cov(0.1)).amax() / 0.01;
        eprintln!("{w:?}: pole {pe:.2e} markov {me:.2e} noise markov {ne:.2e} Re {re:.2e}");
        if !(pe < 2e-2 && me < 2e-2 && ne < 0.1 && re < 0.05) {
            failures.push(format!(
                "{w:?}: pole {pe:e} Markov {me:e} noise {ne:e} Re {re:e}"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn multi_experiment_equals_one_long_run_and_concatenation_does_not() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 3000, 3, 0.0, &DVector::from_element(4, 0.5));
    let set = settings(Weighting::Moesp, false);
    let long = n4sid(&[(&u, &y)], &set, &mut NoProgress).unwrap();
    let pieces: Vec<(DMatrix<f64>, DMatrix<f64>)> = (0..3)
        .map(|k| {
            (
                u.rows(k * 1000, 1000).into_owned(),
                y.rows(k * 1000, 1000).into_owned(),
            )
        })
        .collect();
    let refs: Vec<_> = pieces.iter().map(|(u, y)| (u, y)).collect();
    let multi = n4sid(&refs, &set, &mut NoProgress).unwrap();
    let between = markov_error(&multi, &long, 30);
    assert!(between < 1e-8, "multi vs long: {between:e}");
    assert!(markov_error(&multi, &sys, 30) < 1e-8);

    // Two runs from unrelated initial states: stacked, exact; concatenated,
    // the 2i − 1 windows across the join are not from one trajectory.
    let (u1, y1) = simulate(&sys, 1500, 4, 0.0, &DVector::from_element(4, 3.0));
    let (u2, y2) = simulate(&sys, 1500, 5, 0.0, &DVector::from_element(4, -3.0));
    let stacked = n4sid(&[(&u1, &y1), (&u2, &y2)], &set, &mut NoProgress).unwrap();
    let cat = |a: &DMatrix<f64>, b: &DMatrix<f64>| {
        DMatrix::from_fn(a.nrows() + b.nrows(), a.ncols(), |r, c| {
            if r < a.nrows() {
                a[(r, c)]
            } else {
                b[(r - a.nrows(), c)]
            }
        })
    };
    let (uc, yc) = (cat(&u1, &u2), cat(&y1, &y2));
    let fixed = N4sidSettings {
        order: Some(4),
        ..set.clone()
    };
    let joined = n4sid(&[(&uc, &yc)], &fixed, &mut NoProgress).unwrap();
    let e_stacked = markov_error(&stacked, &sys, 30);
    let e_joined = markov_error(&joined, &sys, 30);
    assert!(e_stacked < 1e-8, "stacked {e_stacked:e}");
    assert!(
        e_joined > 1e4 * e_stacked,
        "joined {e_joined:e} vs stacked {e_stacked:e}"
    );
}

#[test]
fn held_out_validation_fits_match_the_true_models() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 20_000, 6, 0.1, &DVector::zeros(4));
    let (uv, yv) = simulate(&sys, 5000, 7, 0.1, &DVector::from_element(4, 1.0));
    let est = n4sid(
        &[(&u, &y)],
        &settings(Weighting::Moesp, false),
        &mut NoProgress,
    )
    .unwrap();
    let rec = ValidationRecord {
        h: 0.1,
        u: &uv,
        y: &yv,
    };
    for (what, e, t) in [
        (
            "1-step",
            est.predict_k_step(&rec, 1),
            sys.predict_k_step(&rec, 1),
        ),
        (
            "5-step",
            est.predict_k_step(&rec, 5),
            sys.predict_k_step(&rec, 5),
        ),
        ("simulation", est.simulate(&rec), sys.simulate(&rec)),
    ] {
        let fe = nrmse_fit_columns(&yv, &e);
        let ft = nrmse_fit_columns(&yv, &t);
        for (a, b) in fe.iter().zip(&ft) {
            let (a, b) = (a.unwrap(), b.unwrap());
            eprintln!("{what}: estimated {a:.4} true {b:.4}");
            assert!((a - b).abs() < 0.01, "{what}: fit {a} vs true model {b}");
            assert!(b > 0.5, "{what}: the test needs informative outputs ({b})");
        }
    }
}

#[test]
fn predictor_matches_innovations_and_simulation() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 20_000, 8, 0.1, &DVector::from_element(4, 2.0));
    let rec = ValidationRecord {
        h: 0.1,
        u: &u,
        y: &y,
    };
    // With the true K, one-step errors are the innovations: covariance Re.
    let p1 = sys.predict_k_step(&rec, 1);
    assert!(p1.row(0).iter().all(|v| v.is_nan()));
    let err = (&y - &p1).rows(100, 19_900).into_owned();
    let cov = err.transpose() * &err / 19_900.0;
    let rel = (&cov - innovation_cov(0.1)).amax() / 0.01;
    assert!(
        rel < 0.05,
        "innovation covariance from the predictor: {cov}"
    );
    // With K = 0 the k-step predictor is the free-run simulation.
    let mut open = sys.clone();
    open.k.fill(0.0);
    let sim = open.simulate(&rec);
    let p7 = open.predict_k_step(&rec, 7);
    assert!(p7.rows(0, 7).iter().all(|v| v.is_nan()));
    let diff = (p7.rows(7, 19_993) - sim.rows(7, 19_993)).amax();
    assert!(diff < 1e-9, "k-step with K = 0 vs simulation: {diff:e}");
    // Initial state from the first samples of a noise-free run.
    let x0 = DVector::from_row_slice(&[1.0, -2.0, 0.5, 3.0]);
    let (u0, y0) = simulate(&sys, 500, 9, 0.0, &x0);
    let est_x0 = sys.estimate_initial_state(&u0, &y0);
    assert!((est_x0 - x0).amax() < 1e-9);
}

/// Dense reference: O_i = Y_f Π⊥ W_pᵀ (W_p Π⊥ W_pᵀ)⁻¹ W_p and its MOESP SVD
/// O_i Π⊥ (Van Overschee & De Moor eq. 4.26), with explicit N-column
/// matrices on a short noisy run.
#[test]
fn lq_projection_matches_the_dense_oblique_projection() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 400, 10, 0.1, &DVector::zeros(4));
    let layout = Layout { m: 2, l: 2, i: 5 };
    let h = dense_hankel(&u, &y, layout);
    let (a, b) = (layout.mi(), layout.mi() + layout.li());
    let uf = h.rows(0, a).into_owned();
    let wp = h.rows(a, b).into_owned();
    let yf = h.rows(a + b, layout.li()).into_owned();
    let j = h.ncols();
    let proj = DMatrix::<f64>::identity(j, j)
        - uf.transpose() * pinv(&(&uf * uf.transpose()), 0.0).unwrap() * &uf;
    let oi =
        &yf * &proj * wp.transpose() * pinv(&(&wp * &proj * wp.transpose()), 0.0).unwrap() * &wp;
    let dense_sv = (&oi * &proj).svd(false, false).singular_values;
    let lq = hankel_lq_qr(
        &[(&u, &y)],
        &[1.0; 2],
        &[1.0; 2],
        layout,
        64,
        &mut NoProgress,
    )
    .unwrap();
    let sub = subspace(&lq, Weighting::Moesp, Some(4), 10).unwrap();
    for k in 0..layout.li() {
        let rel = (sub.singular_values[k] - dense_sv[k]).abs() / dense_sv[0];
        assert!(
            rel < 1e-10,
            "singular value {k}: {} vs {}",
            sub.singular_values[k],
            dense_sv[k]
        );
    }
    let unweighted = oi.svd(false, false).singular_values;
    let sub = subspace(&lq, Weighting::N4sid, Some(4), 10).unwrap();
    for k in 0..layout.li() {
        let rel = (sub.singular_values[k] - unweighted[k]).abs() / unweighted[0];
        assert!(rel < 1e-10, "N4SID singular value {k}");
    }
}

/// Why the LQ and not the Gram/Cholesky: on noise-free data the Gram matrix
/// H Hᵀ is singular (rank 2mi + n of 2i(m + l)); its Cholesky needs a
/// jitter of order ε‖H Hᵀ‖, i.e. √ε‖H‖ in L. Measured here: pole error
/// QR 1.5e-14 / Gram 6.6e-14 with white inputs, QR 1.9e-14 / Gram 1.3e-12
/// with inputs low-passed by 1/(1 − 0.9 q⁻¹) — the loss grows with
/// cond(H)², i.e. with slowly varying (oversampled) or badly scaled data.
#[test]
fn gram_cholesky_loses_the_noise_free_null_space() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 2000, 11, 0.0, &DVector::from_element(4, 1.0));
    let lp = low_pass(&u, 0.9);
    let (qr_white, gram_white) = gram_vs_qr(&sys, &u, &y, "white");
    let y_lp = sys.simulate_from(&lp, &DVector::from_element(4, 1.0));
    let (qr_lp, gram_lp) = gram_vs_qr(&sys, &lp, &y_lp, "low-pass");
    assert!(
        qr_white < 1e-12 && qr_lp < 1e-12,
        "QR {qr_white:e} {qr_lp:e}"
    );
    assert!(
        gram_white > qr_white,
        "white: Gram {gram_white:e} vs QR {qr_white:e}"
    );
    assert!(
        gram_lp > 30.0 * qr_lp,
        "low-pass: Gram {gram_lp:e} vs QR {qr_lp:e}"
    );
}

/// u filtered by 1/(1 − a q⁻¹): slowly varying, as oversampled trial data.
fn low_pass(u: &DMatrix<f64>, a: f64) -> DMatrix<f64> {
    let mut out = u.clone();
    for c in 0..u.ncols() {
        for t in 1..u.nrows() {
            out[(t, c)] = a * out[(t - 1, c)] + u[(t, c)];
        }
    }
    out
}

/// Pole errors (QR, Gram/Cholesky) of the same noise-free data.
fn gram_vs_qr(sys: &N4sidModel, u: &DMatrix<f64>, y: &DMatrix<f64>, what: &str) -> (f64, f64) {
    let layout = Layout { m: 2, l: 2, i: 8 };
    let lq = hankel_lq_qr(
        &[(u, y)],
        &[1.0; 2],
        &[1.0; 2],
        layout,
        256,
        &mut NoProgress,
    )
    .unwrap();
    let h = dense_hankel(u, y, layout);
    let gram = &h * h.transpose();
    let jitter = f64::EPSILON * gram.trace();
    let l_gram = (gram + DMatrix::<f64>::identity(layout.rows(), layout.rows()) * jitter)
        .cholesky()
        .unwrap()
        .l();
    let poles = |l: &DMatrix<f64>| {
        let lq2 = super::super::hankel::HankelLq {
            layout,
            l: l.clone(),
            columns: lq.columns,
        };
        let sub = subspace(&lq2, Weighting::Moesp, Some(4), 10).unwrap();
        let fit = super::super::system::fit_state_space(&lq2, &sub, false).unwrap();
        fit.a
            .complex_eigenvalues()
            .iter()
            .copied()
            .collect::<Vec<_>>()
    };
    let e_qr = eigen_error(&poles(&lq.l), &sys.eigenvalues());
    let e_gram = eigen_error(&poles(&l_gram), &sys.eigenvalues());
    eprintln!("{what}: pole error QR {e_qr:.2e}, Gram/Cholesky {e_gram:.2e}");
    (e_qr, e_gram)
}

/// Poles of the MOESP model (order 4) built on a given L.
fn poles_from_l(l: &DMatrix<f64>, layout: Layout, columns: usize) -> Vec<nalgebra::Complex<f64>> {
    let lq = super::super::hankel::HankelLq {
        layout,
        l: l.clone(),
        columns,
    };
    let sub = subspace(&lq, Weighting::Moesp, Some(4), 10).unwrap();
    let fit = super::super::system::fit_state_space(&lq, &sub, false).unwrap();
    fit.a.complex_eigenvalues().iter().copied().collect()
}

/// Noisy data take the Gram route, and its model is the QR route's to
/// rounding; noise-free data (rank-deficient H) take the QR route.
#[test]
fn the_gram_route_serves_noisy_data_and_noise_free_data_go_to_the_qr() {
    let sys = truth(false);
    let layout = Layout { m: 2, l: 2, i: 8 };
    let route = |noise: f64, seed: u64| {
        let (u, y) = simulate(&sys, 3000, seed, noise, &DVector::zeros(4));
        let data = [(&u, &y)];
        let (lq, route) =
            hankel_lq(&data, &[1.0; 2], &[1.0; 2], layout, 256, &mut NoProgress).unwrap();
        let qr = hankel_lq_qr(&data, &[1.0; 2], &[1.0; 2], layout, 256, &mut NoProgress).unwrap();
        (lq, qr, route)
    };
    // Pole moduli of the model built on an L, ascending.
    let moduli = |lq: &super::super::hankel::HankelLq| {
        let mut m: Vec<f64> = poles_from_l(&lq.l, layout, lq.columns)
            .iter()
            .map(|z| z.norm())
            .collect();
        m.sort_by(f64::total_cmp);
        m
    };
    for (noise, seed) in [(0.1, 21u64), (0.01, 22), (1.0, 23)] {
        let (lq, qr, r) = route(noise, seed);
        assert_eq!(r, LqRoute::Gram, "noise {noise}");
        let gram = &qr.l * qr.l.transpose();
        let err = (&lq.l * lq.l.transpose() - &gram).amax() / gram.amax();
        assert!(err < 1e-12, "noise {noise}: L Lᵀ differs by {err:e}");
        let (sg, sq) = (moduli(&lq), moduli(&qr));
        for (a, b) in sg.iter().zip(&sq) {
            assert!(
                (a - b).abs() < 1e-9,
                "noise {noise}: pole moduli {sg:?} vs {sq:?}"
            );
        }
    }
    let (_, _, r) = route(0.0, 24);
    assert_eq!(r, LqRoute::Qr, "noise-free data must take the QR route");
}
