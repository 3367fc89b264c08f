//! The filtered regressors of the library's terms, kept per run where they
//! do not depend on the model being fitted, and the size of a term's force.

use super::*;
use crate::models::coriolis::coriolis_force6;

impl Prepared<'_> {
    /// [λφ_p,r] of term `effect`, coefficient `pi`, row `r` on run `run`.
    /// Regressors that do not depend on the model's M and D̄ (all but C(ν)ν
    /// from M and the current) are computed once per run and kept: the
    /// search fits each hypothesis many times (folds, shape profiles).
    pub(super) fn filtered_regressor(
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
            let forces = self.coriolis_forces(run, ctx);
            let i = ctx.dofs[r].index();
            let raw: Vec<f64> = forces.iter().map(|f| f[i]).collect();
            return Rc::new(self.svf.foh(&raw));
        }
        let key = (effect, pi, r, run);
        if let Some(f) = self.regressors.borrow().get(&key) {
            return Rc::clone(f);
        }
        let f = compute();
        self.regressors.borrow_mut().insert(key, Rc::clone(&f));
        f
    }

    /// C(ν)ν from `ctx`'s M at every sample of `run` (six DOFs' order):
    /// kept for the last M per run, since a fit reads it once per row.
    fn coriolis_forces(&self, run: usize, ctx: &TermContext<'_>) -> Rc<Vec<[f64; 6]>> {
        let key: Vec<u64> = ctx.m_ref.iter().map(|x| x.to_bits()).collect();
        if let Some((k, f)) = self.coriolis.borrow().get(&run)
            && *k == key
        {
            return Rc::clone(f);
        }
        let rec = &self.records[run];
        let mut nu = vec![0.0; rec.nu.ncols()];
        let forces: Rc<Vec<[f64; 6]>> = Rc::new(
            (0..rec.len())
                .map(|k| {
                    for (j, v) in nu.iter_mut().enumerate() {
                        *v = rec.nu[(k, j)];
                    }
                    coriolis_force6(ctx.dofs, ctx.m_ref, &nu)
                })
                .collect(),
        );
        self.coriolis
            .borrow_mut()
            .insert(run, (key, Rc::clone(&forces)));
        forces
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
}

/// Whether a term's regressor depends on the data alone, not on the M and
/// D̄ being fitted (all but C(ν)ν from M and the current): such regressors,
/// their weighted columns and their products are kept.
pub(super) fn depends_on_data_alone(effect: Effect) -> bool {
    !matches!(effect, Effect::Current | Effect::CoriolisFromM)
}
