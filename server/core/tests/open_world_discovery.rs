//! Missing-physics discovery on campaigns it did not plan or simulate: the
//! independent truth (`seatrial-truth`) with a concealed effect, flown by
//! another team's controller, identified and examined by the service. The
//! full table: `cargo run --release -p seatrial-core --example
//! open_world_discovery [seeds…]`.
//!
//! What holds today, and is held here: a steady current is named first at
//! every grid speed, and no augmented model worse than its baseline on a
//! held-out channel is kept — on this data the library's other labels
//! (Coriolis products, dead zones) are refused by the held-out gate.

mod support;

use support::open_world_discovery::{Concealed, DiscoveryCase, discover_case};

/// Nothing kept is worse than the baseline on any held-out channel (1-step
/// or 10 s restarted free run, beyond 0.005), and a refused model's
/// verdict says why.
fn gate_holds(c: &DiscoveryCase) {
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
    } else {
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

    let clean = discover_case(1, Concealed::Clean, &spec);
    gate_holds(&clean);
}
