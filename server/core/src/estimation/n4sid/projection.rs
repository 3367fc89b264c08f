//! Oblique projection, weighting, SVD and order: from L to Γ_i and the
//! state map.
//!
//! With H = L Qᵀ and the blocks of L by rows [U_f; W_p; Y_f] (W_p = [U_p;
//! Y_p]) and columns (a = m i, b = (m + l) i):
//!
//! ```text
//!   U_f = L11 Q1ᵀ
//!   W_p = L21 Q1ᵀ + L22 Q2ᵀ
//!   Y_f = L31 Q1ᵀ + L32 Q2ᵀ + L33 Q3ᵀ
//! ```
//!
//! the oblique projection of Y_f along U_f onto W_p is
//! O_i = Y_f /_{U_f} W_p = L32 L22^† W_p (Van Overschee & De Moor 1996,
//! eq. 4.26 in LQ form; L22^† handles the rank-deficient noise-free case).
//! Its SVD after weighting, W₁ O_i W₂ = U S Vᵀ, gives Γ_i = W₁⁻¹ U₁ S₁^{1/2}
//! and the Kalman-filter states X̂_i = Γ_i^† O_i = M W_p: the state map
//! M = Γ_i^† L32 L22^† acts on any past window, which is what the
//! least-squares step uses for X̂_i and X̂_{i+1}.

use faer::MatRef;
use nalgebra::DMatrix;

use super::error::N4sidError;
use super::hankel::HankelLq;
use super::settings::Weighting;

/// Relative singular-value floor of the pseudo-inverses of L22 and of the
/// CVA factor: below it a direction is taken as exactly dependent (the
/// noise-free Y_p, which is U_p and n states). Far above the ε·‖H‖ rounding
/// of the QR, far below any noise actually present in data.
const RANK_TOL: f64 = 1e-11;

/// The result of the subspace step.
#[derive(Debug, Clone)]
pub(crate) struct Subspace {
    /// All singular values of W₁ O_i W₂, descending.
    pub singular_values: Vec<f64>,
    /// Chosen order n.
    pub order: usize,
    /// Extended observability matrix Γ_i (l i × n).
    pub gamma: DMatrix<f64>,
    /// State map M (n × b): x̂ = M w_p for the past window w_p = [U_p; Y_p].
    pub state_map: DMatrix<f64>,
}

/// Pseudo-inverse with a relative singular-value floor.
pub(crate) fn pinv(a: &DMatrix<f64>, rel_tol: f64) -> Result<DMatrix<f64>, N4sidError> {
    if a.is_empty() {
        return Ok(DMatrix::zeros(a.ncols(), a.nrows()));
    }
    let svd = a.clone().svd(true, true);
    let smax = svd.singular_values.max();
    svd.pseudo_inverse(smax * rel_tol)
        .map_err(|_| N4sidError::Numerical {
            step: "pseudo-inverse",
        })
}

/// Thin SVD by faer (no copy in: column-major slice); returns U and S.
fn thin_svd(a: &DMatrix<f64>) -> Result<(DMatrix<f64>, Vec<f64>), N4sidError> {
    let view = MatRef::from_column_major_slice(a.as_slice(), a.nrows(), a.ncols());
    let svd = view.thin_svd().map_err(|_| N4sidError::Numerical {
        step: "SVD of W1 O_i W2",
    })?;
    let u = svd.U();
    let s = svd.S().column_vector();
    let k = s.nrows();
    Ok((
        DMatrix::from_fn(a.nrows(), k, |r, c| u[(r, c)]),
        (0..k).map(|c| s[c]).collect(),
    ))
}

/// Relative floor of the singular values in the order choice: below it a
/// value is rounding (the QR keeps ε·‖H‖), so exact zeros make no gap.
const SV_FLOOR: f64 = 1e-12;

/// Order from the singular values: the last "significant" gap among
/// 1..=max, i.e. the largest k whose log gap ln(s_k / s_{k+1}) is at least
/// half the largest one. The plain largest gap stops at a dominant mode
/// pair when the system's own singular values spread over decades above the
/// noise floor; the noise floor itself is flat, with small gaps.
pub(crate) fn order_from_gap(s: &[f64], max: usize) -> usize {
    let floor = s.first().copied().unwrap_or(0.0) * SV_FLOOR + f64::MIN_POSITIVE;
    let ln = |v: f64| v.max(floor).ln();
    let top = max.min(s.len().saturating_sub(1));
    let gaps: Vec<f64> = (1..=top).map(|k| ln(s[k - 1]) - ln(s[k])).collect();
    let largest = gaps.iter().copied().fold(0.0, f64::max);
    if largest <= 0.0 {
        return max.min(s.len()).max(1);
    }
    gaps.iter()
        .rposition(|&g| g >= 0.5 * largest)
        .map_or(1, |k| k + 1)
}

/// Coefficient P of an oblique projection O = P W along the rows of the
/// leading `a` rows of `l` onto the next `b` rows, for the `f` rows after
/// them (O = L32 L22^† W, Van Overschee & De Moor eq. 4.26 in LQ form).
fn oblique_coefficient(
    l: &DMatrix<f64>,
    a: usize,
    b: usize,
    f: usize,
) -> Result<DMatrix<f64>, N4sidError> {
    let l22 = l.view((a, a), (b, b)).into_owned();
    Ok(l.view((a + b, a), (f, b)) * pinv(&l22, RANK_TOL)?)
}

/// State map M⁺ of the next step: X̂_{i+1} = Γ_{i−1}^† O_{i+1} = M⁺ W_p⁺ with
/// O_{i+1} = Y_f⁻ /_{U_f⁻} W_p⁺ (W_p⁺ = [U_{0|i}; Y_{0|i}], U_f⁻ =
/// U_{i+1|2i−1}, Y_f⁻ = Y_{i+1|2i−1}; Van Overschee & De Moor 1996,
/// sec. 4.3.1). The rows of H are regrouped [U_f⁻; W_p⁺; Y_f⁻] and
/// re-triangularized (r × r QR), then the same LQ formula applies.
pub(crate) fn next_state_map(
    lq: &HankelLq,
    sub: &Subspace,
) -> Result<(DMatrix<f64>, Vec<usize>), N4sidError> {
    let lay = lq.layout;
    let (m, l, i) = (lay.m, lay.l, lay.i);
    let uf: Vec<usize> = (i + 1..2 * i)
        .flat_map(|k| (0..m).map(move |c| lay.u_row(k, c)))
        .collect();
    let wp: Vec<usize> = (0..=i)
        .flat_map(|k| (0..m).map(move |c| lay.u_row(k, c)))
        .chain((0..=i).flat_map(|k| (0..l).map(move |c| lay.y_row(k, c))))
        .collect();
    let yf: Vec<usize> = (i + 1..2 * i)
        .flat_map(|k| (0..l).map(move |c| lay.y_row(k, c)))
        .collect();
    let order: Vec<usize> = uf.iter().chain(&wp).chain(&yf).copied().collect();
    let z = DMatrix::from_fn(order.len(), lq.l.ncols(), |r, c| lq.l[(order[r], c)]);
    let l2 = z.transpose().qr().r().transpose();
    let p = oblique_coefficient(&l2, uf.len(), wp.len(), yf.len())?;
    let gamma_minus = sub.gamma.rows(0, l * (i - 1)).into_owned();
    Ok((pinv(&gamma_minus, 1e-14)? * p, wp))
}

/// Oblique projection, weighting, SVD and order.
pub(crate) fn subspace(
    lq: &HankelLq,
    weighting: Weighting,
    order: Option<usize>,
    max_order: usize,
) -> Result<Subspace, N4sidError> {
    let lay = lq.layout;
    let (a, b, f) = (lay.mi(), lay.mi() + lay.li(), lay.li());
    let l = &lq.l;
    let l21 = l.view((a, 0), (b, a));
    let l22 = l.view((a, a), (b, b)).into_owned();
    // O_i = P W_p with P = L32 L22^†.
    let p = oblique_coefficient(l, a, b, f)?;
    // W₁ (as a factor F with W₁ = F^†) for CVA: F Fᵀ = Y_f Π⊥ Y_fᵀ.
    let cva_factor = match weighting {
        Weighting::Cva => {
            let yf_perp = l.view((a + b, a), (f, b + f)).transpose();
            let r = yf_perp.qr().r();
            Some(r.transpose())
        }
        _ => None,
    };
    let weighted = match weighting {
        // W₂ = I: O_i's coordinates on [Q1 Q2] are P [L21 L22].
        Weighting::N4sid => {
            let mut o = DMatrix::zeros(f, a + b);
            o.view_mut((0, 0), (f, a)).copy_from(&(&p * l21));
            o.view_mut((0, a), (f, b)).copy_from(&(&p * &l22));
            o
        }
        // W₂ = Π_{U_f}^⊥ drops the Q1 coordinates.
        Weighting::Moesp => &p * &l22,
        Weighting::Cva => match &cva_factor {
            Some(fac) => pinv(fac, RANK_TOL)? * &p * &l22,
            None => return Err(N4sidError::Numerical { step: "CVA weight" }),
        },
    };
    let (u, s) = thin_svd(&weighted)?;
    // Γ_{i−1} (l(i−1) rows) must keep full column rank for X̂_{i+1}.
    let rank_bound = s.len().min(f - lay.l);
    let max = max_order.min(rank_bound);
    let n = match order {
        Some(n) => {
            if n == 0 || n > max {
                return Err(N4sidError::OrderTooLarge {
                    field: "order",
                    order: n,
                    max,
                });
            }
            n
        }
        None => {
            if max == 0 {
                return Err(N4sidError::Setting {
                    field: "max_order",
                    reason: "must be at least 1".into(),
                });
            }
            order_from_gap(&s, max)
        }
    };
    // Γ_i = W₁⁻¹ U₁ S₁^{1/2}.
    let mut gamma = u.columns(0, n).into_owned();
    for (c, sv) in s.iter().take(n).enumerate() {
        gamma.column_mut(c).scale_mut(sv.sqrt());
    }
    if let Some(fac) = &cva_factor {
        gamma = fac * gamma;
    }
    let state_map = pinv(&gamma, 1e-14)? * &p;
    Ok(Subspace {
        singular_values: s,
        order: n,
        gamma,
        state_map,
    })
}
