//! Physical plausibility of an identified M ν̇ + D̄ ν = γ (thesis eq. 2.9):
//! M (rigid body + added mass) should be symmetric positive definite
//! (Fossen 2011, property 6.1) and D̄ = C + D dissipative, i.e. its symmetric
//! part positive semi-definite so that νᵀD̄ν ≥ 0 and the unforced vessel
//! cannot gain kinetic energy. D̄ need not be symmetric: at speed it carries
//! the skew-symmetric C(ν), which does no work.

use nalgebra::DMatrix;

use crate::planning::dof::Dof;

/// What [`check_structure`] found. `violations` are the findings that make
/// the model unphysical, each a sentence for a control engineer; `notes` are
/// observations that are expected for some models (e.g. an asymmetric D̄).
#[derive(Debug, Clone, PartialEq)]
pub struct StructureReport {
    /// ‖M − Mᵀ‖_F / ‖M‖_F (0 for symmetric M).
    pub m_asymmetry: f64,
    /// `m_asymmetry` ≤ tolerance.
    pub m_symmetric: bool,
    /// Cholesky factorization of the symmetric part ½(M + Mᵀ) exists.
    pub m_positive_definite: bool,
    /// Smallest eigenvalue of ½(M + Mᵀ).
    pub m_min_eigenvalue: f64,
    /// ‖D̄ − D̄ᵀ‖_F / ‖D̄‖_F.
    pub d_asymmetry: f64,
    /// Smallest eigenvalue of ½(D̄ + D̄ᵀ).
    pub d_min_eigenvalue: f64,
    /// `d_min_eigenvalue` ≥ −tolerance · (largest |eigenvalue|).
    pub d_dissipative: bool,
    /// Findings that make the model unphysical.
    pub violations: Vec<String>,
    /// Findings worth knowing that are not violations.
    pub notes: Vec<String>,
}

impl StructureReport {
    /// No violations: M symmetric positive definite and D̄ dissipative.
    pub fn is_physical(&self) -> bool {
        self.violations.is_empty()
    }
}

fn sym(a: &DMatrix<f64>) -> DMatrix<f64> {
    (a + a.transpose()) * 0.5
}

fn asymmetry(a: &DMatrix<f64>) -> f64 {
    let norm = a.norm();
    if norm == 0.0 {
        0.0
    } else {
        (a - a.transpose()).norm() / norm
    }
}

/// The entry pair (i, j), i < j, with the largest |a_ij − a_ji|.
fn worst_pair(a: &DMatrix<f64>) -> (usize, usize) {
    let n = a.nrows();
    let mut best = (0, 0, -1.0);
    for i in 0..n {
        for j in i + 1..n {
            let d = (a[(i, j)] - a[(j, i)]).abs();
            if d > best.2 {
                best = (i, j, d);
            }
        }
    }
    (best.0, best.1)
}

fn min_eigenvalue(s: &DMatrix<f64>) -> (f64, f64) {
    let ev = s.clone().symmetric_eigenvalues();
    (ev.min(), ev.amax())
}

/// Checks M and D̄ of a model over `dofs` (validated by the caller: square,
/// same size as `dofs`, finite; `tol` finite and ≥ 0).
pub(crate) fn check_structure(
    dofs: &[Dof],
    m: &DMatrix<f64>,
    d_bar: &DMatrix<f64>,
    tol: f64,
) -> StructureReport {
    let name = |i: usize| dofs[i].name();
    let mut violations = Vec::new();
    let mut notes = Vec::new();

    let m_asymmetry = asymmetry(m);
    let m_symmetric = m_asymmetry <= tol;
    if !m_symmetric {
        let (i, j) = worst_pair(m);
        violations.push(format!(
            "M is not symmetric: ‖M − Mᵀ‖/‖M‖ = {m_asymmetry:.3} exceeds the tolerance {tol:e}; \
             the largest mismatch is M[{a},{b}] = {:.4e} against M[{b},{a}] = {:.4e}. The inertia \
             matrix of rigid body plus added mass is symmetric at low speed (Fossen 2011, \
             property 6.1), so the estimate has absorbed effects that belong elsewhere.",
            m[(i, j)],
            m[(j, i)],
            a = name(i),
            b = name(j),
        ));
    }
    let m_sym = sym(m);
    let m_positive_definite = m_sym.clone().cholesky().is_some();
    let (m_min_eigenvalue, m_max_abs) = min_eigenvalue(&m_sym);
    if !m_positive_definite {
        let bad: Vec<String> = (0..m.nrows())
            .filter(|&i| m[(i, i)] <= 0.0)
            .map(|i| format!("M[{0},{0}] = {1:.4e}", name(i), m[(i, i)]))
            .collect();
        let diag = if bad.is_empty() {
            String::from("all diagonal entries are positive, so the coupling terms are too large")
        } else {
            format!("non-positive diagonal entries: {}", bad.join(", "))
        };
        violations.push(format!(
            "M is not positive definite: the smallest eigenvalue of its symmetric part is \
             {m_min_eigenvalue:.4e} (largest magnitude {m_max_abs:.4e}); {diag}. A vessel with \
             such an inertia accelerates against the applied force in some direction."
        ));
    }

    let d_asymmetry = asymmetry(d_bar);
    let (d_min_eigenvalue, d_max_abs) = min_eigenvalue(&sym(d_bar));
    let d_dissipative = d_min_eigenvalue >= -tol * d_max_abs;
    if !d_dissipative {
        let bad: Vec<String> = (0..d_bar.nrows())
            .filter(|&i| d_bar[(i, i)] < 0.0)
            .map(|i| format!("D̄[{0},{0}] = {1:.4e}", name(i), d_bar[(i, i)]))
            .collect();
        let diag = if bad.is_empty() {
            String::from("every diagonal entry is non-negative, so the couplings are too large")
        } else {
            format!("negative diagonal entries: {}", bad.join(", "))
        };
        violations.push(format!(
            "D̄ is not dissipative: the symmetric part ½(D̄ + D̄ᵀ) has the eigenvalue \
             {d_min_eigenvalue:.4e} < 0, so νᵀD̄ν < 0 for some ν and the unforced model gains \
             kinetic energy; {diag}."
        ));
    }
    if d_asymmetry > tol {
        let (i, j) = worst_pair(d_bar);
        notes.push(format!(
            "D̄ is asymmetric (‖D̄ − D̄ᵀ‖/‖D̄‖ = {d_asymmetry:.3}; largest mismatch \
             D̄[{a},{b}] = {:.4e} against D̄[{b},{a}] = {:.4e}). Expected at speed: D̄ also \
             carries the skew-symmetric Coriolis term C(ν), which does no work.",
            d_bar[(i, j)],
            d_bar[(j, i)],
            a = name(i),
            b = name(j),
        ));
    }

    StructureReport {
        m_asymmetry,
        m_symmetric,
        m_positive_definite,
        m_min_eigenvalue,
        d_asymmetry,
        d_min_eigenvalue,
        d_dissipative,
        violations,
        notes,
    }
}
