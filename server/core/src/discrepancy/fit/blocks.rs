//! The baseline part of the regression blocks: every hypothesis that
//! frees the same M and D̄ entries of a row shares its weighted columns,
//! their Gram matrix and the target, computed once per (run, row).

use super::*;

/// Baseline blocks by (run, row, weight's bits, free M columns, free D̄
/// columns), with the logged τ's target.
pub(super) type BaseCache =
    RefCell<HashMap<(usize, usize, u64, Vec<usize>, Vec<usize>), Rc<BaseBlock>>>;

/// The baseline part of one (row, run) block: the weighted target with
/// the held entries' forces taken out, the weighted columns of the freed
/// M and D̄ entries (M's first), their Gram matrix (row-major), their
/// products with the target, and the held entries' forces.
#[derive(Clone)]
pub(super) struct BaseBlock {
    pub y: Rc<Vec<f64>>,
    pub cols: Vec<Rc<Vec<f64>>>,
    pub gram: Rc<Vec<f64>>,
    pub by: Vec<f64>,
    pub held: Rc<Vec<f64>>,
}

impl Prepared<'_> {
    /// The baseline block of row `r` on `run` with row weight `w`, freeing
    /// the M columns `mf` and D̄ columns `df`, with the target of the
    /// logged τ (computed once and kept), or, when actuator hypotheses
    /// reshape the applied force, of its filtered `lam_tau_a` (the kept
    /// columns and Gram matrix with a target of its own).
    pub(super) fn base_block(
        &self,
        run: usize,
        r: usize,
        w: f64,
        mf: &[usize],
        df: &[usize],
        lam_tau_a: Option<Vec<f64>>,
    ) -> BaseBlock {
        let key = (run, r, w.to_bits(), mf.to_vec(), df.to_vec());
        let kept = self.base_blocks.borrow().get(&key).cloned();
        let kept = kept.unwrap_or_else(|| {
            let block = Rc::new(self.new_base_block(run, r, w, mf, df));
            self.base_blocks.borrow_mut().insert(key, Rc::clone(&block));
            block
        });
        match lam_tau_a {
            None => BaseBlock::clone(&kept),
            Some(lam_tau_a) => {
                let y = self.target(run, r, w, &lam_tau_a, &kept.held);
                let by = products(&y, &kept.cols);
                BaseBlock {
                    y: Rc::new(y),
                    by,
                    ..BaseBlock::clone(&kept)
                }
            }
        }
    }

    /// The weighted target w·([λτ_a] − [λg] − held) of row `r` on `run`
    /// from sample `skip` on.
    fn target(&self, run: usize, r: usize, w: f64, lam_tau_a: &[f64], held: &[f64]) -> Vec<f64> {
        let lam_g = &self.runs[run].lam_g[r];
        (self.skip..self.records[run].len())
            .zip(held)
            .map(|(k, h)| w * (lam_tau_a[k] - lam_g[k] - h))
            .collect()
    }

    /// [`Self::base_block`] computed, with the logged τ's target.
    fn new_base_block(
        &self,
        run: usize,
        r: usize,
        w: f64,
        mf: &[usize],
        df: &[usize],
    ) -> BaseBlock {
        let pr = &self.runs[run];
        let len = self.records[run].len();
        // Forces of the entries held at the baseline's values.
        let (m, d) = (&self.baseline.m, &self.baseline.d_bar);
        let mut held = vec![0.0; len - self.skip];
        for j in 0..self.baseline.dofs.len() {
            let mh = if mf.contains(&j) { 0.0 } else { m[(r, j)] };
            let dh = if df.contains(&j) { 0.0 } else { d[(r, j)] };
            let (dl, l) = (&pr.dlam_nu[j][self.skip..], &pr.lam_nu[j][self.skip..]);
            for ((hk, a), b) in held.iter_mut().zip(dl).zip(l) {
                *hk += mh * a + dh * b;
            }
        }
        let y = self.target(run, r, w, &pr.lam_tau[r], &held);
        let cols: Vec<Rc<Vec<f64>>> = mf
            .iter()
            .map(|&j| &pr.dlam_nu[j])
            .chain(df.iter().map(|&j| &pr.lam_nu[j]))
            .map(|c| Rc::new(weighted(&c[self.skip..], w)))
            .collect();
        let nb = cols.len();
        let mut gram = vec![0.0; nb * nb];
        let mut out = vec![0.0; nb];
        for a in 0..nb {
            let ys: Vec<&[f64]> = cols[a..].iter().map(|c| c.as_slice()).collect();
            let out = &mut out[..ys.len()];
            out.fill(0.0);
            crate::kernels::dots(&cols[a], &ys, out);
            for b in a..nb {
                gram[a * nb + b] = out[b - a];
                gram[b * nb + a] = out[b - a];
            }
        }
        let by = products(&y, &cols);
        BaseBlock {
            y: Rc::new(y),
            cols,
            gram: Rc::new(gram),
            by,
            held: Rc::new(held),
        }
    }
}

/// `cᵀy` for every column c.
pub(super) fn products(y: &[f64], cols: &[Rc<Vec<f64>>]) -> Vec<f64> {
    let ys: Vec<&[f64]> = cols.iter().map(|c| c.as_slice()).collect();
    let mut out = vec![0.0; ys.len()];
    crate::kernels::dots(y, &ys, &mut out);
    out
}

/// `w·x` element-wise.
pub(super) fn weighted(x: &[f64], w: f64) -> Vec<f64> {
    x.iter().map(|v| w * v).collect()
}

/// Σ a·b over the shorter length, in eight partial sums (vectorised).
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let mut out = [0.0];
    crate::kernels::dots(&a[..n], &[&b[..n]], &mut out);
    out[0]
}
