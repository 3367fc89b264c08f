//! Equation-error fits of hypotheses as augmentations of the baseline.
//!
//! Every signal passes the state-variable filter λ(s) = 1/(1+sT), so the
//! regression per DOF row i reads
//! [λγ_i] = Σ_j M_ij [sλν_j] + Σ_j D̄_ij [λν_j] + Σ_p θ_p [λφ_p,i],
//! with [sλν] = (ν − [λν])/T (no raw differencing). The baseline entries of
//! the rows a hypothesis touches are refitted with it, so a term is not
//! biased by what the baseline already absorbed. Rows are weighted by
//! 1/σ_i of the baseline's own equation error, so forces and moments mix.
//! Coefficient covariances are heteroskedasticity-and-autocorrelation
//! consistent (Newey–West, Bartlett weights): filtered residuals are far
//! from white, and OLS standard errors would call noise significant.

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

use nalgebra::DMatrix;

use super::candidates::{Effect, TermContext};
use super::data::{Baseline, Record};
use super::model::{AugmentedModel, ModelTerm, actuate};
use super::svf::{Svf, lag_zoh};
use crate::planning::Dof;

/// A hypothesis term with its shape parameter fixed (actuator effects).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Spec {
    pub effect: Effect,
    pub shape: Option<f64>,
}

/// Filtered signals of one run.
pub(crate) struct PrepRun {
    /// g_i(η) per DOF at the samples.
    g: Vec<Vec<f64>>,
    lam_nu: Vec<Vec<f64>>,
    dlam_nu: Vec<Vec<f64>>,
    lam_tau: Vec<Vec<f64>>,
    lam_g: Vec<Vec<f64>>,
    /// [λ1]: a constant load's filtered regressor.
    lam_one: Vec<f64>,
}

/// Everything the fits share: the runs, their filtered signals, the
/// baseline's structure and the row weights.
pub(crate) struct Prepared<'a> {
    pub records: &'a [Record],
    pub baseline: &'a Baseline,
    pub svf: Svf,
    /// Samples dropped at the start of each run (filter transient, delays).
    pub skip: usize,
    runs: Vec<PrepRun>,
    /// Per row: free M columns and free D̄ columns of the baseline.
    structure: Vec<(Vec<usize>, Vec<usize>)>,
    /// The baseline's M and D̄ are held, not refitted ([`Self::frozen`]).
    frozen: bool,
    /// Terms whose coefficients are held ([`Self::holding`]): a force
    /// shared by the campaign, estimated once for it.
    held: Vec<ModelTerm>,
    /// 1/σ_i of the baseline's equation error per row.
    pub weights: Vec<f64>,
    /// Long-run variance inflation of the residuals (≥ 1).
    pub kappa: f64,
    /// Bartlett lags of the HAC covariance.
    pub hac_lags: usize,
    /// Filtered regressors that depend on the data alone, by (term,
    /// coefficient, row, run).
    regressors: RegressorCache,
    /// Baseline parts of the regression blocks, shared by every
    /// hypothesis that frees the same entries of a row.
    base_blocks: BaseCache,
    /// Sines and cosines of η at the RK4 stages of each run's intervals,
    /// by run (see `kstep`).
    stage_trig: RefCell<HashMap<usize, Rc<Vec<[super::candidates::Trig; 3]>>>>,
    /// C(ν)ν at the samples of each run for the last M it was built with
    /// (that M's bits).
    coriolis: CoriolisCache,
    /// Weighted columns of data alone, and their products.
    columns: blocks::ColumnCache,
}

/// C(ν)ν per sample by run, with the bits of the M it was built from.
type CoriolisCache = RefCell<HashMap<usize, (Vec<u64>, Rc<Vec<[f64; 6]>>)>>;

/// Filtered regressors by (term, coefficient, row, run).
type RegressorCache = RefCell<HashMap<(Effect, usize, usize, usize), Rc<Vec<f64>>>>;

use blocks::{BaseCache, dot, weighted};

/// One (row, run) block of the stacked regression: global parameter
/// indices, their weighted columns, the weighted target.
type Block = (Vec<usize>, Vec<Rc<Vec<f64>>>, Rc<Vec<f64>>);

/// Effects whose fits iterate M, D̄ (and the current) to a fixed point.
fn iterates(e: Effect) -> bool {
    matches!(e, Effect::Current | Effect::CoriolisFromM)
}

/// A shape profile's fits ([`Prepared::shape_profile`]).
pub(crate) struct ShapeFits<'p, 'a> {
    prep: &'p Prepared<'a>,
    normal: equations::Normal,
    specs: Vec<Spec>,
    /// θ is [`Prepared::fit`]'s at every shape, not only at the first.
    pub exact: bool,
}

impl ShapeFits<'_, '_> {
    /// θ with the last spec's shape at `v` (no residuals: `sse` NaN); the
    /// same θ as [`Prepared::fit`] of those specs.
    pub fn at(&self, v: f64) -> Option<FitOut> {
        let mut specs = self.specs.clone();
        let last = specs.len() - 1;
        specs[last].shape = Some(v);
        self.prep.reshaped(&self.normal, &specs, last)
    }
}

/// A fitted hypothesis.
#[derive(Debug, Clone)]
pub(crate) struct FitOut {
    pub rows: Vec<usize>,
    /// Per row of `rows`: (M free values, D̄ free values).
    pub base: Vec<(Vec<f64>, Vec<f64>)>,
    /// Per spec: its linear coefficients.
    pub theta: Vec<Vec<f64>>,
    /// Global parameter index of each spec's first coefficient.
    pub theta_index: Vec<usize>,
    /// Weighted residual sum of squares.
    pub sse: f64,
    /// Stacked samples.
    pub n: usize,
    /// HAC covariance of the terms' coefficients (every spec's θ, in
    /// parameter order from `theta_index[0]`), if asked for.
    pub cov: Option<DMatrix<f64>>,
    /// Weighted residuals per (row, run) block.
    pub resid: Vec<Vec<f64>>,
    /// The row of each block of `resid`.
    pub block_rows: Vec<usize>,
    /// D̄ the current's regressors were built with.
    pub d_ref: DMatrix<f64>,
    /// M the C(ν)ν regressors were built with.
    pub m_ref: DMatrix<f64>,
    /// Per row of `rows`: the change of its constant load b, refitted with
    /// a force fixed in NED ([`Effect::fixed_in_ned`]); `None` when held.
    pub loads: Vec<Option<f64>>,
    /// Per spec: its coefficients were held ([`Prepared::holding`]), not
    /// fitted.
    pub held: Vec<bool>,
}

impl FitOut {
    /// HAC covariance of spec `s`'s coefficients.
    pub fn theta_cov(&self, s: usize) -> Option<DMatrix<f64>> {
        if self.held.get(s).copied().unwrap_or(false) {
            return None;
        }
        let cov = self.cov.as_ref()?;
        let k = self.theta.get(s)?.len();
        let i = self.theta_index[s] - self.theta_index[0];
        Some(cov.view((i, i), (k, k)).into_owned())
    }
}

impl<'a> Prepared<'a> {
    /// Filters every run and fits the baseline structure per row to set
    /// the weights and κ. `None` when no row has samples left.
    pub fn new(
        baseline: &'a Baseline,
        records: &'a [Record],
        svf_t: f64,
        skip: usize,
        hac_lags: usize,
    ) -> Option<Self> {
        let h = records.first()?.h;
        let svf = Svf::new(svf_t, h);
        let n = baseline.n();
        let runs: Vec<PrepRun> = records
            .iter()
            .map(|rec| {
                let mut p = PrepRun {
                    g: vec![],
                    lam_nu: vec![],
                    dlam_nu: vec![],
                    lam_tau: vec![],
                    lam_g: vec![],
                    lam_one: svf.zoh(&vec![1.0; rec.len()]),
                };
                // g(η) and, when the baseline carries it, C(δ)δ at the
                // measured ν: the forces the baseline already explains.
                let gs: Vec<Vec<f64>> = (0..rec.len())
                    .map(|k| {
                        let nu: Vec<f64> = rec.nu.row(k).iter().copied().collect();
                        baseline.known_force(&rec.eta_at(k), &nu)
                    })
                    .collect();
                for i in 0..n {
                    let nu = rec.nu.column(i);
                    let l = svf.foh(nu.as_slice());
                    p.dlam_nu.push(svf.derivative(nu.as_slice(), &l));
                    p.lam_nu.push(l);
                    p.lam_tau.push(svf.zoh(rec.tau.column(i).as_slice()));
                    let g: Vec<f64> = gs.iter().map(|g| g[i]).collect();
                    p.lam_g.push(svf.foh(&g));
                    p.g.push(g);
                }
                p
            })
            .collect();
        let unforced = unforced_rows(&runs, baseline);
        let structure = (0..n)
            .map(|i| {
                let mf = (0..n)
                    .filter(|&j| baseline.m[(i, j)] != 0.0 || i == j)
                    .filter(|&j| !(j == i && unforced.contains(&i)))
                    .collect();
                let df = (0..n)
                    .filter(|&j| baseline.d_bar[(i, j)] != 0.0 || i == j)
                    .collect();
                (mf, df)
            })
            .collect();
        let mut prep = Prepared {
            records,
            baseline,
            svf,
            skip,
            runs,
            structure,
            frozen: false,
            held: vec![],
            weights: vec![1.0; n],
            kappa: 1.0,
            hac_lags,
            regressors: RefCell::new(HashMap::new()),
            base_blocks: RefCell::new(HashMap::new()),
            stage_trig: RefCell::new(HashMap::new()),
            coriolis: RefCell::new(HashMap::new()),
            columns: blocks::ColumnCache::default(),
        };
        let all: Vec<usize> = (0..records.len()).collect();
        let mut weights = vec![1.0; n];
        for (i, w) in weights.iter_mut().enumerate() {
            let f = prep.fit(&[], &[i], &all, false)?;
            let s = (f.sse / f.n.max(1) as f64).sqrt();
            *w = if s > 0.0 && s.is_finite() {
                1.0 / s
            } else {
                1.0
            };
        }
        prep.weights = weights;
        let all_rows: Vec<usize> = (0..n).collect();
        let null = prep.fit(&[], &all_rows, &all, false)?;
        prep.kappa = long_run_inflation(&null.resid, hac_lags);
        Some(prep)
    }

    /// The same runs with the baseline's M and D̄ held: fits then estimate
    /// only the terms' coefficients (the window test of a current, where a
    /// short window would trade M, D̄ against the current).
    pub fn frozen(mut self) -> Self {
        self.frozen = true;
        for s in &mut self.structure {
            *s = (vec![], vec![]);
        }
        self
    }

    /// The same runs with the coefficients of `terms` held: a spec of one
    /// of their effects adds its force at those values to the known side
    /// and fits nothing of its own (M, D̄ and the other terms are fitted
    /// around it).
    pub fn holding(mut self, terms: Vec<ModelTerm>) -> Self {
        self.held = terms;
        self
    }

    /// The held coefficients of `effect`, if it is held.
    fn held_values(&self, effect: Effect) -> Option<&ModelTerm> {
        self.held.iter().find(|t| t.effect == effect)
    }

    /// Columns of row `r` a fit of `rows` frees: the baseline's free
    /// entries, or with `hold` only those in the columns of the refitted
    /// rows (an entry coupling `r` to a DOF whose row is not refitted then
    /// stays at the baseline's value).
    fn freed(&self, r: usize, rows: &[usize], hold: bool) -> (Vec<usize>, Vec<usize>) {
        let (mf, df) = &self.structure[r];
        let keep = |j: &&usize| !hold || rows.contains(j);
        (
            mf.iter().filter(keep).copied().collect(),
            df.iter().filter(keep).copied().collect(),
        )
    }

    /// Rows touched by `specs` plus `extra`, sorted.
    pub fn rows_of(&self, specs: &[Spec], extra: &[usize]) -> Vec<usize> {
        let mut rows: Vec<usize> = extra.to_vec();
        for s in specs {
            rows.extend(s.effect.rows(&self.baseline.dofs, &self.baseline.d_bar));
        }
        rows.sort_unstable();
        rows.dedup();
        rows
    }

    /// Fits `specs` jointly with the baseline entries of their rows (and of
    /// `extra` rows) on the runs `runs`. `None` if nothing is left to fit.
    pub fn fit(
        &self,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
        hac: bool,
    ) -> Option<FitOut> {
        self.fit_iterated(specs, extra, runs, hac, false)
            .map(|(f, ..)| f)
    }

    /// [`Self::fit`] for the model that is kept: the refitted rows'
    /// couplings to DOFs whose rows are not refitted stay at the baseline's
    /// values ([`Self::freed`]). Free couplings let a term borrow from its
    /// neighbours, which serves the search (the term's evidence is judged
    /// with the most flexible row) but through M⁻¹ moves the predictions of
    /// DOFs the hypothesis never touched.
    pub fn fit_for_model(&self, specs: &[Spec], runs: &[usize], hac: bool) -> Option<FitOut> {
        self.fit_iterated(specs, &[], runs, hac, true)
            .map(|(f, ..)| f)
    }

    /// The fits of `specs` over a shape profile of its last spec: its
    /// normal equations assembled once, each shape then changing only the
    /// targets of the rows its actuator drives ([`Self::reshaped`]).
    ///
    /// A fit with a current or C(ν) from M iterates (their regressors
    /// follow the fitted M, D̄, see [`Self::fit`]); over a profile those
    /// stay where the full fit at `specs`' own shape left them, which
    /// moves θ at other shapes by far less than the profile resolves.
    pub(crate) fn shape_profile(
        &self,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
    ) -> Option<ShapeFits<'_, 'a>> {
        specs.last()?.shape?;
        let exact = !specs.iter().any(|s| iterates(s.effect));
        let (m, d, at) = if exact {
            (self.baseline.m.clone(), self.baseline.d_bar.clone(), None)
        } else {
            let (_, m, d, at) = self.fit_iterated(specs, extra, runs, false, false)?;
            (m, d, at)
        };
        let normal = self.assemble(&m, &d, specs, extra, runs, false, at)?;
        Some(ShapeFits {
            prep: self,
            normal,
            specs: specs.to_vec(),
            exact,
        })
    }

    /// A fit of `specs` (couplings to rows not refitted held at the
    /// baseline's with `hold`), with the M, D̄ and current its last pass
    /// was assembled with.
    #[allow(clippy::type_complexity)]
    fn fit_iterated(
        &self,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
        hac: bool,
        hold: bool,
    ) -> Option<(FitOut, DMatrix<f64>, DMatrix<f64>, Option<[f64; 2]>)> {
        let current = specs.iter().position(|s| s.effect == Effect::Current);
        let (mut m, mut d) = (self.baseline.m.clone(), self.baseline.d_bar.clone());
        if !specs.iter().any(|s| iterates(s.effect)) {
            let f = self.fit_with(&m, &d, specs, extra, runs, hac, hold, None)?;
            return Some((f, m, d, None));
        }
        // The current's estimate of a fit, where the next one linearizes
        // the quadratic drag on ν_r (see `through_water`).
        let estimate = |f: &FitOut| {
            current
                .and_then(|si| f.theta.get(si))
                .filter(|t| t.len() == 2 && t.iter().all(|x| x.is_finite()))
                .map(|t| [t[0], t[1]])
        };
        let current = current.is_some();
        // The current acts through D̄ and M on ν − ν_c, and C(ν) is built from M:
        // their regressors need the D̄ and M being fitted. A baseline
        // identified with the effect present has them biased (it absorbed
        // the effect's linear part), so iterate to the fixed point.
        let start = current.then_some([0.0; 2]);
        let mut f = self.fit_with(&m, &d, specs, extra, runs, false, hold, start)?;
        let mut at = start;
        for pass in 0..3 {
            let (m_new, d_new) = self.refitted(specs, &f, &m, &d);
            m = m_new;
            if current {
                d = d_new;
            }
            at = estimate(&f).or(start);
            f = self.fit_with(&m, &d, specs, extra, runs, hac && pass == 2, hold, at)?;
        }
        Some((f, m, d, at))
    }

    /// (M, D̄) with the rows and coupling entries of `f` written into
    /// (`m`, `d`).
    fn refitted(
        &self,
        specs: &[Spec],
        f: &FitOut,
        m: &DMatrix<f64>,
        d: &DMatrix<f64>,
    ) -> (DMatrix<f64>, DMatrix<f64>) {
        let (mut m, mut d) = (m.clone(), d.clone());
        for (ri, &r) in f.rows.iter().enumerate() {
            let (mf, df) = &self.structure[r];
            for (k, &j) in mf.iter().enumerate() {
                m[(r, j)] = f.base[ri].0[k];
            }
            for (k, &j) in df.iter().enumerate() {
                d[(r, j)] = f.base[ri].1[k];
            }
        }
        for (si, s) in specs.iter().enumerate() {
            if let Effect::Coupling { dof, from } = s.effect
                && let (Some(i), Some(j)) =
                    (self.baseline.index_of(dof), self.baseline.index_of(from))
            {
                m[(i, j)] = f.theta[si][0];
                d[(i, j)] = f.theta[si][1];
            }
        }
        (m, d)
    }

    /// The augmented model of a fit: the baseline with the fitted rows
    /// replaced, coupling entries set, the terms attached, and the
    /// baseline's C(δ)δ and D_q|δ|δ carried (the fit put them on the known
    /// side).
    pub fn model(&self, specs: &[Spec], f: &FitOut, shape_std: &[Option<f64>]) -> AugmentedModel {
        let b = self.baseline;
        let (m, d) = self.refitted(specs, f, &b.m, &b.d_bar);
        let mut restoring = b.restoring;
        for (&r, load) in f.rows.iter().zip(&f.loads) {
            if let Some(db) = load {
                restoring.constant[b.dofs[r].index()] += db;
            }
        }
        let mut terms = Vec::with_capacity(specs.len());
        for (si, s) in specs.iter().enumerate() {
            if let Some(t) = self.held_values(s.effect) {
                terms.push(ModelTerm {
                    shape: s.shape,
                    ..t.clone()
                });
                continue;
            }
            let covariance = f
                .theta_cov(si)
                .map(|c| {
                    (0..c.nrows())
                        .map(|i| c.row(i).iter().copied().collect())
                        .collect()
                })
                .unwrap_or_default();
            terms.push(ModelTerm {
                effect: s.effect,
                coefficients: f.theta[si].clone(),
                covariance,
                shape: s.shape,
                shape_std: shape_std.get(si).copied().flatten(),
            });
        }
        AugmentedModel::new(
            b.dofs.clone(),
            m,
            d,
            restoring,
            f.m_ref.clone(),
            f.d_ref.clone(),
            terms,
        )
        .with_coriolis(b.coriolis.clone())
        .with_quadratic(b.quadratic.clone())
    }

    /// (M_rr, D̄_rr) of row `r` (the `ri`-th of `f`) after the fit, where
    /// the fit frees them.
    pub fn row_diagonal(&self, f: &FitOut, ri: usize, r: usize) -> (Option<f64>, Option<f64>) {
        let (mf, df) = &self.structure[r];
        let (m, d) = &f.base[ri];
        (
            mf.iter().position(|&j| j == r).map(|k| m[k]),
            df.iter().position(|&j| j == r).map(|k| d[k]),
        )
    }

    /// Pooled |τ| of one DOF over `runs`, sorted (for threshold grids).
    pub fn abs_tau_sorted(&self, row: usize, runs: &[usize]) -> Vec<f64> {
        let mut v: Vec<f64> = runs
            .iter()
            .flat_map(|&r| {
                self.records[r]
                    .tau
                    .column(row)
                    .iter()
                    .map(|x| x.abs())
                    .collect::<Vec<_>>()
            })
            .filter(|x| x.is_finite())
            .collect();
        v.sort_by(|a, b| a.total_cmp(b));
        v
    }
}

/// A row whose known force [λτ_i] − [λg_i] (without its constant load)
/// stays below this fraction of the baseline's own inertial and damping
/// force in it, RMS over the runs, is taken as never forced.
const UNFORCED_FRACTION: f64 = 1e-3;

/// The rows no run forced (an underactuated vessel's sway, τ_Y = 0): their
/// equation M_i· ν̇ + D̄_i· ν + θ φ = 0 is homogeneous and fits best with
/// everything zero, so M_ii is held at the baseline's value (the scale the
/// identification gave it) and the rest of the row is fitted against it.
/// A constant load does not force the row: it is the offset of the
/// damping's linearization, or a force fixed in NED the baseline absorbed,
/// and is refitted with such a force.
fn unforced_rows(runs: &[PrepRun], baseline: &Baseline) -> Vec<usize> {
    (0..baseline.n())
        .filter(|&i| {
            let b = baseline.restoring.constant[baseline.dofs[i].index()];
            let (mut tau, mut own, mut count) = (0.0, 0.0, 0usize);
            for r in runs {
                let (t, g, one) = (&r.lam_tau[i], &r.lam_g[i], &r.lam_one);
                let (a, v) = (&r.dlam_nu[i], &r.lam_nu[i]);
                for k in 0..t.len().min(g.len()).min(a.len()).min(v.len()) {
                    let f = baseline.m[(i, i)] * a[k] + baseline.d_bar[(i, i)] * v[k];
                    let known = t[k] - g[k] + b * one[k];
                    tau += known * known;
                    own += f * f;
                    count += 1;
                }
            }
            count > 0 && own > 0.0 && tau <= UNFORCED_FRACTION * UNFORCED_FRACTION * own
        })
        .collect()
}

mod blocks;
mod equations;
mod hac;
mod kstep;
mod profile;
mod regressors;
mod through_water;

pub(crate) use profile::{long_run_inflation, profile};

#[cfg(test)]
mod tests;
