//! The truth linearizations against independent computations.

use nalgebra::Vector6;
use seatrial_truth::rng::Rng;
use seatrial_truth::{CampaignSpec, Dof, Role, Vessel, effective_linearization, fly_campaign};

#[test]
fn tangent_matches_central_differences() {
    let mut rng = Rng::new(9);
    for seed in 0..10 {
        let v = Vessel::draw(seed);
        let mut points: Vec<Vector6<f64>> = [0.3, 1.0, 2.2]
            .iter()
            .map(|&u| Vector6::new(u, 0.0, 0.0, 0.0, 0.0, 0.0))
            .collect();
        // generic points, away from the |·| kinks
        points.extend((0..3).map(|_| Vector6::from_fn(|_, _| rng.range(0.1, 0.6) * rng.sign())));
        for nu0 in points {
            let lin = v.linearization_at(&nu0);
            let fd = v.central_difference_jacobian(&nu0, 1e-7);
            let scale = lin.d_bar.abs().max();
            let diff = (lin.d_bar - fd).abs().max();
            assert!(
                diff < 2e-6 * scale,
                "seed {seed}: |D̄ − FD| = {diff:e} of {scale:e}"
            );
            // f(ν₀) = D̄ν₀ + b exactly
            let f = v.hydrodynamic_force(&nu0);
            assert!((lin.force(&nu0) - f).norm() < 1e-10 * f.norm().max(1.0));
        }
        // at ν₀ = (u₀, 0, …) the surge bias is −(l_u + q) u₀²
        let u0 = 1.5;
        let lin = v.linearization(u0);
        let expected = -(v.damping_linear_per_speed[0] + v.damping_quadratic[0]) * u0 * u0;
        assert!((lin.bias[0] - expected).abs() < 1e-9 * expected.abs());
    }
}

#[test]
fn effective_sway_damping_is_the_statistical_not_the_tangent_linearization() {
    let v = Vessel::draw(4);
    let spec = CampaignSpec {
        grid_speeds: vec![0.5],
        dynamic_dofs: vec![Dof::Sway],
        validation_duration_s: 60.0,
        ..CampaignSpec::default()
    };
    let c = fly_campaign(&v, &spec, 4);
    let runs = c.runs_at(0.5, Role::Dynamic);
    assert_eq!(runs.len(), 1);
    let eff = effective_linearization(&v, &runs);
    let tan = v.linearization(0.5);
    // quadratic sway damping q|v|v fitted by a line: slope q cov(|v|v, v)/var(v)
    // (≈ q E|v|³/E v² for a zero-mean excitation)
    let vs: Vec<f64> = runs[0].truth.nu.column(1).iter().copied().collect();
    let n = vs.len() as f64;
    let mean = |f: &dyn Fn(f64) -> f64| vs.iter().map(|x| f(*x)).sum::<f64>() / n;
    let (mv, mq) = (mean(&|x| x), mean(&|x| x.abs() * x));
    let cov = mean(&|x| (x.abs() * x - mq) * (x - mv));
    let var = mean(&|x| (x - mv) * (x - mv));
    let predicted = v.damping_quadratic[1] * cov / var;
    let got = eff.d_bar[(1, 1)] - tan.d_bar[(1, 1)];
    println!(
        "D̄_vv tangent {:.2}, effective {:.2}; excess {got:.2} vs q E|v|³/E v² = {predicted:.2}",
        tan.d_bar[(1, 1)],
        eff.d_bar[(1, 1)]
    );
    assert!(
        predicted > 0.1 * tan.d_bar[(1, 1)],
        "the test needs visible quadratic damping"
    );
    // Not exact: the yaw rate and roll the sway motion induces are
    // correlated with |v|v and take part of it in the multivariate fit.
    assert!(
        (got - predicted).abs() < 0.3 * predicted,
        "excess {got} vs {predicted}"
    );
    // and it explains the true force better than the tangent does
    let (mut r_eff, mut r_tan) = (0.0, 0.0);
    for i in 0..runs[0].truth.nu.nrows() {
        let nu = Vector6::from_fn(|j, _| runs[0].truth.nu[(i, j)]);
        let f = v.hydrodynamic_force(&nu);
        r_eff += (eff.force(&nu) - f).norm_squared();
        r_tan += (tan.force(&nu) - f).norm_squared();
    }
    assert!(
        r_eff < 0.5 * r_tan,
        "effective residual {r_eff} vs tangent {r_tan}"
    );
}
