//! The sub-models' experiments with what is already known taken in: a
//! campaign current, by fitting M ν̇_r + D̄ ν_r + b = γ on the velocity
//! through the water ν_r = ν − ν_c(ψ) ([`super::ned_current::Relative`]),
//! and the pooled quadratic drag D_q|ν_r|ν_r moved to the known side.

use nalgebra::DVector;

use super::dataset::Segment;
use super::lambda_quadratic;
use super::ned_current::Relative;
use crate::estimation::lambda::Experiment;

/// Each grid point's experiments, on ν_r where the current is known.
pub(crate) struct KnownSide {
    /// On ν_r where the current is known.
    exps: Vec<Vec<Experiment>>,
    grid: Vec<f64>,
    surge: Option<usize>,
}

impl KnownSide {
    /// `plain` and `segments` per grid speed (ψ their input column
    /// `psi_col`); with a campaign current (`relative`) every point fits
    /// ν_r ([`Relative::apply`]): the current is fixed in NED, the same at
    /// every speed; `surge`: the index of surge.
    pub fn new(
        plain: Vec<Vec<Experiment>>,
        segments: &[Vec<Segment>],
        grid: &[f64],
        psi_col: usize,
        surge: Option<usize>,
        relative: Option<&Relative>,
    ) -> Self {
        let mut exps = Vec::with_capacity(plain.len());
        for (point, segs) in plain.into_iter().zip(segments) {
            let point: Vec<Experiment> = match relative {
                Some(r) => point
                    .into_iter()
                    .zip(segs)
                    .map(|(e, s)| r.apply(e, s, psi_col))
                    .collect(),
                None => point,
            };
            exps.push(point);
        }
        KnownSide {
            exps,
            grid: grid.to_vec(),
            surge,
        }
    }

    /// The experiments with `d_q`'s drag (about each grid speed) known.
    pub fn with_drag(&self, d_q: Option<&DVector<f64>>) -> Vec<Vec<Experiment>> {
        self.exps
            .iter()
            .zip(&self.grid)
            .map(|(point, &u0)| {
                point
                    .iter()
                    .cloned()
                    .map(|e| match d_q {
                        Some(d) => lambda_quadratic::subtract(e, d, self.surge, u0),
                        None => e,
                    })
                    .collect()
            })
            .collect()
    }
}
