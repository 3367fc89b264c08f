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
    /// 1/σ_i of the baseline's equation error per row.
    pub weights: Vec<f64>,
    /// Long-run variance inflation of the residuals (≥ 1).
    pub kappa: f64,
    /// Bartlett lags of the HAC covariance.
    pub hac_lags: usize,
    /// Filtered regressors that depend on the data alone, by (term,
    /// coefficient, row, run).
    regressors: RegressorCache,
}

/// Filtered regressors by (term, coefficient, row, run).
type RegressorCache = RefCell<HashMap<(Effect, usize, usize, usize), Rc<Vec<f64>>>>;

/// One (row, run) block of the stacked regression: global parameter
/// indices, their weighted columns, the weighted target.
type Block = (Vec<usize>, Vec<Vec<f64>>, Vec<f64>);

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
}

impl FitOut {
    /// HAC covariance of spec `s`'s coefficients.
    pub fn theta_cov(&self, s: usize) -> Option<DMatrix<f64>> {
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
        let runs = records
            .iter()
            .map(|rec| {
                let mut p = PrepRun {
                    g: vec![],
                    lam_nu: vec![],
                    dlam_nu: vec![],
                    lam_tau: vec![],
                    lam_g: vec![],
                };
                let gs: Vec<Vec<f64>> =
                    (0..rec.len()).map(|k| baseline.g(&rec.eta_at(k))).collect();
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
        let structure = (0..n)
            .map(|i| {
                let mf = (0..n)
                    .filter(|&j| baseline.m[(i, j)] != 0.0 || i == j)
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
            weights: vec![1.0; n],
            kappa: 1.0,
            hac_lags,
            regressors: RefCell::new(HashMap::new()),
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

    /// [λφ_p,r] of term `effect`, coefficient `pi`, row `r` on run `run`.
    /// Regressors that do not depend on the model's M and D̄ (all but C(ν)ν
    /// from M and the current) are computed once per run and kept: the
    /// search fits each hypothesis many times (folds, shape profiles).
    fn filtered_regressor(
        &self,
        effect: Effect,
        pi: usize,
        r: usize,
        run: usize,
        ctx: &TermContext<'_>,
    ) -> Rc<Vec<f64>> {
        let compute = || {
            let rec = &self.records[run];
            let mut nu = vec![0.0; rec.nu.ncols()];
            let raw: Vec<f64> = (0..rec.len())
                .map(|k| {
                    for (j, v) in nu.iter_mut().enumerate() {
                        *v = rec.nu[(k, j)];
                    }
                    effect.regressor(pi, r, ctx, &nu, &rec.eta_at(k))
                })
                .collect();
            Rc::new(self.svf.foh(&raw))
        };
        if effect == Effect::Current {
            return self.current_regressor(pi, r, run, ctx);
        }
        if effect == Effect::CoriolisFromM {
            return compute();
        }
        let key = (effect, pi, r, run);
        if let Some(f) = self.regressors.borrow().get(&key) {
            return Rc::clone(f);
        }
        let f = compute();
        self.regressors.borrow_mut().insert(key, Rc::clone(&f));
        f
    }

    /// The current's filtered regressor for coefficient `p` in row `r`.
    /// It is −d_u cos ψ + d_v sin ψ + m_u r sin ψ + m_v r cos ψ (north) and
    /// −d_v cos ψ − d_u sin ψ + m_v r sin ψ − m_u r cos ψ (east), with
    /// d, m the row's surge and sway entries of D̄, M: linear in them, and
    /// the λ filter is linear, so the four filtered data signals are kept
    /// per run and only combined here (the fixed point on D̄, M refits
    /// every hypothesis that carries a current several times).
    fn current_regressor(
        &self,
        p: usize,
        r: usize,
        run: usize,
        ctx: &TermContext<'_>,
    ) -> Rc<Vec<f64>> {
        let rec = &self.records[run];
        let (Some(iu), Some(iv)) = (ctx.index(Dof::Surge), ctx.index(Dof::Sway)) else {
            return Rc::new(vec![0.0; rec.len()]);
        };
        let yaw = ctx.index(Dof::Yaw);
        let basis = |b: usize| {
            let key = (Effect::Current, b, usize::MAX, run);
            if let Some(f) = self.regressors.borrow().get(&key) {
                return Rc::clone(f);
            }
            let raw: Vec<f64> = (0..rec.len())
                .map(|k| {
                    let (s, c) = rec.eta[(k, 5)].sin_cos();
                    let rate = yaw.map_or(0.0, |j| rec.nu[(k, j)]);
                    [c, s, rate * s, rate * c][b]
                })
                .collect();
            let f = Rc::new(self.svf.foh(&raw));
            self.regressors.borrow_mut().insert(key, Rc::clone(&f));
            f
        };
        let (du, dv) = (ctx.d_ref[(r, iu)], ctx.d_ref[(r, iv)]);
        let (mu, mv) = (ctx.m_ref[(r, iu)], ctx.m_ref[(r, iv)]);
        let coef = if p == 0 {
            [-du, dv, mu, mv]
        } else {
            [-dv, -du, mv, -mu]
        };
        let signals: Vec<Rc<Vec<f64>>> = (0..4).map(basis).collect();
        Rc::new(
            (0..rec.len())
                .map(|k| (0..4).map(|b| coef[b] * signals[b][k]).sum())
                .collect(),
        )
    }

    /// How much a term changes the model's account of the forces: per row,
    /// the RMS of the change of the (weighted) equation error from the fit
    /// without it (`null`) to the fit with it (`with`), over the RMS of the
    /// row's (weighted, λ-filtered) command on `runs`; the largest over
    /// `rows`. A term that only trades against refitted entries of M and D̄
    /// (a product collinear with a velocity at the grid speed) changes
    /// nothing, however large its coefficient. With tens of thousands of
    /// samples a term can be significant and still too small to matter to
    /// anyone designing a controller: this says how much it matters.
    /// `None` when the two fits do not cover the same blocks.
    pub fn force_share(
        &self,
        null: &FitOut,
        with: &FitOut,
        rows: &[usize],
        runs: &[usize],
    ) -> Option<f64> {
        if null.block_rows != with.block_rows
            || null
                .resid
                .iter()
                .zip(&with.resid)
                .any(|(a, b)| a.len() != b.len())
        {
            return None;
        }
        let mut share = 0.0_f64;
        for &r in rows {
            let num: f64 = null
                .resid
                .iter()
                .zip(&with.resid)
                .zip(&null.block_rows)
                .filter(|(_, row)| **row == r)
                .map(|((a, b), _)| a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>())
                .sum();
            let w = self.weights[r];
            let den: f64 = runs
                .iter()
                .filter(|&&run| self.records[run].len() > self.skip + 1)
                .map(|&run| {
                    self.runs[run].lam_tau[r][self.skip..]
                        .iter()
                        .map(|x| (w * x).powi(2))
                        .sum::<f64>()
                })
                .sum();
            if den > 0.0 && num.is_finite() {
                share = share.max((num / den).sqrt());
            }
        }
        Some(share)
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
            p += s.effect.n_linear();
        }
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
                let lam_tau_a = if shapes.iter().any(|(e, _)| e.acts_on(dof)) {
                    let (x, lag) = actuate(rec.tau.column(r).as_slice(), dof, &shapes);
                    match lag {
                        Some(t) => self.svf.foh(&lag_zoh(&x, t, rec.h)),
                        None => self.svf.zoh(&x),
                    }
                } else {
                    pr.lam_tau[r].clone()
                };
                let (mf, df) = &freed[ri];
                let held = |k: usize| {
                    let (m, d) = (&self.baseline.m, &self.baseline.d_bar);
                    (0..dofs.len())
                        .map(|j| {
                            let mh = if mf.contains(&j) { 0.0 } else { m[(r, j)] };
                            let dh = if df.contains(&j) { 0.0 } else { d[(r, j)] };
                            mh * pr.dlam_nu[j][k] + dh * pr.lam_nu[j][k]
                        })
                        .sum::<f64>()
                };
                let y: Vec<f64> = (self.skip..len)
                    .map(|k| w * (lam_tau_a[k] - pr.lam_g[r][k] - held(k)))
                    .collect();
                let mut idx = Vec::new();
                let mut cols: Vec<Vec<f64>> = Vec::new();
                let mut q = base_index[ri];
                for &j in mf {
                    idx.push(q);
                    q += 1;
                    cols.push(pr.dlam_nu[j][self.skip..].iter().map(|x| w * x).collect());
                }
                for &j in df {
                    idx.push(q);
                    q += 1;
                    cols.push(pr.lam_nu[j][self.skip..].iter().map(|x| w * x).collect());
                }
                for (si, s) in specs.iter().enumerate() {
                    let nl = s.effect.n_linear();
                    if nl == 0 || !s.effect.rows(dofs, &self.baseline.d_bar).contains(&r) {
                        continue;
                    }
                    if let Effect::Coupling { from, .. } = s.effect {
                        let j = dofs.iter().position(|&d| d == from)?;
                        idx.push(theta_index[si]);
                        cols.push(pr.dlam_nu[j][self.skip..].iter().map(|x| w * x).collect());
                        idx.push(theta_index[si] + 1);
                        cols.push(pr.lam_nu[j][self.skip..].iter().map(|x| w * x).collect());
                        continue;
                    }
                    for pi in 0..nl {
                        let f = self.filtered_regressor(s.effect, pi, r, run, &ctx);
                        idx.push(theta_index[si] + pi);
                        cols.push(f[self.skip..].iter().map(|x| w * x).collect());
                    }
                }
                for a in 0..idx.len() {
                    bvec[idx[a]] += dot(&cols[a], &y);
                    for b in a..idx.len() {
                        let v = dot(&cols[a], &cols[b]);
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
            let e: Vec<f64> = (0..y.len())
                .map(|k| {
                    y[k] - idx
                        .iter()
                        .zip(cols)
                        .map(|(&i, c)| theta_all[i] * c[k])
                        .sum::<f64>()
                })
                .collect();
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
            .map(|(s, &i)| theta_all[i..i + s.effect.n_linear()].to_vec())
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
        })
    }

    /// The augmented model of a fit: the baseline with the fitted rows
    /// replaced, coupling entries set, and the terms attached.
    pub fn model(&self, specs: &[Spec], f: &FitOut, shape_std: &[Option<f64>]) -> AugmentedModel {
        let b = self.baseline;
        let (m, d) = self.refitted(specs, f, &b.m, &b.d_bar);
        let mut terms = Vec::with_capacity(specs.len());
        for (si, s) in specs.iter().enumerate() {
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
            b.restoring,
            f.m_ref.clone(),
            f.d_ref.clone(),
            terms,
        )
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

impl Prepared<'_> {
    /// [`Self::kstep_row`] over several rows: each row's errors scaled by
    /// its equation weight times M_rr (velocity error → normalized force),
    /// so DOFs in different units add up.
    pub fn kstep_rows(
        &self,
        specs: &[Spec],
        f: &FitOut,
        rows: &[usize],
        runs: &[usize],
        k: usize,
    ) -> Option<(f64, Vec<Vec<f64>>)> {
        if let [r] = rows {
            return self.kstep_row(specs, f, *r, runs, k);
        }
        let mut sse = 0.0;
        let mut resid = Vec::new();
        for &r in rows {
            let (s, e) = self.kstep_row(specs, f, r, runs, k)?;
            let w = self.weights[r] * self.baseline.m[(r, r)].abs();
            sse += w * w * s;
            resid.extend(
                e.into_iter()
                    .map(|v| v.into_iter().map(|x| w * x).collect::<Vec<_>>()),
            );
        }
        Some((sse, resid))
    }

    /// Output error of one row: the k-step-ahead prediction of ν_r from
    /// the measured ν_r(t−k), the other velocities and η taken as measured
    /// (linear between samples), under the fitted row of `f`. Returns the
    /// squared-error sum and the residual runs.
    ///
    /// Why: an actuator lag T_a ≈ M_ii/D̄_ii with M_ii → 0 re-describes a
    /// first-order DOF exactly, and the equation error prefers it because
    /// it drops the noisy [sλν] regressor. Prediction error carries no such
    /// bias, so shape parameters are profiled on it.
    pub fn kstep_row(
        &self,
        specs: &[Spec],
        f: &FitOut,
        r: usize,
        runs: &[usize],
        k: usize,
    ) -> Option<(f64, Vec<Vec<f64>>)> {
        let ri = f.rows.iter().position(|&x| x == r)?;
        let dofs = &self.baseline.dofs;
        let n = dofs.len();
        let (mf, df) = &self.structure[r];
        let mut m_row = vec![0.0; n];
        let mut d_row = vec![0.0; n];
        for (q, &j) in mf.iter().enumerate() {
            m_row[j] = f.base[ri].0[q];
        }
        for (q, &j) in df.iter().enumerate() {
            d_row[j] = f.base[ri].1[q];
        }
        let mut terms: Vec<(Effect, Vec<f64>)> = Vec::new();
        for (si, s) in specs.iter().enumerate() {
            if let Effect::Coupling { dof, from } = s.effect {
                if dofs[r] == dof {
                    let j = dofs.iter().position(|&d| d == from)?;
                    m_row[j] = f.theta[si][0];
                    d_row[j] = f.theta[si][1];
                }
            } else if s.effect.n_linear() > 0
                && s.effect.rows(dofs, &self.baseline.d_bar).contains(&r)
            {
                terms.push((s.effect, f.theta[si].clone()));
            }
        }
        let mrr = m_row[r];
        if mrr.is_nan() || mrr <= 0.0 {
            return None;
        }
        let shapes: Vec<(Effect, f64)> = specs
            .iter()
            .filter_map(|s| s.shape.map(|v| (s.effect, v)))
            .collect();
        let ctx = TermContext {
            dofs,
            m_ref: &f.m_ref,
            d_ref: &f.d_ref,
        };
        let k = k.max(1);
        let mut sse = 0.0;
        let mut resid = Vec::new();
        for &run in runs {
            let rec = &self.records[run];
            let pr = &self.runs[run];
            let len = rec.len();
            if len <= self.skip + k {
                continue;
            }
            let h = rec.h;
            let (held, lag) = actuate(rec.tau.column(r).as_slice(), dofs[r], &shapes);
            let lag_states = lag.map(|t| lag_zoh(&held, t, h));
            // Everything but τ_a and ν_r, at the samples (linear in between):
            // −g_r(η) − Σ_{j≠r} (D̄_rj ν_j + M_rj [sλν_j]).
            let ext: Vec<f64> = (0..len)
                .map(|kk| {
                    let mut v = -pr.g[r][kk];
                    for j in 0..n {
                        if j != r {
                            v -= d_row[j] * rec.nu[(kk, j)] + m_row[j] * pr.dlam_nu[j][kk];
                        }
                    }
                    v
                })
                .collect();
            let d_rr = d_row[r];
            let mut nu_buf = vec![0.0; n];
            let mut force = |k0: usize, frac: f64, nu_r: f64, tau_a: f64| -> f64 {
                let k1 = (k0 + 1).min(len - 1);
                let mut fr = tau_a + ext[k0] + frac * (ext[k1] - ext[k0]) - d_rr * nu_r;
                if !terms.is_empty() {
                    for (j, v) in nu_buf.iter_mut().enumerate() {
                        *v = rec.nu[(k0, j)] + frac * (rec.nu[(k1, j)] - rec.nu[(k0, j)]);
                    }
                    nu_buf[r] = nu_r;
                    let eta: [f64; 6] = std::array::from_fn(|j| {
                        rec.eta[(k0, j)] + frac * (rec.eta[(k1, j)] - rec.eta[(k0, j)])
                    });
                    for (e, th) in &terms {
                        for (p, c) in th.iter().enumerate() {
                            fr -= c * e.regressor(p, r, &ctx, &nu_buf, &eta);
                        }
                    }
                }
                fr / mrr
            };
            let mut e = Vec::with_capacity(len - self.skip);
            // Every other start point: neighbouring k-step errors share
            // k − 1 steps, so little information is lost for half the cost.
            for t in (self.skip..len).step_by(2) {
                let s0 = t - k;
                let mut x = rec.nu[(s0, r)];
                let mut a = lag_states.as_ref().map_or(0.0, |l| l[s0]);
                for (step, &u) in held.iter().enumerate().take(t).skip(s0) {
                    let ta = lag.unwrap_or(1.0);
                    let da = |a: f64| if lag.is_some() { (u - a) / ta } else { 0.0 };
                    let tau = |a: f64| if lag.is_some() { a } else { u };
                    let k1x = force(step, 0.0, x, tau(a));
                    let k1a = da(a);
                    let k2x = force(step, 0.5, x + 0.5 * h * k1x, tau(a + 0.5 * h * k1a));
                    let k2a = da(a + 0.5 * h * k1a);
                    let k3x = force(step, 0.5, x + 0.5 * h * k2x, tau(a + 0.5 * h * k2a));
                    let k3a = da(a + 0.5 * h * k2a);
                    let k4x = force(step, 1.0, x + h * k3x, tau(a + h * k3a));
                    let k4a = da(a + h * k3a);
                    x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                    a += h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a);
                }
                if !x.is_finite() {
                    return None;
                }
                let err = rec.nu[(t, r)] - x;
                sse += err * err;
                e.push(err);
            }
            resid.push(e);
        }
        Some((sse, resid))
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

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
    let inv = match hs.clone().cholesky() {
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

/// κ = 1 + 2 Σ_l (1 − l/(L+1)) ρ(l) of residual blocks (the factor by which
/// correlated residuals shrink the effective sample count), ≥ 1.
pub(crate) fn long_run_inflation(blocks: &[Vec<f64>], lags: usize) -> f64 {
    let mut r0 = 0.0;
    let mut rl = vec![0.0; lags + 1];
    for e in blocks {
        r0 += dot(e, e);
        for (l, acc) in rl.iter_mut().enumerate().skip(1) {
            if l < e.len() {
                *acc += dot(&e[l..], &e[..e.len() - l]);
            }
        }
    }
    if r0 <= 0.0 {
        return 1.0;
    }
    let k = 1.0
        + 2.0
            * (1..=lags)
                .map(|l| (1.0 - l as f64 / (lags as f64 + 1.0)) * rl[l] / r0)
                .sum::<f64>();
    k.max(1.0)
}

/// A profile search over a shape parameter on the k-step prediction error
/// of its row ([`Prepared::kstep_row`]): the grid minimum, refined by
/// golden section between its neighbours when `continuous`, with a standard
/// deviation from the curvature of the SSE (Δχ² = 1 at ΔSSE = κσ²).
pub(crate) struct Profile {
    pub value: f64,
    pub fit: FitOut,
    pub std: Option<f64>,
    /// k-step prediction SSE of the row at the optimum.
    pub sse: f64,
    /// Predicted samples.
    pub n: usize,
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn profile(
    prep: &Prepared<'_>,
    chosen: &[Spec],
    effect: Effect,
    extra: &[usize],
    runs: &[usize],
    grid: &[f64],
    continuous: bool,
    k: usize,
) -> Option<Profile> {
    extra.first()?;
    let specs_at = |v: f64| {
        let mut specs = chosen.to_vec();
        specs.push(Spec {
            effect,
            shape: Some(v),
        });
        specs
    };
    let lag = effect.shape() == Some(super::candidates::ShapeKind::LagTime);
    // A refitted row must stay a hull: M_rr > 0, D̄_rr ≥ 0, and a lag must
    // be the faster of the two poles. Lag T and the hull's M_rr/D̄_rr are
    // interchangeable in 1/((1+sT)(D̄ + sM)) — the data cannot tell them
    // apart — so the slow pole is the hull's and the fast one the
    // thruster's, as on every ROV and ship.
    let admissible = |f: &FitOut, v: f64| {
        f.rows.iter().enumerate().all(|(ri, &r)| {
            let (m, d) = prep.row_diagonal(f, ri, r);
            m.is_none_or(|m| m > 0.0)
                && d.is_none_or(|d| d >= 0.0)
                && !(lag && matches!((m, d), (Some(m), Some(d)) if d > 0.0 && m / d <= v))
        })
    };
    let eval = |v: f64| -> Option<FitOut> {
        prep.fit(&specs_at(v), extra, runs, false)
            .filter(|f| admissible(f, v))
    };
    let sse = |v: f64| {
        eval(v)
            .and_then(|f| prep.kstep_rows(&specs_at(v), &f, extra, runs, k))
            .map_or(f64::INFINITY, |x| x.0)
    };
    let values: Vec<f64> = grid.iter().map(|&g| sse(g)).collect();
    let (ib, _) = values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let mut best = grid[ib];
    if continuous && grid.len() >= 3 {
        // Golden section in log space (parameters are positive scales).
        let lo = grid[ib.saturating_sub(1)].ln();
        let hi = grid[(ib + 1).min(grid.len() - 1)].ln();
        let (mut a, mut b) = (lo, hi);
        let r = 0.618_033_988_749_895;
        let mut c = b - r * (b - a);
        let mut d = a + r * (b - a);
        let (mut fc, mut fd) = (sse(c.exp()), sse(d.exp()));
        for _ in 0..6 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - r * (b - a);
                fc = sse(c.exp());
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + r * (b - a);
                fd = sse(d.exp());
            }
        }
        let cand = if fc < fd { c.exp() } else { d.exp() };
        if sse(cand) < values[ib] {
            best = cand;
        }
    }
    let fit = eval(best)?;
    let (s0, resid) = prep.kstep_rows(&specs_at(best), &fit, extra, runs, k)?;
    let delta = if continuous {
        0.03 * best.abs().max(1e-9)
    } else {
        1.0
    };
    let (sm, sp) = (sse(best - delta), sse(best + delta));
    let curv = (sp - 2.0 * s0 + sm) / (delta * delta);
    let n: usize = resid.iter().map(Vec::len).sum();
    let kappa = long_run_inflation(&resid, prep.hac_lags.max(2 * k));
    let sigma2 = s0 / n.max(1) as f64;
    let std = (curv > 0.0 && sm.is_finite() && sp.is_finite())
        .then(|| (2.0 * sigma2 * kappa / curv).sqrt());
    Some(Profile {
        value: best,
        fit,
        std,
        sse: s0,
        n,
    })
}

#[cfg(test)]
mod tests;
