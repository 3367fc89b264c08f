//! In a current the hull's forces follow the speed through the water
//! u_r = u − u_c(ψ), not the speed over ground the log records: the same
//! propeller command gives the same u_r on every heading, while u over
//! ground differs by up to ±V. A sub-model linearized about a grid speed
//! must hold runs flown at that u_r, and the model in a current is
//! scheduled on it ([`super::heading_loop`]).
//!
//! On the independent Otter in a 0.29 m/s current the runs' mean ground
//! speeds put four of six runs at the wrong grid point (a 0.30 m/s run at
//! 0.55 over ground, a 0.52 m/s run at 0.23) and the held-out free runs fit
//! surge 0.03, yaw 0.24.

use nalgebra::Vector2;

use super::dataset::{RunInput, Segment};
use super::lambda_data::PointData;
use super::ned_current::surge_component;
use super::roles::{Roles, nearest_grid_index};
use crate::numbers::sig3;

/// The forward speed through the water u_r = u − u_c(ψ) (m/s) at each
/// sample of `seg` (u its output column `surge`, ψ its input column
/// `psi_col`) in the current V = [V_N, V_E]; without one, u.
pub(crate) fn speed_through_water(
    seg: &Segment,
    surge: usize,
    psi_col: usize,
    v: Option<Vector2<f64>>,
) -> Vec<f64> {
    (0..seg.y.nrows())
        .map(|k| {
            let u = seg.y[(k, surge)];
            match v {
                Some(v) => u - surge_component([v[0], v[1]], seg.u[(k, psi_col)]),
                None => u,
            }
        })
        .collect()
}

/// One run's mean speeds (m/s) and where its segments sit.
struct RunSpeeds {
    id: String,
    ground: f64,
    water: f64,
    samples: usize,
    points: Vec<usize>,
}

/// The estimation runs without a stated grid speed whose mean speed
/// through the water (current V = [V_N, V_E], ψ the input column `psi_col`
/// of each segment, u the output column `surge`) belongs to another grid
/// point than their segments were given by their speed over ground: `runs`
/// with those runs' grid speed set to that grid point, and a note naming
/// each. `None` when none moves.
pub(crate) fn regrid(
    runs: &[RunInput],
    roles: &Roles<'_>,
    data: &PointData,
    grid: &[f64],
    surge: usize,
    psi_col: usize,
    v: Vector2<f64>,
) -> Option<(Vec<RunInput>, String)> {
    let mut speeds: Vec<RunSpeeds> = Vec::new();
    for (i, segs) in data.segments.iter().enumerate() {
        for s in segs {
            let free = roles
                .estimation
                .iter()
                .any(|r| r.run_id == s.run_id && r.grid_speed_mps.is_none());
            if !free || psi_col >= s.u.ncols() || surge >= s.y.ncols() {
                continue;
            }
            let rows = s.y.nrows();
            let ground: f64 = s.y.column(surge).sum();
            let water: f64 = speed_through_water(s, surge, psi_col, Some(v)).iter().sum();
            let entry = match speeds.iter_mut().find(|e| e.id == s.run_id) {
                Some(e) => e,
                None => {
                    speeds.push(RunSpeeds {
                        id: s.run_id.clone(),
                        ground: 0.0,
                        water: 0.0,
                        samples: 0,
                        points: Vec::new(),
                    });
                    speeds.last_mut().expect("just pushed")
                }
            };
            entry.ground += ground;
            entry.water += water;
            entry.samples += rows;
            entry.points.push(i);
        }
    }
    let mut moved = Vec::new();
    let mut out: Vec<RunInput> = runs.to_vec();
    for e in speeds.iter().filter(|e| e.samples > 0) {
        let (ground, water) = (e.ground / e.samples as f64, e.water / e.samples as f64);
        let j = nearest_grid_index(grid, water);
        if e.points.iter().all(|&p| p == j) {
            continue;
        }
        if let Some(r) = out.iter_mut().find(|r| r.run_id == e.id) {
            r.grid_speed_mps = Some(grid[j]);
            moved.push(format!(
                "{} ({} m/s over ground, {} through the water: at {} m/s)",
                r.name,
                sig3(ground),
                sig3(water),
                sig3(grid[j])
            ));
        }
    }
    (!moved.is_empty()).then(|| {
        (
            out,
            format!(
                "the current moved runs to the grid point of their mean speed through the water, u_r = u − u_c(ψ), which the hull's forces follow and the model is scheduled on: {}; the campaign was identified again with them there",
                moved.join(", ")
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::Segment;
    use crate::timeseries::UniformRecord;
    use nalgebra::DMatrix;

    fn run(id: &str, grid_speed: Option<f64>) -> RunInput {
        RunInput {
            run_id: id.into(),
            name: format!("run {id}"),
            family: None,
            grid_speed_mps: grid_speed,
            excited_dofs: Vec::new(),
            record: UniformRecord {
                sample_rate_hz: 10.0,
                t0: 0.0,
                names: Vec::new(),
                data: Vec::new(),
                valid: Vec::new(),
            },
        }
    }

    /// A segment at constant u over ground and heading ψ: inputs τ (3) then ψ.
    fn segment(id: &str, u: f64, psi: f64) -> Segment {
        let rows = 100;
        Segment {
            run_id: id.into(),
            h: 0.1,
            t0: 0.0,
            u: DMatrix::from_fn(rows, 4, |_, j| if j == 3 { psi } else { 0.0 }),
            y: DMatrix::from_fn(rows, 3, |_, j| if j == 0 { u } else { 0.0 }),
        }
    }

    #[test]
    fn a_run_into_the_current_moves_to_its_speed_through_the_water() {
        let grid = [0.3, 0.55, 0.8];
        // Current 0.3 m/s towards north. Run a heads north at 0.6 m/s over
        // ground: 0.3 through the water. Run b heads south at 0.25 over
        // ground: 0.55 through the water. Run c heads east: unchanged. Run
        // d states its grid speed and stays.
        let runs = vec![
            run("a", None),
            run("b", None),
            run("c", None),
            run("d", Some(0.8)),
        ];
        let data = PointData {
            segments: vec![
                vec![segment("b", 0.25, std::f64::consts::PI)],
                vec![
                    segment("a", 0.6, 0.0),
                    segment("c", 0.55, std::f64::consts::FRAC_PI_2),
                ],
                vec![segment("d", 0.2, std::f64::consts::PI)],
            ],
            run_ids: vec![
                vec!["b".into()],
                vec!["a".into(), "c".into()],
                vec!["d".into()],
            ],
        };
        let roles = Roles {
            statics: Vec::new(),
            estimation: runs.iter().collect(),
            validation: Vec::new(),
        };
        let (out, note) = regrid(&runs, &roles, &data, &grid, 0, 3, Vector2::new(0.3, 0.0))
            .expect("two runs move");
        assert_eq!(out[0].grid_speed_mps, Some(0.3));
        assert_eq!(out[1].grid_speed_mps, Some(0.55));
        assert_eq!(out[2].grid_speed_mps, None);
        assert_eq!(out[3].grid_speed_mps, Some(0.8));
        assert!(
            note.contains("run a (0.6 m/s over ground, 0.3 through the water: at 0.3 m/s)"),
            "{note}"
        );
        assert!(!note.contains("run c") && !note.contains("run d"), "{note}");
        // Without a current nothing moves.
        assert!(regrid(&runs, &roles, &data, &grid, 0, 3, Vector2::zeros()).is_none());
    }
}
