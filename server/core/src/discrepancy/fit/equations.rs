//! One fit's weighted normal equations: the rows' baseline blocks, the
//! terms' filtered regressors and the constant loads assembled over the
//! runs, solved with Jacobi scaling, with HAC covariances.

use super::hac;
use super::*;
use blocks::Column;
use regressors::depends_on_data_alone;

/// One fit's stacked normal equations before solving. A shape profile
/// reuses them: a shape (lag, delay, saturation, dead zone) has no linear
/// coefficient, so only the targets of the rows its actuator drives change
/// with it, never the columns or H.
pub(super) struct Normal {
    rows: Vec<usize>,
    freed: Vec<(Vec<usize>, Vec<usize>)>,
    base_index: Vec<usize>,
    theta_index: Vec<usize>,
    load_index: Vec<Option<usize>>,
    hmat: DMatrix<f64>,
    blocks: Vec<Block>,
    block_rows: Vec<usize>,
    block_runs: Vec<usize>,
    /// Per block: each column's product with the target, in column order
    /// (b is their sum over blocks, in block order).
    targets: Vec<Vec<f64>>,
    n_tot: usize,
    /// The M and D̄ the terms' regressors were built with.
    m_ref: DMatrix<f64>,
    d_ref: DMatrix<f64>,
    /// Where the current's drag was linearized ([`Prepared::assemble`]).
    water: Option<([f64; 2], bool)>,
}

impl Normal {
    /// b = Σ_blocks Xᵀy, with the targets of `targets` (per block).
    fn rhs(&self, targets: &[impl AsRef<[f64]>]) -> Vec<f64> {
        let mut bvec = vec![0.0; self.hmat.nrows()];
        for ((idx, _, _), t) in self.blocks.iter().zip(targets) {
            for (&i, v) in idx.iter().zip(t.as_ref()) {
                bvec[i] += v;
            }
        }
        bvec
    }
}

impl Prepared<'_> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn fit_with(
        &self,
        m_ref: &DMatrix<f64>,
        d_ref: &DMatrix<f64>,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
        hac: bool,
        hold: bool,
        current_at: Option<[f64; 2]>,
    ) -> Option<FitOut> {
        let normal = self.assemble(m_ref, d_ref, specs, extra, runs, hold, current_at)?;
        let bvec = normal.rhs(&normal.targets);
        let (theta_all, h_inv) = solve_scaled(&normal.hmat, &bvec)?;
        Some(self.fit_out(&normal, specs, theta_all, Some((&h_inv, hac))))
    }

    /// θ of `specs` — the specs `normal` was assembled for, but for the
    /// shape of `specs[shaped]` — with the targets of the rows that shape's
    /// actuator drives rebuilt. The fit has no residuals (`sse` NaN) and no
    /// covariance: the points of a shape profile, where only θ is read.
    pub(super) fn reshaped(
        &self,
        normal: &Normal,
        specs: &[Spec],
        shaped: usize,
    ) -> Option<FitOut> {
        let dofs = &self.baseline.dofs;
        let shapes = shapes_of(specs);
        let effect = specs[shaped].effect;
        let ctx = TermContext {
            dofs,
            m_ref: &normal.m_ref,
            d_ref: &normal.d_ref,
        };
        let targets: Vec<std::borrow::Cow<'_, [f64]>> = normal
            .blocks
            .iter()
            .enumerate()
            .map(|(bi, (_, cols, _))| {
                let r = normal.block_rows[bi];
                if !effect.acts_on(dofs[r]) {
                    return std::borrow::Cow::Borrowed(normal.targets[bi].as_slice());
                }
                let run = normal.block_runs[bi];
                let ri = normal
                    .rows
                    .iter()
                    .position(|&x| x == r)
                    .expect("a block's row");
                let (mf, df) = &normal.freed[ri];
                let (bb, _) = self.block_target(run, r, mf, df, specs, &shapes, normal.water, &ctx);
                let mut t = bb.by;
                for c in &cols[t.len()..] {
                    let mut out = [0.0];
                    crate::kernels::dots(c, &[bb.y.as_slice()], &mut out);
                    t.push(out[0]);
                }
                std::borrow::Cow::Owned(t)
            })
            .collect();
        let bvec = normal.rhs(&targets);
        let (theta_all, _) = solve_scaled(&normal.hmat, &bvec)?;
        Some(self.fit_out(normal, specs, theta_all, None))
    }

    /// The target of row `r` on `run` under the actuator hypotheses
    /// `shapes` ([λτ_a] − [λg], held terms' forces and the baseline's D_q
    /// through the water on the known side) with the baseline block's
    /// columns and their products with it, and the current's shift.
    #[allow(clippy::too_many_arguments)]
    fn block_target(
        &self,
        run: usize,
        r: usize,
        mf: &[usize],
        df: &[usize],
        specs: &[Spec],
        shapes: &[(Effect, f64)],
        water: Option<([f64; 2], bool)>,
        ctx: &TermContext<'_>,
    ) -> (blocks::BaseBlock, Option<through_water::ThroughWater>) {
        let rec = &self.records[run];
        let dofs = &self.baseline.dofs;
        let w = self.weights[r];
        let dof = dofs[r];
        // Target [λτ_a] − [λg]: the applied force depends on the
        // actuator hypotheses of this DOF.
        let lam_tau_a = shapes.iter().any(|(e, _)| e.acts_on(dof)).then(|| {
            let (x, lag) = actuate(rec.tau.column(r).as_slice(), dof, shapes);
            match lag {
                Some(t) => self.svf.foh(&lag_zoh(&x, t, rec.h)),
                None => self.svf.zoh(&x),
            }
        });
        let mut bb = self.base_block(run, r, w, mf, df, lam_tau_a);
        // Held terms' forces go to the known side.
        let held: Vec<&ModelTerm> = specs
            .iter()
            .filter_map(|s| self.held_values(s.effect))
            .filter(|t| t.effect.rows(dofs, &self.baseline.d_bar).contains(&r))
            .collect();
        // The baseline's D_q on the velocity through the water.
        let water = water.and_then(|(at, held)| self.through_water(r, run, at, held));
        if !held.is_empty() || water.is_some() {
            let mut y = bb.y.as_ref().clone();
            for t in &held {
                for (pi, c) in t.coefficients.iter().enumerate() {
                    let f = self.filtered_regressor(t.effect, pi, r, run, ctx);
                    for (yk, fk) in y.iter_mut().zip(&f[self.skip..]) {
                        *yk -= c * w * fk;
                    }
                }
            }
            if let Some(tw) = &water {
                for (yk, fk) in y.iter_mut().zip(&tw.shift[self.skip..]) {
                    *yk -= w * fk;
                }
            }
            bb.by = blocks::products(&y, &bb.cols);
            bb.y = Rc::new(y);
        }
        (bb, water)
    }

    /// The normal equations of `specs` on `rows` (see [`Self::fit_with`]).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn assemble(
        &self,
        m_ref: &DMatrix<f64>,
        d_ref: &DMatrix<f64>,
        specs: &[Spec],
        extra: &[usize],
        runs: &[usize],
        hold: bool,
        current_at: Option<[f64; 2]>,
    ) -> Option<Normal> {
        let rows = self.rows_of(specs, extra);
        if rows.is_empty() {
            return None;
        }
        let dofs = &self.baseline.dofs;
        let shapes = shapes_of(specs);
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
        // Where the current's D_q|δ_r|δ_r is linearized (a held current: at
        // its value, exactly).
        let water: Option<([f64; 2], bool)> = specs
            .iter()
            .find(|s| s.effect == Effect::Current)
            .and_then(|s| match self.held_values(s.effect) {
                Some(t) if t.coefficients.len() == 2 => {
                    Some(([t.coefficients[0], t.coefficients[1]], true))
                }
                Some(_) => None,
                None => current_at.map(|at| (at, false)),
            });
        let mut hmat = DMatrix::<f64>::zeros(p, p);
        let mut blocks: Vec<Block> = Vec::new();
        let mut block_rows: Vec<usize> = Vec::new();
        let mut block_runs: Vec<usize> = Vec::new();
        let mut targets: Vec<Vec<f64>> = Vec::new();
        let mut n_tot = 0;
        for &run in runs {
            let pr = &self.runs[run];
            let len = self.records[run].len();
            if len <= self.skip + 1 {
                continue;
            }
            for (ri, &r) in rows.iter().enumerate() {
                let w = self.weights[r];
                let (mf, df) = &freed[ri];
                let (bb, water) = self.block_target(run, r, mf, df, specs, &shapes, water, &ctx);
                let nb = bb.cols.len();
                let y = Rc::clone(&bb.y);
                let mut idx: Vec<usize> = (base_index[ri]..base_index[ri] + nb).collect();
                let mut cols: Vec<Rc<Vec<f64>>> = bb.cols.clone();
                // Columns that depend on the data alone are kept with their
                // products (see `blocks::Column`).
                let mut keys: Vec<Option<Column>> = Column::base(run, w, mf, df);
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
                        for (q, (key, data)) in [
                            (Column::inertia(run, w, j), &pr.dlam_nu[j]),
                            (Column::damping(run, w, j), &pr.lam_nu[j]),
                        ]
                        .into_iter()
                        .enumerate()
                        {
                            idx.push(theta_index[si] + q);
                            cols.push(self.weighted_column(key, data, w));
                            keys.push(Some(key));
                        }
                        continue;
                    }
                    for pi in 0..nl {
                        let f = self.filtered_regressor(s.effect, pi, r, run, &ctx);
                        idx.push(theta_index[si] + pi);
                        let jac = water
                            .as_ref()
                            .filter(|_| s.effect == Effect::Current)
                            .and_then(|tw| tw.jacobian.as_ref());
                        let (col, key) = match jac {
                            Some(j) => {
                                let sum: Vec<f64> =
                                    f.iter().zip(&j[pi]).map(|(a, b)| a + b).collect();
                                (Rc::new(weighted(&sum[self.skip..], w)), None)
                            }
                            None if depends_on_data_alone(s.effect) => {
                                let key = Column::term(s.effect, pi, r, run, w);
                                (self.weighted_column(key, &f, w), Some(key))
                            }
                            None => (Rc::new(weighted(&f[self.skip..], w)), None),
                        };
                        cols.push(col);
                        keys.push(key);
                    }
                }
                if let Some(li) = load_index[ri] {
                    idx.push(li);
                    let key = Column::load(run, w);
                    cols.push(self.weighted_column(key, &pr.lam_one, w));
                    keys.push(Some(key));
                }
                // The baseline block's products (with each other and with
                // the target) come from its cache, products of two kept
                // columns from theirs; the rest are computed here.
                let mut block_targets = Vec::with_capacity(idx.len());
                for a in 0..idx.len() {
                    let from = a.max(nb);
                    let known: Vec<Option<f64>> = (from..idx.len())
                        .map(|b| self.kept_product(keys[a], keys[b]))
                        .collect();
                    let with_target = a >= nb;
                    let ys: Vec<&[f64]> = with_target
                        .then_some(y.as_slice())
                        .into_iter()
                        .chain(
                            cols[from..]
                                .iter()
                                .zip(&known)
                                .filter(|(_, k)| k.is_none())
                                .map(|(c, _)| c.as_slice()),
                        )
                        .collect();
                    let mut out = vec![0.0; ys.len()];
                    crate::kernels::dots(&cols[a], &ys, &mut out);
                    let (target, mut fresh) = if with_target {
                        (out[0], out[1..].iter())
                    } else {
                        (bb.by[a], out.iter())
                    };
                    block_targets.push(target);
                    let prods: Vec<f64> = known
                        .iter()
                        .zip(from..)
                        .map(|(k, b)| {
                            k.unwrap_or_else(|| {
                                let v = *fresh.next().expect("one product per unknown");
                                self.keep_product(keys[a], keys[b], v);
                                v
                            })
                        })
                        .collect();
                    for b in a..idx.len() {
                        let v = if b < nb {
                            bb.gram[a * nb + b]
                        } else {
                            prods[b - from]
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
                block_runs.push(run);
                targets.push(block_targets);
            }
        }
        if n_tot <= p {
            return None;
        }
        Some(Normal {
            rows,
            freed,
            base_index,
            theta_index,
            load_index,
            hmat,
            blocks,
            block_rows,
            block_runs,
            targets,
            n_tot,
            m_ref: m_ref.clone(),
            d_ref: d_ref.clone(),
            water,
        })
    }

    /// The fit of θ (all parameters) on `normal`: with `h_inv` (H⁻¹ and
    /// whether the HAC covariance is wanted) its residuals too; without,
    /// θ alone (`sse` NaN, no residuals).
    fn fit_out(
        &self,
        normal: &Normal,
        specs: &[Spec],
        theta_all: Vec<f64>,
        h_inv: Option<(&DMatrix<f64>, bool)>,
    ) -> FitOut {
        let Normal {
            rows,
            freed,
            base_index,
            theta_index,
            load_index,
            blocks,
            ..
        } = normal;
        let p = normal.hmat.nrows();
        let mut sse = if h_inv.is_some() { 0.0 } else { f64::NAN };
        let mut resid = Vec::with_capacity(blocks.len());
        for (idx, cols, y) in blocks.iter().filter(|_| h_inv.is_some()) {
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
        // scores h_k = C φ_k e_k, which costs t² instead of p² ([`hac`]).
        let t0 = theta_index.first().copied().unwrap_or(p);
        let cov = h_inv.filter(|(_, hac)| *hac).map(|(h_inv, _)| {
            let t = p - t0;
            let mut s = DMatrix::<f64>::zeros(t, t);
            for ((idx, cols, _), e) in blocks.iter().zip(&resid) {
                let len = e.len();
                let mut h = vec![vec![0.0; len]; t];
                for (a, &ia) in idx.iter().enumerate() {
                    for (ti, hv) in h.iter_mut().enumerate() {
                        let c = h_inv[(t0 + ti, ia)];
                        if c != 0.0 {
                            for ((hk, ck), ek) in hv.iter_mut().zip(&cols[a][..len]).zip(e) {
                                *hk += c * ck * ek;
                            }
                        }
                    }
                }
                hac::add_bartlett(&h, self.hac_lags, &mut s);
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
            .zip(theta_index)
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
        FitOut {
            rows: rows.clone(),
            base,
            theta,
            theta_index: theta_index.clone(),
            sse,
            n: normal.n_tot,
            cov,
            resid,
            block_rows: normal.block_rows.clone(),
            d_ref: normal.d_ref.clone(),
            m_ref: normal.m_ref.clone(),
            loads,
            held,
        }
    }
}

/// The (effect, shape) of every spec that has a shape.
fn shapes_of(specs: &[Spec]) -> Vec<(Effect, f64)> {
    specs
        .iter()
        .filter_map(|s| s.shape.map(|v| (s.effect, v)))
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
