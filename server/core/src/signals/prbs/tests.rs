use super::*;

// ----- GF(2) polynomial helpers for the algebraic primitivity check -----

/// Carry-less product of two GF(2) polynomials of degree < 32.
fn clmul(a: u64, b: u64) -> u64 {
    let mut r = 0;
    for i in 0..32 {
        if (b >> i) & 1 == 1 {
            r ^= a << i;
        }
    }
    r
}

/// Remainder of `a` modulo `p` (deg p = n).
fn polymod(mut a: u64, p: u64, n: u32) -> u64 {
    for i in (n..64).rev() {
        if (a >> i) & 1 == 1 {
            a ^= p << (i - n);
        }
    }
    a
}

/// x^e mod p by square-and-multiply.
fn x_pow_mod(mut e: u64, p: u64, n: u32) -> u64 {
    let mut result = 1u64;
    let mut base = polymod(2, p, n); // the polynomial x
    while e > 0 {
        if e & 1 == 1 {
            result = polymod(clmul(result, base), p, n);
        }
        base = polymod(clmul(base, base), p, n);
        e >>= 1;
    }
    result
}

fn prime_factors(mut m: u64) -> Vec<u64> {
    let mut f = Vec::new();
    let mut d = 2;
    while d * d <= m {
        if m.is_multiple_of(d) {
            f.push(d);
            while m.is_multiple_of(d) {
                m /= d;
            }
        }
        d += 1;
    }
    if m > 1 {
        f.push(m);
    }
    f
}

fn divisors(m: u64) -> Vec<u64> {
    let mut d: Vec<u64> = (1..)
        .take_while(|i| i * i <= m)
        .filter(|i| m.is_multiple_of(*i))
        .flat_map(|i| [i, m / i])
        .collect();
    d.sort_unstable();
    d.dedup();
    d
}

/// Tiny SplitMix64 for picking test lags.
fn splitmix(state: &mut u64) -> u64 {
    let out = crate::rng::mix(*state);
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    out
}

fn periodic_autocorr(x: &[i8], k: usize) -> i64 {
    let m = x.len();
    (0..m)
        .map(|t| i64::from(x[t]) * i64::from(x[(t + k) % m]))
        .sum()
}

/// Every table entry is a primitive polynomial: x has multiplicative
/// order exactly 2ⁿ − 1 modulo p (x^(2ⁿ−1) = 1 and x^((2ⁿ−1)/q) ≠ 1 for
/// each prime q | 2ⁿ − 1). This covers orders 25..=32 that are too long
/// to count by brute force.
#[test]
fn tap_table_polynomials_are_primitive_for_all_orders() {
    for order in MIN_ORDER..=MAX_ORDER {
        let taps = TAPS[(order - MIN_ORDER) as usize];
        assert_eq!(taps[0], order, "first tap must be the register length");
        let p = taps.iter().fold(1u64, |p, &t| p | (1u64 << t));
        let m = period_of(order);
        assert_eq!(x_pow_mod(m, p, order), 1, "order {order}: x^(2^n-1) != 1");
        for q in prime_factors(m) {
            assert_ne!(
                x_pow_mod(m / q, p, order),
                1,
                "order {order}: x has order dividing (2^n-1)/{q}, not primitive"
            );
        }
    }
}

/// Brute force: the register state first returns to its start after
/// exactly 2ⁿ − 1 steps (so it visits every nonzero state once).
#[test]
fn register_state_period_is_exactly_2n_minus_1_for_orders_3_to_24() {
    for order in 3..=24 {
        let mut reg = Lfsr::new(order, 0).unwrap();
        let start = reg.state();
        let mut steps: u64 = 0;
        loop {
            reg.step();
            steps += 1;
            assert_ne!(reg.state(), 0, "order {order}: register hit the zero state");
            if reg.state() == start || steps > period_of(order) {
                break;
            }
        }
        assert_eq!(steps, period_of(order), "order {order}");
    }
}

/// The output sequence has minimal period exactly 2ⁿ − 1: it repeats at
/// M, is not periodic with any proper divisor of M, and is balanced
/// (2ⁿ⁻¹ ones, one more +1 than −1).
#[test]
fn sequence_period_and_balance_for_orders_3_to_24() {
    for order in 3..=24 {
        let x = mls(order, 0).unwrap();
        let m = period_of(order) as usize;
        assert_eq!(x.len(), m, "order {order}");
        assert!(x.iter().all(|&v| v == 1 || v == -1));

        let plus = x.iter().filter(|&&v| v == 1).count();
        let minus = m - plus;
        assert_eq!(plus, 1usize << (order - 1), "order {order}");
        assert_eq!(plus as i64 - minus as i64, 1, "order {order}");

        // Repeats at M: the next period from the same register is identical.
        let mut reg = Lfsr::new(order, 0).unwrap();
        for _ in 0..m {
            reg.step();
        }
        for (t, &v) in x.iter().enumerate() {
            assert_eq!(
                chip(reg.step()),
                v,
                "order {order}: differs at {t} in period 2"
            );
        }

        // Not periodic with any proper divisor d of M.
        for d in divisors(m as u64).into_iter().filter(|&d| d < m as u64) {
            let d = d as usize;
            assert!(
                (0..m).any(|t| x[t] != x[(t + d) % m]),
                "order {order}: sequence is periodic with proper divisor {d}"
            );
        }
    }
}

/// Two-valued autocorrelation R(0) = M, R(k) = −1 for all lags 1..M−1.
#[test]
fn autocorrelation_is_ideal_at_every_lag_for_orders_3_to_12() {
    for order in 3..=12 {
        let x = mls(order, 7).unwrap();
        let m = x.len();
        assert_eq!(periodic_autocorr(&x, 0), m as i64);
        for k in 1..m {
            assert_eq!(periodic_autocorr(&x, k), -1, "order {order}, lag {k}");
        }
    }
}

/// Same property on a sample of lags (including the extremes) for the
/// longer sequences where checking all lags is quadratic.
#[test]
fn autocorrelation_is_ideal_at_sampled_lags_for_orders_13_to_24() {
    let mut rng = 0x5EED_u64;
    for order in 13..=24 {
        let x = mls(order, 3).unwrap();
        let m = x.len();
        assert_eq!(periodic_autocorr(&x, 0), m as i64);
        let mut lags = vec![1, 2, order as usize, m / 3, m / 2, m - 2, m - 1];
        let extra = if order <= 20 { 24 } else { 10 };
        lags.extend((0..extra).map(|_| 1 + (splitmix(&mut rng) % (m as u64 - 1)) as usize));
        for k in lags {
            assert_eq!(periodic_autocorr(&x, k), -1, "order {order}, lag {k}");
        }
    }
}

fn cyclic_shift_between(a: &[i8], b: &[i8]) -> Option<usize> {
    let m = a.len();
    (0..m).find(|&s| (0..m).all(|t| b[t] == a[(t + s) % m]))
}

#[test]
fn different_seeds_give_distinct_cyclic_shifts_of_one_sequence() {
    for order in [3, 5, 8, 10] {
        let m = period_of(order);
        let base = mls(order, 0).unwrap();
        let mut shifts = Vec::new();
        for seed in [1u64, 2, 5, 12_345, m - 1, u64::MAX] {
            let other = mls(order, seed).unwrap();
            let s = cyclic_shift_between(&base, &other)
                .unwrap_or_else(|| panic!("order {order}, seed {seed}: not a cyclic shift"));
            shifts.push((seed % m, s));
        }
        // Distinct states give distinct shifts (each state occurs once per period).
        for (i, a) in shifts.iter().enumerate() {
            for b in &shifts[i + 1..] {
                assert_eq!(a.0 == b.0, a.1 == b.1, "order {order}: {a:?} vs {b:?}");
            }
        }
        assert_ne!(mls(order, 1).unwrap(), base);
    }
}

#[test]
fn same_seed_and_seed_plus_period_give_identical_output() {
    for order in [2, 4, 9, 16] {
        let m = period_of(order);
        let a = mls(order, 42).unwrap();
        assert_eq!(a, mls(order, 42).unwrap());
        assert_eq!(a, mls(order, 42 + m).unwrap());
    }
    assert_eq!(mls(2, 0).unwrap().len(), 3);
}

#[test]
fn mls_rejects_unsupported_orders() {
    for order in [0, 1, 33, 64] {
        let e = mls(order, 0).unwrap_err();
        assert_eq!(e.field(), "order");
    }
}

fn spec(order: u32, clock_period_s: f64) -> PrbsSpec {
    PrbsSpec {
        order,
        clock_period_s,
        amplitude: 2.0,
        offset: 10.0,
        seed: 9,
    }
}

#[test]
fn sampled_prbs_holds_each_chip_for_the_right_number_of_samples() {
    // 3 samples per chip: chip c occupies samples 3c, 3c+1, 3c+2.
    let s = spec(5, 0.3);
    let chips = mls(5, 9).unwrap();
    let x = prbs(&s, 10.0, 12.0).unwrap();
    assert_eq!(x.len(), 120);
    for (k, &v) in x.iter().enumerate() {
        let expected = 10.0 + 2.0 * f64::from(chips[(k / 3) % chips.len()]);
        assert_eq!(v, expected, "sample {k}");
    }

    // 2.5 samples per chip: chips alternate 3 and 2 samples (boundaries at
    // 0, 2.5, 5, 7.5, … samples; a boundary on a sample belongs to the new chip).
    let x = prbs(&spec(7, 0.25), 10.0, 10.0).unwrap();
    let chips = mls(7, 9).unwrap();
    for (k, &v) in x.iter().enumerate() {
        let c = (2 * k) / 5;
        assert_eq!(
            v,
            10.0 + 2.0 * f64::from(chips[c % chips.len()]),
            "sample {k}"
        );
    }
}

#[test]
fn sampled_prbs_at_one_sample_per_chip_wraps_around_the_period() {
    let s = PrbsSpec {
        order: 4,
        clock_period_s: 0.1,
        amplitude: 1.0,
        offset: 0.0,
        seed: 3,
    };
    let x = prbs(&s, 10.0, 4.5).unwrap(); // 45 samples = 3 periods of 15
    assert_eq!(x.len(), 45);
    let chips = mls(4, 3).unwrap();
    for (k, &v) in x.iter().enumerate() {
        assert_eq!(v, f64::from(chips[k % 15]), "sample {k}");
    }
}

#[test]
fn sampled_prbs_length_is_rounded_duration_times_rate() {
    let x = prbs(&spec(6, 1.0), 4.0, 10.12).unwrap();
    assert_eq!(x.len(), 40);
    let x = prbs(&spec(6, 1.0), 4.0, 10.13).unwrap();
    assert_eq!(x.len(), 41);
}

#[test]
fn prbs_reports_each_invalid_field() {
    let ok = spec(6, 0.5);
    let field = |s: &PrbsSpec, fs: f64, d: f64| prbs(s, fs, d).unwrap_err().field().to_owned();

    assert_eq!(
        field(
            &PrbsSpec {
                order: 1,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "order"
    );
    assert_eq!(
        field(
            &PrbsSpec {
                order: 33,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "order"
    );
    // Clock period shorter than one sample (0.05 s < 0.1 s).
    assert_eq!(
        field(
            &PrbsSpec {
                clock_period_s: 0.05,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "clock_period_s"
    );
    // Clock slower than the run.
    let e = prbs(
        &PrbsSpec {
            clock_period_s: 100.0,
            ..ok.clone()
        },
        10.0,
        60.0,
    )
    .unwrap_err();
    assert_eq!(e.field(), "clock_period_s");
    assert!(e.message().contains("clock slower than the run"), "{e}");
    assert_eq!(
        field(
            &PrbsSpec {
                clock_period_s: f64::NAN,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "clock_period_s"
    );
    assert_eq!(
        field(
            &PrbsSpec {
                clock_period_s: 0.0,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "clock_period_s"
    );
    assert_eq!(
        field(
            &PrbsSpec {
                amplitude: -1.0,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "amplitude"
    );
    assert_eq!(
        field(
            &PrbsSpec {
                amplitude: f64::INFINITY,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "amplitude"
    );
    assert_eq!(
        field(
            &PrbsSpec {
                offset: f64::NAN,
                ..ok.clone()
            },
            10.0,
            60.0
        ),
        "offset"
    );
    assert_eq!(field(&ok, 10.0, 0.0), "duration_s");
    assert_eq!(field(&ok, 10.0, -5.0), "duration_s");
    assert_eq!(field(&ok, 10.0, f64::INFINITY), "duration_s");
    assert_eq!(field(&ok, 0.0, 60.0), "sample_rate_hz");
    assert_eq!(field(&ok, -10.0, 60.0), "sample_rate_hz");
    assert_eq!(field(&ok, f64::NAN, 60.0), "sample_rate_hz");

    // Edge cases that are valid: exactly one sample per chip, clock == run.
    assert!(
        prbs(
            &PrbsSpec {
                clock_period_s: 0.1,
                ..ok.clone()
            },
            10.0,
            60.0
        )
        .is_ok()
    );
    assert!(
        prbs(
            &PrbsSpec {
                clock_period_s: 60.0,
                ..ok.clone()
            },
            10.0,
            60.0
        )
        .is_ok()
    );
    assert!(
        prbs(
            &PrbsSpec {
                amplitude: 0.0,
                ..ok
            },
            10.0,
            60.0
        )
        .is_ok()
    );
}

#[test]
fn prbs_spec_round_trips_through_serde() {
    let s = spec(11, 0.7);
    let json = serde_json::to_string(&s).unwrap();
    let back: PrbsSpec = serde_json::from_str(&json).unwrap();
    assert_eq!(back, s);
}
