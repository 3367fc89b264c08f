//! The D-optimal criterion of a plan from the λ regression's Fisher
//! information, cheap enough to compare hundreds of candidate designs: each
//! planned experiment is flown once, noise-free, with the prior through the
//! project's ROV simulator (`simulation::trials`), and its Gram matrix
//! Σφφᵀ per grid point (the information up to the noise variance σ², the
//! same for every design) is kept by the experiment's content, so a design
//! that changes one DOF's excitation flies only the runs it changed.
//!
//! Per grid point g and output row i with free regressors F_i (the
//! port–starboard structure the identification assumes by default):
//!
//!   D_g = −(1 / Σ|F_i|) Σ_i log det (S G_g S)[F_i, F_i],
//!
//! with S the diagonal scaling of the reference plan's Gram matrix (so the
//! reference scores ≈ 0 and the numbers do not depend on units), and the
//! plan's criterion D the mean of D_g over the grid. exp(D_ref − D) is the
//! geometric-mean information per parameter relative to the reference: 2
//! means every parameter's std is, on the geometric mean, √2 smaller.

use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};

use nalgebra::DMatrix;

use super::DesignError;
use super::predict::run_input;
use crate::identification::lambda_information::{
    exogenous_count, lambda_information, symmetric_rows,
};
use crate::logs::input_columns;
use crate::planning::{ExperimentFamily, Plan, PlannedExperiment, VesselProfile};
use crate::simulation::rov::RovTruth;
use crate::simulation::trials::{Feedback, MeasurementNoise, TrialSettings, fly_experiment};

/// Ridge on the scaled information (relative to the reference's unit
/// diagonal): keeps an unexcited direction finite but heavily penalised.
const RIDGE: f64 = 1e-8;

/// Gram matrices per grid point of each flown experiment, by content.
#[derive(Debug, Default)]
pub struct InformationCache {
    by_content: HashMap<u64, Vec<(usize, DMatrix<f64>)>>,
    /// Experiments flown so far (cache misses).
    pub flown: usize,
}

/// A plan's information: the summed Gram matrix per grid point.
#[derive(Debug, Clone)]
pub struct PlanInformation {
    /// Σφφᵀ per grid point (None where the plan gives no estimation data).
    pub grams: Vec<Option<DMatrix<f64>>>,
}

fn content_key(p: &PlannedExperiment) -> u64 {
    let e = &p.experiment;
    let mut h = DefaultHasher::new();
    e.family.code().hash(&mut h);
    e.grid_index.hash(&mut h);
    e.grid_speed_mps.map(f64::to_bits).hash(&mut h);
    e.sample_rate_hz.to_bits().hash(&mut h);
    p.schedule.columns.hash(&mut h);
    for row in &p.schedule.values {
        for v in row {
            v.to_bits().hash(&mut h);
        }
    }
    h.finish()
}

/// The information one planned experiment gives per grid point of `grid`
/// (flown once, then kept by its content).
///
/// # Errors
/// The simulator or the identification's data path refuses it (named by
/// its code).
pub fn experiment_information<'c>(
    profile: &VesselProfile,
    grid: &[f64],
    planned: &PlannedExperiment,
    truth: &RovTruth,
    cache: &'c mut InformationCache,
) -> Result<&'c [(usize, DMatrix<f64>)], DesignError> {
    let key = content_key(planned);
    if !cache.by_content.contains_key(&key) {
        let field = || format!("plan.experiments[{}]", planned.experiment.code);
        let settings = TrialSettings {
            noise: MeasurementNoise::NONE,
            feedback: Feedback::True,
            ..TrialSettings::default()
        };
        let flown = fly_experiment(profile, truth, planned, &settings)
            .map_err(|e| DesignError::new(field(), e.to_string()))?;
        let run = run_input(profile, planned, &flown.csv)?;
        let info = lambda_information(profile, grid, &input_columns(profile), &[run])
            .map_err(|e| DesignError::new(field(), e.to_string()))?;
        cache.flown += 1;
        cache.by_content.insert(
            key,
            info.into_iter().map(|i| (i.grid_index, i.gram)).collect(),
        );
    }
    Ok(&cache.by_content[&key])
}

/// Flies every estimation experiment of `plan` (validation runs are held
/// out by the identification and add nothing) and sums its information.
///
/// # Errors
/// An experiment the simulator or the identification's data path refuses,
/// named by its code.
pub fn plan_information(
    profile: &VesselProfile,
    plan: &Plan,
    truth: &RovTruth,
    cache: &mut InformationCache,
) -> Result<PlanInformation, DesignError> {
    let grid = plan.grid_speeds();
    let mut info = PlanInformation {
        grams: vec![None; grid.len()],
    };
    for p in &plan.experiments {
        if p.experiment.family == ExperimentFamily::Validation {
            continue;
        }
        for (g, gram) in experiment_information(profile, &grid, p, truth, cache)? {
            info.add(*g, gram);
        }
    }
    Ok(info)
}

impl PlanInformation {
    /// Adds `gram` at grid point `g`.
    pub fn add(&mut self, g: usize, gram: &DMatrix<f64>) {
        match &mut self.grams[g] {
            Some(acc) => *acc += gram,
            slot => *slot = Some(gram.clone()),
        }
    }
}

/// The diagonal scaling S of a reference plan's information, per grid
/// point (1/√G_jj; 1 where a regressor carries nothing).
#[derive(Debug, Clone)]
pub struct Scaling {
    per_point: Vec<Vec<f64>>,
}

impl Scaling {
    /// The scaling of `reference`, which must give data at every grid point.
    ///
    /// # Errors
    /// A grid point without estimation data, named by its speed.
    pub fn of(reference: &PlanInformation, grid: &[f64]) -> Result<Self, DesignError> {
        let per_point = reference
            .grams
            .iter()
            .zip(grid)
            .map(|(g, speed)| {
                let g = g.as_ref().ok_or_else(|| {
                    DesignError::new(
                        "plan",
                        format!("the plan gives no estimation data at {speed:.2} m/s"),
                    )
                })?;
                Ok(g.diagonal()
                    .iter()
                    .map(|d| if *d > 0.0 { 1.0 / d.sqrt() } else { 1.0 })
                    .collect())
            })
            .collect::<Result<Vec<Vec<f64>>, DesignError>>()?;
        Ok(Scaling { per_point })
    }
}

/// The plan's D criterion (module docs); `None` when a grid point has no
/// estimation data (such a design cannot identify the LPV model there).
pub fn d_criterion(
    profile: &VesselProfile,
    info: &PlanInformation,
    scaling: &Scaling,
) -> Option<f64> {
    let rows = symmetric_rows(&profile.dofs, exogenous_count(profile));
    let mut sum = 0.0;
    for (g, s) in info.grams.iter().zip(&scaling.per_point) {
        let g = g.as_ref()?;
        let mut log_det = 0.0;
        let mut count = 0usize;
        for free in &rows {
            let k = free.len();
            let sub = DMatrix::from_fn(k, k, |a, b| {
                let (i, j) = (free[a], free[b]);
                s[i] * g[(i, j)] * s[j] + if a == b { RIDGE } else { 0.0 }
            });
            let chol = sub.cholesky()?;
            log_det += chol
                .l()
                .diagonal()
                .iter()
                .map(|d| 2.0 * d.ln())
                .sum::<f64>();
            count += k;
        }
        sum += -log_det / count as f64;
    }
    Some(sum / info.grams.len() as f64)
}
