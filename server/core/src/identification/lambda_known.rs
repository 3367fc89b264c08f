//! The sub-models' experiments with what is already known moved to the
//! known side of M ν̇ + D̄ ν + b = γ: a campaign current's force and
//! C(δ)δ on ν_r ([`super::ned_current::Relative`]), and the pooled
//! quadratic drag D_q|ν_r|ν_r on the velocity through the water
//! ν_r = ν − ν_c(ψ).

use nalgebra::{DMatrix, DVector};

use super::dataset::Segment;
use super::lambda_quadratic;
use super::ned_current::{self, Relative};
use crate::estimation::lambda::Experiment;

/// Each grid point's experiments with the current known, and ν_c(ψ) per
/// sample where it is.
pub(crate) struct KnownSide {
    exps: Vec<Vec<Experiment>>,
    nu_c: Vec<Vec<Option<DMatrix<f64>>>>,
    grid: Vec<f64>,
    surge: Option<usize>,
}

impl KnownSide {
    /// `plain` and `segments` per speed of `grid` (ψ their input column
    /// `psi_col`); `current_force(u₀)`: the current's force shapes
    /// where the current is known; `surge`: the index of surge.
    pub fn new(
        plain: Vec<Vec<Experiment>>,
        segments: &[Vec<Segment>],
        grid: &[f64],
        psi_col: usize,
        surge: Option<usize>,
        relative: Option<&Relative>,
        current_force: &dyn Fn(f64) -> Option<DMatrix<f64>>,
    ) -> Self {
        let mut exps = Vec::with_capacity(plain.len());
        let mut nu_c = Vec::with_capacity(plain.len());
        for ((point, segs), &u0) in plain.into_iter().zip(segments).zip(grid) {
            let known = relative.zip(current_force(u0));
            let point: Vec<Experiment> = match &known {
                Some((r, f)) => point
                    .into_iter()
                    .zip(segs)
                    .map(|(e, s)| r.apply(e, s, psi_col, u0, f))
                    .collect(),
                None => point,
            };
            let shapes = point
                .iter()
                .zip(segs)
                .map(|(e, seg)| {
                    let (r, _) = known.as_ref()?;
                    let psi = ned_current::heading(seg, psi_col);
                    let rows: Vec<_> = psi
                        .get(..e.nu.nrows())?
                        .iter()
                        .map(|&p| r.nu_c(p).transpose())
                        .collect();
                    (!rows.is_empty()).then(|| DMatrix::from_rows(&rows))
                })
                .collect();
            exps.push(point);
            nu_c.push(shapes);
        }
        KnownSide {
            exps,
            nu_c,
            grid: grid.to_vec(),
            surge,
        }
    }

    /// The experiments with `d_q`'s drag (about each grid speed) known.
    pub fn with_drag(&self, d_q: Option<&DVector<f64>>) -> Vec<Vec<Experiment>> {
        self.exps
            .iter()
            .zip(&self.nu_c)
            .zip(&self.grid)
            .map(|((point, nu_c), &u0)| {
                point
                    .iter()
                    .cloned()
                    .zip(nu_c)
                    .map(|(e, c)| match d_q {
                        Some(d) => lambda_quadratic::subtract(e, d, self.surge, u0, c.as_ref()),
                        None => e,
                    })
                    .collect()
            })
            .collect()
    }
}
