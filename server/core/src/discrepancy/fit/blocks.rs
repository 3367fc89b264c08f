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

/// A weighted regression column that depends on the data alone: its
/// identity, under which it and its products with other such columns are
/// kept (a product of two columns is the same in every fit that has both).
/// Weights by their bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Column {
    /// w·[sλν_j] of a run (an M entry).
    Inertia { run: usize, w: u64, j: usize },
    /// w·[λν_j] of a run (a D̄ entry).
    Damping { run: usize, w: u64, j: usize },
    /// w·[λφ_p,r] of a term whose regressor is data alone.
    Term {
        effect: Effect,
        pi: usize,
        r: usize,
        run: usize,
        w: u64,
    },
    /// w·[λ1] (a constant load).
    Load { run: usize, w: u64 },
}

impl Column {
    /// The columns of a baseline block freeing M columns `mf` and D̄
    /// columns `df` (M's first, as [`BaseBlock::cols`]).
    pub fn base(run: usize, w: f64, mf: &[usize], df: &[usize]) -> Vec<Option<Column>> {
        mf.iter()
            .map(|&j| Some(Column::inertia(run, w, j)))
            .chain(df.iter().map(|&j| Some(Column::damping(run, w, j))))
            .collect()
    }

    pub fn inertia(run: usize, w: f64, j: usize) -> Column {
        Column::Inertia {
            run,
            w: w.to_bits(),
            j,
        }
    }

    pub fn damping(run: usize, w: f64, j: usize) -> Column {
        Column::Damping {
            run,
            w: w.to_bits(),
            j,
        }
    }

    pub fn term(effect: Effect, pi: usize, r: usize, run: usize, w: f64) -> Column {
        Column::Term {
            effect,
            pi,
            r,
            run,
            w: w.to_bits(),
        }
    }

    pub fn load(run: usize, w: f64) -> Column {
        Column::Load {
            run,
            w: w.to_bits(),
        }
    }
}

/// Kept weighted columns, and the products of pairs of them.
#[derive(Default)]
pub(super) struct ColumnCache {
    columns: RefCell<HashMap<Column, Rc<Vec<f64>>>>,
    products: RefCell<HashMap<(Column, Column), f64>>,
}

impl Prepared<'_> {
    /// w·`data` from sample `skip` on, kept under `key`.
    pub(super) fn weighted_column(&self, key: Column, data: &[f64], w: f64) -> Rc<Vec<f64>> {
        let cache = &self.columns.columns;
        if let Some(c) = cache.borrow().get(&key) {
            return Rc::clone(c);
        }
        let c = Rc::new(weighted(&data[self.skip..], w));
        cache.borrow_mut().insert(key, Rc::clone(&c));
        c
    }

    /// The kept product of two kept columns (either order: each product
    /// is the same sum bit for bit).
    pub(super) fn kept_product(&self, a: Option<Column>, b: Option<Column>) -> Option<f64> {
        let (a, b) = (a?, b?);
        let products = self.columns.products.borrow();
        products
            .get(&(a, b))
            .or_else(|| products.get(&(b, a)))
            .copied()
    }

    /// Keeps the product of two columns when both are kept ones.
    pub(super) fn keep_product(&self, a: Option<Column>, b: Option<Column>, v: f64) {
        if let (Some(a), Some(b)) = (a, b) {
            self.columns.products.borrow_mut().insert((a, b), v);
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
