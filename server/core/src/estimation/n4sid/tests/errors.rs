//! Typed errors name the offending field; cancellation stops the work.

use nalgebra::{DMatrix, DVector};

use super::super::{N4sidError, N4sidSettings, n4sid};
use super::*;
use crate::estimation::{Cancelled, NoProgress};

#[test]
fn bad_inputs_give_typed_errors() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 500, 1, 0.1, &DVector::zeros(4));
    let set = N4sidSettings::new(0.1);
    let run = |u: &DMatrix<f64>, y: &DMatrix<f64>, s: &N4sidSettings| {
        n4sid(&[(u, y)], s, &mut NoProgress)
    };

    assert_eq!(
        n4sid(&[], &set, &mut NoProgress),
        Err(N4sidError::NoExperiments)
    );
    let y3 = DMatrix::zeros(499, 2);
    assert!(matches!(
        run(&u, &y3, &set),
        Err(N4sidError::Shape { field: "y", .. })
    ));
    let mut bad = y.clone();
    bad[(17, 1)] = f64::NAN;
    assert_eq!(
        run(&u, &bad, &set),
        Err(N4sidError::NonFinite {
            experiment: 0,
            field: "y",
            row: 17,
            column: 1
        })
    );
    let mut zero = u.clone();
    zero.column_mut(1).fill(0.0);
    assert_eq!(
        run(&zero, &y, &set),
        Err(N4sidError::ZeroChannel {
            field: "u",
            column: 1
        })
    );
    // 2i(m+l) = 80 rows need ≥ 160 columns: 100 samples are too few.
    let (us, ys) = (u.rows(0, 100).into_owned(), y.rows(0, 100).into_owned());
    assert!(matches!(
        run(&us, &ys, &set),
        Err(N4sidError::TooFewSamples {
            field: "experiments",
            ..
        })
    ));
    let (ut, yt) = (u.rows(0, 15).into_owned(), y.rows(0, 15).into_owned());
    assert!(matches!(
        n4sid(&[(&u, &y), (&ut, &yt)], &set, &mut NoProgress),
        Err(N4sidError::TooFewSamples {
            samples: 15,
            required: 20,
            ..
        })
    ));
    let fixed = N4sidSettings {
        order: Some(12),
        max_order: 10,
        ..set.clone()
    };
    assert_eq!(
        run(&u, &y, &fixed),
        Err(N4sidError::OrderTooLarge {
            field: "order",
            order: 12,
            max: 10
        })
    );
    let short = N4sidSettings {
        order: Some(5),
        horizon: 2,
        ..set.clone()
    };
    assert_eq!(
        run(&u, &y, &short),
        Err(N4sidError::OrderTooLarge {
            field: "horizon",
            order: 5,
            max: 2
        })
    );
    let h0 = N4sidSettings {
        h: -1.0,
        ..set.clone()
    };
    assert!(matches!(
        run(&u, &y, &h0),
        Err(N4sidError::Setting { field: "h", .. })
    ));
    let i0 = N4sidSettings {
        horizon: 1,
        ..set.clone()
    };
    assert!(matches!(
        run(&u, &y, &i0),
        Err(N4sidError::Setting {
            field: "horizon",
            ..
        })
    ));
    // A constant input is not persistently exciting of order 2i.
    let mut flat = u.clone();
    flat.column_mut(0).fill(1.0);
    assert!(matches!(
        run(&flat, &y, &set),
        Err(N4sidError::NotPersistentlyExciting { .. })
    ));
}

#[test]
fn cancellation_unwinds() {
    let sys = truth(false);
    let (u, y) = simulate(&sys, 5000, 1, 0.1, &DVector::zeros(4));
    let set = N4sidSettings {
        chunk_rows: Some(100),
        ..N4sidSettings::new(0.1)
    };
    let mut calls = 0;
    let mut stop = |f: f64, _: &str| {
        calls += 1;
        if f > 0.3 { Err(Cancelled) } else { Ok(()) }
    };
    assert_eq!(
        n4sid(&[(&u, &y)], &set, &mut stop),
        Err(N4sidError::Cancelled)
    );
    assert!(calls > 1 && calls < 40, "stopped early: {calls} updates");
}
