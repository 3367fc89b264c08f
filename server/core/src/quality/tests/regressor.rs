//! Regressor.

use super::*;

fn two_by_two(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = Rng::new(seed);
    let x1 = rng.binary(n, 3, 1.0);
    let x2 = rng.white(n, 2.0);
    let y1 = add_noise(&first_order(&x1, 0.9, 0.3), &mut rng, 0.05);
    let y2 = add_noise(&first_order(&x2, 0.7, -0.4), &mut rng, 0.05);
    (x1, x2, y1, y2)
}

/// Two independent inputs and their outputs: full rank. A third input
/// that is an affine copy of the first (collinear about the mean) drops
/// the identifiable count by exactly one per lag, and the deficient
/// direction names the two columns.
#[test]
fn collinear_input_drops_identifiable_count_by_one_per_lag() {
    let (x1, x2, y1, y2) = two_by_two(20_000, 4);
    let x3: Vec<f64> = x1.iter().map(|v| 3.0 - 2.0 * v).collect();
    let all = [0..20_000];
    let r =
        regressor_analysis(&["y1", "y2", "x1", "x2"], &[&y1, &y2, &x1, &x2], 2, &all, 1).unwrap();
    assert_eq!((r.identifiable, r.n_columns), (4, 4));
    assert!(r.deficient_directions.is_empty());
    assert!((r.singular_values[0] - 1.0).abs() < 1e-15);
    assert!(r.singular_values.windows(2).all(|w| w[0] >= w[1]));

    let r = regressor_analysis(
        &["y1", "y2", "x1", "x2", "x3"],
        &[&y1, &y2, &x1, &x2, &x3],
        2,
        &all,
        1,
    )
    .unwrap();
    assert_eq!((r.identifiable, r.n_columns), (4, 5));
    assert_eq!(r.deficient_directions.len(), 1);
    let g = &r.deficient_directions[0];
    let cols: Vec<&str> = g.columns.iter().map(|c| c.column.as_str()).collect();
    assert_eq!(cols, ["x1(t-1)", "x3(t-1)"]);
    // Unit-RMS columns z1 = −z3: each lies half in the null direction.
    assert!(g.columns.iter().all(|c| (c.weight - 0.5).abs() < 1e-9));
    assert_eq!(g.dimension, 1);
    assert!(g.singular_value < 1e-6);
    assert!((g.input_share - 1.0).abs() < 1e-9);

    // With na = nb = 2 every lag of the copy is collinear: two fewer.
    let r = regressor_analysis(
        &["y1", "y2", "x1", "x2", "x3"],
        &[&y1, &y2, &x1, &x2, &x3],
        2,
        &all,
        2,
    )
    .unwrap();
    assert_eq!((r.identifiable, r.n_columns), (8, 10));
    // One group per lag, whatever rotation the eigen-solver picked within
    // the two-dimensional null space.
    let groups: Vec<Vec<&str>> = r
        .deficient_directions
        .iter()
        .map(|g| g.columns.iter().map(|c| c.column.as_str()).collect())
        .collect();
    assert_eq!(groups, [["x1(t-1)", "x3(t-1)"], ["x1(t-2)", "x3(t-2)"]]);
    assert_eq!(r.columns[0], "y1(t-1)");
    assert_eq!(r.columns[9], "x3(t-2)");
    assert_eq!(r.threshold, SINGULAR_VALUE_THRESHOLD);
}

/// Sway and yaw excited by one and the same signal: the full regressor is
/// deficient and both DOFs are Weak with the collinear columns named.
#[test]
fn same_signal_on_two_dofs_makes_both_weak() {
    let mut rng = Rng::new(8);
    let n = 20_000;
    let x = rng.binary(n, 5, 1.0);
    let v = add_noise(&first_order(&x, 0.9, 0.2), &mut rng, 0.01);
    let rr = add_noise(&first_order(&x, 0.8, 0.1), &mut rng, 0.01);
    let tau_n: Vec<f64> = x.iter().map(|s| 0.5 * s).collect();
    let rec = record(
        10.0,
        vec![("tau_Y", x), ("tau_N", tau_n), ("v", v), ("r", rr)],
    );
    let spec = QualitySpec::new(names(&["tau_Y", "tau_N"]), names(&["v", "r"]))
        .with_dof(Dof::Sway, "tau_Y", "v")
        .with_dof(Dof::Yaw, "tau_N", "r");
    let mut spec = spec;
    spec.regressor_lags = 2; // one collinear direction per lag
    let rep = quality_report(&rec, &spec).unwrap();
    assert_eq!(rep.regressor.n_columns - rep.regressor.identifiable, 2);
    for d in &rep.dofs {
        assert_eq!(d.verdict, Verdict::Weak, "{}", d.reason);
        assert!(d.evidence.input_deficient);
        let pair = if d.dof == Dof::Sway {
            "tau_Y and tau_N"
        } else {
            "tau_N and tau_Y"
        };
        assert!(
            d.reason.contains(&format!("{pair} move together")),
            "{}",
            d.reason
        );
        assert!(d.reason.contains("own independent signal"), "{}", d.reason);
    }
    assert!(
        rep.warnings
            .iter()
            .any(|w| w.contains("determines 6 of its 8 parameters")),
        "{:?}",
        rep.warnings
    );
}
