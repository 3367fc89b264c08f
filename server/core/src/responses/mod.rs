//! Linear responses of an identified model, for the plots an engineer
//! checks a model with: frequency response (Bode), poles and per-channel
//! zeros, step and impulse responses, Hankel singular values.
//!
//! Every model kind is first put in plain state space by
//! [`crate::identification::export_state_space`] (one operating point per
//! LPV grid speed; continuous for LPV and DP models, discrete at its own
//! sample time for an N4SID model), so one set of functions serves all.
//! Numbers that cannot be shown (a diverged response, an undefined Gramian)
//! are reported in words, never as ∞ or NaN.

pub mod frequency;
pub mod hankel;
pub mod poles;
pub mod polynomial;
pub mod step;

use nalgebra::DMatrix;

use crate::identification::document::{Matrix, from_rows};
use crate::identification::export_state_space::{Channel, StateSpaceExport};

/// One operating point of a model as x' = A x + B u, y = C x + D u:
/// continuous (x' = ẋ) when `sample_time_s` is 0, else discrete (x' = x⁺).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearModel {
    /// A (n × n).
    pub a: DMatrix<f64>,
    /// B (n × m).
    pub b: DMatrix<f64>,
    /// C (p × n).
    pub c: DMatrix<f64>,
    /// D (p × m).
    pub d: DMatrix<f64>,
    /// Sample time (s); 0 for continuous time.
    pub sample_time_s: f64,
}

impl LinearModel {
    /// True for a continuous-time model.
    pub fn continuous(&self) -> bool {
        self.sample_time_s == 0.0
    }

    /// States n.
    pub fn n_states(&self) -> usize {
        self.a.nrows()
    }

    /// Inputs m.
    pub fn n_inputs(&self) -> usize {
        self.b.ncols()
    }

    /// Outputs p.
    pub fn n_outputs(&self) -> usize {
        self.c.nrows()
    }

    /// From row-major matrices; `Err` names the ragged or mis-shaped one.
    pub fn from_rows(
        a: &Matrix,
        b: &Matrix,
        c: &Matrix,
        d: &Matrix,
        sample_time_s: f64,
    ) -> Result<Self, String> {
        let get = |m: &Matrix, name: &str| from_rows(m).ok_or(format!("{name} is ragged"));
        let (a, b, c, d) = (get(a, "A")?, get(b, "B")?, get(c, "C")?, get(d, "D")?);
        let n = a.nrows();
        if a.ncols() != n || b.nrows() != n || c.ncols() != n || d.nrows() != c.nrows() {
            return Err(format!(
                "inconsistent shapes: A {}×{}, B {}×{}, C {}×{}, D {}×{}",
                a.nrows(),
                a.ncols(),
                b.nrows(),
                b.ncols(),
                c.nrows(),
                c.ncols(),
                d.nrows(),
                d.ncols()
            ));
        }
        if d.ncols() != b.ncols() {
            return Err(format!("D has {} columns, B {}", d.ncols(), b.ncols()));
        }
        Ok(LinearModel {
            a,
            b,
            c,
            d,
            sample_time_s,
        })
    }
}

/// A model's operating points with their names and units.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearModels {
    /// Inputs, in B's column order.
    pub inputs: Vec<Channel>,
    /// Outputs, in C's row order.
    pub outputs: Vec<Channel>,
    /// (grid speed (m/s) of an LPV point, the model there).
    pub points: Vec<(Option<f64>, LinearModel)>,
}

/// The operating points of a state-space export.
pub fn linear_models(e: &StateSpaceExport) -> Result<LinearModels, String> {
    let points = e
        .points
        .iter()
        .map(|p| {
            LinearModel::from_rows(&p.a, &p.b, &p.c, &p.d, e.sample_time_s)
                .map(|m| (p.grid_speed_mps, m))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(LinearModels {
        inputs: e.inputs.clone(),
        outputs: e.outputs.clone(),
        points,
    })
}

/// Unit of a ratio output/input, e.g. `m/s per N`.
pub fn ratio_unit(output: &str, input: &str) -> String {
    format!("{output} per {input}")
}

/// A finite number, or `None` (serialised as `null`).
pub(crate) fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// A one-channel model `tau_X` [N] → `u` [m/s] around `m` (tests).
#[cfg(test)]
pub(crate) fn surge_channel(m: LinearModel) -> LinearModels {
    let ch = |n: &str, u: &str| Channel {
        name: n.into(),
        unit: u.into(),
    };
    LinearModels {
        inputs: vec![ch("tau_X", "N")],
        outputs: vec![ch("u", "m/s")],
        points: vec![(None, m)],
    }
}
