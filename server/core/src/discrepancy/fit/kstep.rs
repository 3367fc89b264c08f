//! k-step predictions of a fitted row on the records, the error the shape
//! profiles and the refit choice minimise.

use super::*;
use crate::discrepancy::candidates::Trig;

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
            let trig = terms
                .iter()
                .any(|(e, _)| e.reads_attitude())
                .then(|| self.stage_trig(run));
            // `stage` 0, 1, 2: the start, middle and end of interval k0.
            let mut force = |k0: usize, stage: usize, nu_r: f64, tau_a: f64| -> f64 {
                let frac = STAGE_FRACTIONS[stage];
                let k1 = (k0 + 1).min(len - 1);
                let mut fr = tau_a + ext[k0] + frac * (ext[k1] - ext[k0]) - d_rr * nu_r;
                if !terms.is_empty() {
                    for (j, v) in nu_buf.iter_mut().enumerate() {
                        *v = rec.nu[(k0, j)] + frac * (rec.nu[(k1, j)] - rec.nu[(k0, j)]);
                    }
                    nu_buf[r] = nu_r;
                    let eta = stage_eta(rec, k0, frac);
                    let t = trig.as_ref().map(|t| &t[k0][stage]);
                    for (e, th) in &terms {
                        for (p, c) in th.iter().enumerate() {
                            fr -= c * e.regressor_at(p, r, &ctx, &nu_buf, &eta, t);
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
                    let k1x = force(step, 0, x, tau(a));
                    let k1a = da(a);
                    let k2x = force(step, 1, x + 0.5 * h * k1x, tau(a + 0.5 * h * k1a));
                    let k2a = da(a + 0.5 * h * k1a);
                    let k3x = force(step, 1, x + 0.5 * h * k2x, tau(a + 0.5 * h * k2a));
                    let k3a = da(a + 0.5 * h * k2a);
                    let k4x = force(step, 2, x + h * k3x, tau(a + h * k3a));
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

/// Where in a sample interval RK4 evaluates the force: start, middle, end.
const STAGE_FRACTIONS: [f64; 3] = [0.0, 0.5, 1.0];

/// η at fraction `frac` of interval `k0` of `rec`, linear between samples.
fn stage_eta(rec: &Record, k0: usize, frac: f64) -> [f64; 6] {
    let k1 = (k0 + 1).min(rec.len() - 1);
    std::array::from_fn(|j| rec.eta[(k0, j)] + frac * (rec.eta[(k1, j)] - rec.eta[(k0, j)]))
}

impl Prepared<'_> {
    /// [`Trig`] of η at the RK4 stages of every interval of `run`
    /// ([`STAGE_FRACTIONS`]; the first at the sample itself), computed once
    /// per run and kept: the k-step predictions of the profiles visit every
    /// stage many times, and every fit with a current reads the heading's.
    pub(super) fn stage_trig(&self, run: usize) -> Rc<Vec<[Trig; 3]>> {
        if let Some(t) = self.stage_trig.borrow().get(&run) {
            return Rc::clone(t);
        }
        let rec = &self.records[run];
        let table: Rc<Vec<[Trig; 3]>> = Rc::new(
            (0..rec.len())
                .map(|k0| {
                    [
                        Trig::of(&rec.eta_at(k0)),
                        Trig::of(&stage_eta(rec, k0, STAGE_FRACTIONS[1])),
                        Trig::of(&stage_eta(rec, k0, STAGE_FRACTIONS[2])),
                    ]
                })
                .collect(),
        );
        self.stage_trig.borrow_mut().insert(run, Rc::clone(&table));
        table
    }
}
