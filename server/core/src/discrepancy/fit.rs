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
}

/// Filtered regressors by (term, coefficient, row, run).
type RegressorCache = RefCell<HashMap<(Effect, usize, usize, usize), Rc<Vec<f64>>>>;

use blocks::{BaseCache, dot, weighted};

/// One (row, run) block of the stacked regression: global parameter
/// indices, their weighted columns, the weighted target.
type Block = (Vec<usize>, Vec<Rc<Vec<f64>>>, Rc<Vec<f64>>);

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
        self.fit_holding(specs, extra, runs, hac, false)
    }

    /// [`Self::fit`] for the model that is kept: the refitted rows'
    /// couplings to DOFs whose rows are not refitted stay at the baseline's
    /// values ([`Self::freed`]). Free couplings let a term borrow from its
    /// neighbours, which serves the search (the term's evidence is judged
    /// with the most flexible row) but through M⁻¹ moves the predictions of
    /// DOFs the hypothesis never touched.
    pub fn fit_for_model(&self, specs: &[Spec], runs: &[usize], hac: bool) -> Option<FitOut> {
        self.fit_holding(specs, &[], runs, hac, true)
    }

    fn fit_holding(
        &self,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
        hac: bool,
        hold: bool,
    ) -> Option<FitOut> {
        let current = specs.iter().any(|s| s.effect == Effect::Current);
        let coriolis = specs.iter().any(|s| s.effect == Effect::CoriolisFromM);
        let (mut m, mut d) = (self.baseline.m.clone(), self.baseline.d_bar.clone());
        if !current && !coriolis {
            return self.fit_with(&m, &d, specs, extra, runs, hac, hold);
        }
        // The current acts through D̄ and M on ν − ν_c, and C(ν) is built from M:
        // their regressors need the D̄ and M being fitted. A baseline
        // identified with the effect present has them biased (it absorbed
        // the effect's linear part), so iterate to the fixed point.
        let mut f = self.fit_with(&m, &d, specs, extra, runs, false, hold)?;
        for pass in 0..3 {
            let (m_new, d_new) = self.refitted(specs, &f, &m, &d);
            m = m_new;
            if current {
                d = d_new;
            }
            f = self.fit_with(&m, &d, specs, extra, runs, hac && pass == 2, hold)?;
        }
        Some(f)
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

    #[allow(clippy::too_many_arguments)]
    fn fit_with(
        &self,
        m_ref: &DMatrix<f64>,
        d_ref: &DMatrix<f64>,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
        hac: bool,
        hold: bool,
    ) -> Option<FitOut> {
        let rows = self.rows_of(specs, extra);
        if rows.is_empty() {
            return None;
        }
        let dofs = &self.baseline.dofs;
        let shapes: Vec<(Effect, f64)> = specs
            .iter()
            .filter_map(|s| s.shape.map(|v| (s.effect, v)))
            .collect();
        // Parameter layout: base entries of each row, then the specs' θ.
        let freed: Vec<(Vec<usize>, Vec<usize>)> =
            rows.iter().map(|&r| self.freed(r, &rows, hold)).collect();
        let mut base_index = Vec::with_capacity(rows.len());
        let mut p = 0;
        for (mf, df) in &freed {
            base_index.push(p);
            p += mf.len() + df.len();
        }
        let mut theta_index = Vec::with_capacity(specs.len());
        for s in specs {
            theta_index.push(p);
            if self.held_values(s.effect).is_none() {
                p += s.effect.n_linear();
            }
        }
        // The constant loads of the rows, after the terms' θ, when a force
        // fixed in NED is fitted (not when M, D̄ are held: a short window's
        // heading barely turns, and the force would be the load).
        let free_loads = !self.frozen && specs.iter().any(|s| s.effect.fixed_in_ned());
        let load_index: Vec<Option<usize>> = rows
            .iter()
            .map(|_| {
                free_loads.then(|| {
                    p += 1;
                    p - 1
                })
            })
            .collect();
        let ctx = TermContext { dofs, m_ref, d_ref };
        let mut hmat = DMatrix::<f64>::zeros(p, p);
        let mut bvec = vec![0.0; p];
        let mut blocks: Vec<Block> = Vec::new();
        let mut block_rows: Vec<usize> = Vec::new();
        let mut n_tot = 0;
        for &run in runs {
            let rec = &self.records[run];
            let pr = &self.runs[run];
            let len = rec.len();
            if len <= self.skip + 1 {
                continue;
            }
            for (ri, &r) in rows.iter().enumerate() {
                let w = self.weights[r];
                let dof = dofs[r];
                // Target [λτ_a] − [λg]: the applied force depends on the
                // actuator hypotheses of this DOF.
                let lam_tau_a = shapes.iter().any(|(e, _)| e.acts_on(dof)).then(|| {
                    let (x, lag) = actuate(rec.tau.column(r).as_slice(), dof, &shapes);
                    match lag {
                        Some(t) => self.svf.foh(&lag_zoh(&x, t, rec.h)),
                        None => self.svf.zoh(&x),
                    }
                });
                let (mf, df) = &freed[ri];
                let mut bb = self.base_block(run, r, w, mf, df, lam_tau_a);
                // Held terms' forces go to the known side.
                let held: Vec<&ModelTerm> = specs
                    .iter()
                    .filter_map(|s| self.held_values(s.effect))
                    .filter(|t| t.effect.rows(dofs, &self.baseline.d_bar).contains(&r))
                    .collect();
                if !held.is_empty() {
                    let mut y = bb.y.as_ref().clone();
                    for t in &held {
                        for (pi, c) in t.coefficients.iter().enumerate() {
                            let f = self.filtered_regressor(t.effect, pi, r, run, &ctx);
                            for (yk, fk) in y.iter_mut().zip(&f[self.skip..]) {
                                *yk -= c * w * fk;
                            }
                        }
                    }
                    bb.by = blocks::products(&y, &bb.cols);
                    bb.y = Rc::new(y);
                }
                let nb = bb.cols.len();
                let y = Rc::clone(&bb.y);
                let mut idx: Vec<usize> = (base_index[ri]..base_index[ri] + nb).collect();
                let mut cols: Vec<Rc<Vec<f64>>> = bb.cols.clone();
                for (si, s) in specs.iter().enumerate() {
                    let nl = s.effect.n_linear();
                    if nl == 0
                        || self.held_values(s.effect).is_some()
                        || !s.effect.rows(dofs, &self.baseline.d_bar).contains(&r)
                    {
                        continue;
                    }
                    if let Effect::Coupling { from, .. } = s.effect {
                        let j = dofs.iter().position(|&d| d == from)?;
                        idx.push(theta_index[si]);
                        cols.push(Rc::new(weighted(&pr.dlam_nu[j][self.skip..], w)));
                        idx.push(theta_index[si] + 1);
                        cols.push(Rc::new(weighted(&pr.lam_nu[j][self.skip..], w)));
                        continue;
                    }
                    for pi in 0..nl {
                        let f = self.filtered_regressor(s.effect, pi, r, run, &ctx);
                        idx.push(theta_index[si] + pi);
                        cols.push(Rc::new(weighted(&f[self.skip..], w)));
                    }
                }
                if let Some(li) = load_index[ri] {
                    idx.push(li);
                    cols.push(Rc::new(weighted(&pr.lam_one[self.skip..], w)));
                }
                // The baseline block's products come from the cache; the
                // terms' columns are multiplied with every column.
                let mut prods = vec![0.0; idx.len() + 1];
                for a in 0..idx.len() {
                    if a < nb {
                        bvec[idx[a]] += bb.by[a];
                    }
                    let from = a.max(nb);
                    let ys: Vec<&[f64]> = std::iter::once(y.as_slice())
                        .chain(cols[from..].iter().map(|c| c.as_slice()))
                        .collect();
                    let out = &mut prods[..ys.len()];
                    out.fill(0.0);
                    crate::kernels::dots(&cols[a], &ys, out);
                    if a >= nb {
                        bvec[idx[a]] += out[0];
                    }
                    for b in a..idx.len() {
                        let v = if b < nb {
                            bb.gram[a * nb + b]
                        } else {
                            out[1 + b - from]
                        };
                        hmat[(idx[a], idx[b])] += v;
                        if a != b {
                            hmat[(idx[b], idx[a])] += v;
                        }
                    }
                }
                n_tot += y.len();
                blocks.push((idx, cols, y));
                block_rows.push(r);
            }
        }
        if n_tot <= p {
            return None;
        }
        let (theta_all, h_inv) = solve_scaled(&hmat, &bvec)?;
        let mut sse = 0.0;
        let mut resid = Vec::with_capacity(blocks.len());
        for (idx, cols, y) in &blocks {
            // Σ_i θ_i c_i[k] column by column (the same order per sample).
            let mut fitted = vec![0.0; y.len()];
            for (&i, c) in idx.iter().zip(cols) {
                let t = theta_all[i];
                for (f, v) in fitted.iter_mut().zip(c.iter()) {
                    *f += t * v;
                }
            }
            let e: Vec<f64> = y.iter().zip(&fitted).map(|(y, f)| y - f).collect();
            sse += dot(&e, &e);
            resid.push(e);
        }
        // Sandwich H⁻¹ S H⁻¹ on the θ block only: with C = H⁻¹[θ, :] the
        // block is C S Cᵀ = Σ_l w_l Σ_k h_k h_{k−l}ᵀ over the projected
        // scores h_k = C φ_k e_k, which costs t² per lag instead of p².
        let t0 = theta_index.first().copied().unwrap_or(p);
        let cov = hac.then(|| {
            let t = p - t0;
            let mut s = DMatrix::<f64>::zeros(t, t);
            for ((idx, cols, _), e) in blocks.iter().zip(&resid) {
                let len = e.len();
                let mut h = vec![vec![0.0; len]; t];
                for (a, &ia) in idx.iter().enumerate() {
                    for (ti, hv) in h.iter_mut().enumerate() {
                        let c = h_inv[(t0 + ti, ia)];
                        if c != 0.0 {
                            for k in 0..len {
                                hv[k] += c * cols[a][k] * e[k];
                            }
                        }
                    }
                }
                for l in 0..=self.hac_lags.min(len.saturating_sub(1)) {
                    let wl = 1.0 - l as f64 / (self.hac_lags as f64 + 1.0);
                    for a in 0..t {
                        for b in 0..t {
                            let acc = dot(&h[a][l..], &h[b][..len - l]);
                            let v = if l == 0 { acc } else { wl * acc };
                            s[(a, b)] += v;
                            if l > 0 {
                                s[(b, a)] += v;
                            }
                        }
                    }
                }
            }
            s
        });
        let base = rows
            .iter()
            .enumerate()
            .map(|(ri, &r)| {
                // Every free entry of the row: fitted, or held at the baseline.
                let (mf, df) = &self.structure[r];
                let (fm, fd) = &freed[ri];
                let i0 = base_index[ri];
                let value = |free: &[usize], j: usize, at: usize, held: f64| {
                    free.iter()
                        .position(|&x| x == j)
                        .map_or(held, |k| theta_all[at + k])
                };
                (
                    mf.iter()
                        .map(|&j| value(fm, j, i0, self.baseline.m[(r, j)]))
                        .collect(),
                    df.iter()
                        .map(|&j| value(fd, j, i0 + fm.len(), self.baseline.d_bar[(r, j)]))
                        .collect(),
                )
            })
            .collect();
        let theta = specs
            .iter()
            .zip(&theta_index)
            .map(|(s, &i)| match self.held_values(s.effect) {
                Some(t) => t.coefficients.clone(),
                None => theta_all[i..i + s.effect.n_linear()].to_vec(),
            })
            .collect();
        let held = specs
            .iter()
            .map(|s| self.held_values(s.effect).is_some())
            .collect();
        let loads = load_index
            .iter()
            .map(|li| li.map(|i| theta_all[i]))
            .collect();
        Some(FitOut {
            rows,
            base,
            theta,
            theta_index,
            sse,
            n: n_tot,
            cov,
            resid,
            block_rows,
            d_ref: d_ref.clone(),
            m_ref: m_ref.clone(),
            loads,
            held,
        })
    }

    /// The augmented model of a fit: the baseline with the fitted rows
    /// replaced, coupling entries set, and the terms attached.
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

/// Smallest Cholesky pivot of the Jacobi-scaled normal matrix accepted as
/// non-singular (condition ≈ 10¹⁰).
const PIVOT_FLOOR: f64 = 1e-10;

/// Solves H θ = b with Jacobi scaling (columns span forces of 10⁴ N and
/// velocities of 10⁻² m/s); returns θ and H⁻¹.
fn solve_scaled(h: &DMatrix<f64>, b: &[f64]) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let p = h.nrows();
    let s: Vec<f64> = (0..p)
        .map(|i| {
            let d = h[(i, i)];
            if d > 0.0 { 1.0 / d.sqrt() } else { 1.0 }
        })
        .collect();
    let mut hs = DMatrix::from_fn(p, p, |i, j| h[(i, j)] * s[i] * s[j]);
    let bs = nalgebra::DVector::from_fn(p, |i, _| b[i] * s[i]);
    // A pivot below 1e-10 of the unit diagonal is a column the others
    // determine to rounding (a term collinear with D̄): whether Cholesky
    // then succeeds is chance, and its inverse is noise. The pseudo-inverse
    // gives the minimum-norm fit instead.
    let factor = hs
        .clone()
        .cholesky()
        .filter(|c| (0..p).all(|i| c.l_dirty()[(i, i)].powi(2) > PIVOT_FLOOR));
    let inv = match factor {
        Some(c) => c.inverse(),
        None => {
            for i in 0..p {
                hs[(i, i)] += 1e-10;
            }
            hs.clone().pseudo_inverse(1e-12).ok()?
        }
    };
    let z = &inv * bs;
    let theta: Vec<f64> = (0..p).map(|i| z[i] * s[i]).collect();
    if theta.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let h_inv = DMatrix::from_fn(p, p, |i, j| inv[(i, j)] * s[i] * s[j]);
    Some((theta, h_inv))
}

mod blocks;
mod kstep;
mod profile;
mod regressors;

pub(crate) use profile::{long_run_inflation, profile};

#[cfg(test)]
mod tests;
