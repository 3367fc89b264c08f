//! How far an identified LPV model extends beyond its grid speeds.
//!
//! Validation runs and real missions fly below the lowest and above the
//! highest grid speed; the thesis's model holds its end sub-model there. An
//! extension extrapolates the end sub-models the way hull forces vary with
//! speed (D̄ affine, load quadratic in u₀, M constant; see
//! [`crate::models::lpv_schedule`]) — but only a short way, and only as far
//! as the extrapolated sub-model stays physical and stable: M symmetric
//! positive definite and D = D̄ − J_C(M, u) dissipative, and the linearized
//! vehicle (with its restoring spring in roll and pitch when g(η) is
//! estimated) no less stable than the end sub-model. Dissipative D alone
//! does not make it stable: J_C's symmetric part (the Munk moment) grows
//! with speed and, extrapolated from poor end estimates, can overcome the
//! metacentric restoring.

use nalgebra::DMatrix;

use super::lambda_coriolis::coriolis_jacobian;
use crate::estimation::restoring::RestoringParams;
use crate::models::{Extension, LinearVesselModel, LpvModel, Scheduling};
use crate::planning::dof::Dof;

/// Reach beyond each end, as fractions of the end grid spacing, tried in
/// turn: 0.6 covers the half-spacing steps engineers fly beyond a grid
/// (and the speed's excursions about them) while the quadratic load, fixed
/// by three grid points, is still close; shorter when 0.6 is not physical.
const REACHES: [f64; 3] = [0.6, 0.3, 0.15];

/// Relative tolerance of the physical check (as the sub-models' own).
const TOL: f64 = 1e-3;

/// Largest real part (1/s) of the eigenvalues of the linearized vehicle
/// `model` about zero attitude: ν̇ = −M⁻¹(D̄ν + G·(φ, θ)), φ̇ = p, θ̇ = q,
/// with G = ∂g/∂(φ, θ) of `restoring` (6-DOF models only); without it,
/// of −M⁻¹D̄. `None` when M is singular or the result is not finite.
fn growth_rate(model: &LinearVesselModel, restoring: Option<&RestoringParams>) -> Option<f64> {
    let n = model.dofs().len();
    let m_inv = model.m().clone().try_inverse()?;
    let a = match restoring.filter(|_| model.dofs() == Dof::ALL) {
        None => -(&m_inv * model.d_bar()),
        Some(g) => {
            let mut a = DMatrix::zeros(n + 2, n + 2);
            a.view_mut((0, 0), (n, n))
                .copy_from(&(-(&m_inv * model.d_bar())));
            let step = 1e-4;
            for (c, k) in [(n, 3), (n + 1, 4)] {
                let (mut plus, mut minus) = ([0.0; 6], [0.0; 6]);
                plus[k] = step;
                minus[k] = -step;
                let (gp, gm) = (g.g(&plus), g.g(&minus));
                let dg = nalgebra::DVector::from_fn(6, |i, _| (gp[i] - gm[i]) / (2.0 * step));
                a.view_mut((0, c), (n, 1)).copy_from(&(-(&m_inv * dg)));
            }
            a[(n, 3)] = 1.0;
            a[(n + 1, 4)] = 1.0;
            a
        }
    };
    let rate = a
        .complex_eigenvalues()
        .iter()
        .map(|l| l.re)
        .fold(f64::NEG_INFINITY, f64::max);
    rate.is_finite().then_some(rate)
}

/// Whether the extrapolated sub-model of `lpv` at `speed` is physical (M
/// SPD, D dissipative) and grows no faster than `end`'s (or decays).
fn physical_at(
    lpv: &LpvModel,
    speed: f64,
    coriolis: bool,
    restoring: Option<&RestoringParams>,
    end: f64,
) -> bool {
    let Ok(model) = lpv.at(speed, Scheduling::Interpolate) else {
        return false;
    };
    let n = model.dofs().len();
    let m = model.m();
    let m_sym = (m + m.transpose()) * 0.5;
    let jc = coriolis
        .then(|| coriolis_jacobian(m, model.dofs(), speed))
        .flatten()
        .unwrap_or_else(|| DMatrix::zeros(n, n));
    let d = model.d_bar() - jc;
    let d_sym = (&d + d.transpose()) * 0.5;
    let m_eig = m_sym.symmetric_eigenvalues();
    let d_eig = d_sym.symmetric_eigenvalues();
    let m_max = m_eig.amax();
    let d_max = d_eig.amax();
    let dissipative = m_eig.iter().all(|e| e.is_finite() && *e > TOL * m_max)
        && d_eig.iter().all(|e| e.is_finite() && *e >= -TOL * d_max);
    let stable = || {
        let end_rate = lpv
            .at(end, Scheduling::Interpolate)
            .ok()
            .and_then(|e| growth_rate(&e, restoring));
        match (growth_rate(&model, restoring), end_rate) {
            (Some(rate), Some(end_rate)) => rate <= end_rate.max(0.0),
            _ => false,
        }
    };
    dissipative && stable()
}

/// Which ends an identification extends. Both by default: with M fitted
/// symmetric and quadratic damping estimated, extending above the grid
/// too closed the free-run gap of the top speeds on the independent truth
/// (12 vessels: worst channel −0.06 → −0.03 of the true model's fit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Sides {
    pub below: bool,
    pub above: bool,
}

/// The extension of `lpv` (its sub-models as stored: the vehicle's M and D̄
/// with their loads) on `sides`, with `coriolis` and g(η) (`restoring`)
/// as in the identification: the longest reach of [`REACHES`] on each side
/// whose edge model, and the one midway to it, are physical and stable (no
/// extension below 0 m/s, the model's speeds being forward speeds), and a
/// note for the engineer. `None` when nothing extends, and for grids of
/// fewer than three points.
pub(crate) fn choose_extension(
    lpv: &LpvModel,
    coriolis: bool,
    restoring: Option<&RestoringParams>,
    sides: Sides,
) -> Option<(Extension, String)> {
    let g = lpv.grid_speeds();
    let n = g.len();
    if n < 3 {
        return None;
    }
    let (lo, hi) = (g[0], g[n - 1]);
    let below_edge = |r: f64| (lo - r * (g[1] - g[0])).max(0.0);
    let above_edge = |r: f64| hi + r * (g[n - 1] - g[n - 2]);
    let reach = |ext: &dyn Fn(f64) -> Extension, edge: &dyn Fn(f64) -> f64, end: f64| {
        REACHES.iter().copied().find(|&r| {
            lpv.clone().with_extension(ext(r)).is_ok_and(|m| {
                [edge(r), 0.5 * (edge(r) + end)]
                    .iter()
                    .all(|&s| physical_at(&m, s, coriolis, restoring, end))
            })
        })
    };
    let below = (sides.below && lo > 0.0)
        .then(|| {
            reach(
                &|r| Extension {
                    from_mps: below_edge(r),
                    to_mps: hi,
                },
                &below_edge,
                lo,
            )
        })
        .flatten();
    let above = sides
        .above
        .then(|| {
            reach(
                &|r| Extension {
                    from_mps: lo,
                    to_mps: above_edge(r),
                },
                &above_edge,
                hi,
            )
        })
        .flatten();
    let ext = Extension {
        from_mps: below.map_or(lo, below_edge),
        to_mps: above.map_or(hi, above_edge),
    };
    let refused = |end: f64| {
        format!(
            "none (extrapolated, the model would not be physical or would be less stable than at {end:.2} m/s, so it holds that sub-model)"
        )
    };
    let mut said = Vec::new();
    if sides.below {
        said.push(match below {
            Some(_) => format!("down to {:.2} m/s", ext.from_mps),
            None => format!("down: {}", refused(lo)),
        });
    }
    if sides.above {
        said.push(match above {
            Some(_) => format!("up to {:.2} m/s", ext.to_mps),
            None => format!("up: {}", refused(hi)),
        });
    }
    let note = format!(
        "beyond its grid the model extends its end sub-models (damping extrapolated linearly in forward speed, the constant load quadratically, as linear + quadratic hull damping and the Munk moment vary) {}; beyond that it holds the sub-model at the edge{}",
        said.join(", "),
        if sides.above {
            String::new()
        } else {
            format!(", and above the grid its {hi:.2} m/s sub-model")
        }
    );
    (below.is_some() || above.is_some()).then_some((ext, note))
}

/// Notes on validation run `run`'s forward speeds `u` outside the `grid`
/// (≥ 5 % of the run on a side, with [`super::roles::beyond_grid`]'s
/// margin): where the model extrapolates (`ext`) or holds its end
/// sub-model, and how much of the run lies beyond the extension. None for
/// a station-keeping model (one sub-model at 0 m/s): it is identified from
/// manoeuvres that move both ways about zero, as its validation runs do.
pub(crate) fn speed_coverage_notes(
    run: &str,
    u: &[f64],
    grid: &[f64],
    ext: Option<Extension>,
) -> Vec<String> {
    if grid.len() == 1 && grid[0].abs() < 1e-9 {
        return Vec::new();
    }
    let (below, above) = super::roles::beyond_grid(u, grid);
    let (lo, hi) = (grid[0], grid[grid.len() - 1]);
    let (below_ext, above_ext) = match ext {
        Some(e) => super::roles::shares_outside(u, e.from_mps, e.to_mps),
        None => (below, above),
    };
    let sides = [
        (below, below_ext, "below", lo, ext.map(|e| e.from_mps)),
        (above, above_ext, "above", hi, ext.map(|e| e.to_mps)),
    ];
    let mut notes = Vec::new();
    for (share, beyond, side, end, edge) in sides {
        if share < 0.05 {
            continue;
        }
        notes.push(match edge.filter(|e| (e - end).abs() > 1e-9) {
            Some(edge) => format!(
                "validation run {run}: {:.0} % of it was flown {side} the identified speeds ({end:.2} m/s), where the model extrapolates its sub-models to {edge:.2} m/s{}; its fits there measure extrapolation, and a grid point at that speed would model it",
                100.0 * share,
                if beyond >= 0.005 {
                    format!(" and holds that model {side} it ({:.0} % of the run)", 100.0 * beyond)
                } else {
                    String::new()
                }
            ),
            None => format!(
                "validation run {run}: {:.0} % of it was flown {side} the identified speeds, where the model holds its {end:.2} m/s sub-model; its fits there measure extrapolation, and a grid point at that speed would model it",
                100.0 * share
            ),
        });
    }
    notes
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;
    use crate::models::LinearVesselModel;
    use crate::planning::dof::Dof;

    const BOTH: Sides = Sides {
        below: true,
        above: true,
    };

    /// Surge–yaw sub-models, the tangents of X = −(d_l u + d_q u|u|) at the
    /// grid speeds, yaw damping `yaw(x)`.
    fn lpv(grid: &[f64], yaw: impl Fn(f64) -> f64) -> LpvModel {
        let (d_l, d_q) = (100.0, 400.0);
        let points = grid
            .iter()
            .map(|&x| {
                let m = DMatrix::from_row_slice(2, 2, &[5000.0, 0.0, 0.0, 3000.0]);
                let d = DMatrix::from_row_slice(2, 2, &[d_l + 2.0 * d_q * x, 0.0, 0.0, yaw(x)]);
                LinearVesselModel::new(vec![Dof::Surge, Dof::Yaw], m, d)
                    .unwrap()
                    .with_load(DVector::from_vec(vec![-d_q * x * x, 0.0]))
                    .unwrap()
            })
            .collect();
        LpvModel::new(grid.to_vec(), points).unwrap()
    }

    #[test]
    fn a_physical_grid_extends_by_six_tenths_of_its_end_spacing() {
        let (ext, note) = choose_extension(
            &lpv(&[0.5, 1.0, 1.5, 2.0], |x| 300.0 + 50.0 * x),
            false,
            None,
            BOTH,
        )
        .expect("extends");
        assert!((ext.from_mps - 0.2).abs() < 1e-12 && (ext.to_mps - 2.3).abs() < 1e-12);
        assert!(
            note.contains("down to 0.20 m/s") && note.contains("up to 2.30 m/s"),
            "{note}"
        );
    }

    #[test]
    fn a_side_whose_extrapolation_loses_dissipation_is_shortened_or_held() {
        // Yaw damping falls with speed: 40 at 0.5 … 10 at 2.0 N·m·s/rad;
        // extrapolated it reaches 0 at 2.5 m/s, still 4 at 2.3.
        let m = lpv(&[0.5, 1.0, 1.5, 2.0], |x| 50.0 - 20.0 * x);
        let (ext, _) = choose_extension(&m, false, None, BOTH).expect("extends");
        assert!((ext.to_mps - 2.3).abs() < 1e-12);
        // Steeper: 11 at 2.0, −19 at 2.3, −4 at 2.15 (beyond the
        // tolerance), 3.5 at 2.075: 0.15 of the spacing is the most that
        // stays dissipative.
        let m = lpv(&[0.5, 1.0, 1.5, 2.0], |x| 211.0 - 100.0 * x);
        let (ext, note) = choose_extension(&m, false, None, BOTH).expect("extends below");
        assert!((ext.to_mps - 2.075).abs() < 1e-12, "{ext:?}");
        assert!((ext.from_mps - 0.2).abs() < 1e-12, "{ext:?}");
        // Steeper still (−2.5 at 2.075): no extension above, said so.
        let m = lpv(&[0.5, 1.0, 1.5, 2.0], |x| 205.0 - 100.0 * x);
        let (ext, note2) = choose_extension(&m, false, None, BOTH).expect("extends below");
        assert_eq!(ext.to_mps, 2.0);
        assert!(note2.contains("up: none"), "{note2}");
        assert!(!note.contains("none"), "{note}");
        // Two grid points: no extension.
        assert!(choose_extension(&lpv(&[0.5, 1.0], |_| 300.0), false, None, BOTH).is_none());
    }

    /// A DP run surging ±0.3 m/s about its one sub-model at 0 m/s is not
    /// "below the identified speeds"; a run at 0.1 m/s against a single
    /// sub-model at 0.5 m/s is.
    #[test]
    fn station_keeping_runs_are_not_flagged_below_the_grid() {
        let u: Vec<f64> = (0..600).map(|k| 0.3 * (0.05 * k as f64).sin()).collect();
        assert!(speed_coverage_notes("VAL", &u, &[0.0], None).is_empty());
        let slow = vec![0.1; 600];
        let notes = speed_coverage_notes("VAL", &slow, &[0.5], None);
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("100 % of it was flown below"),
            "{notes:?}"
        );
    }
}
