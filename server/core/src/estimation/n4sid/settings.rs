//! Settings of the N4SID identification.

/// Weighting of the oblique projection O_i before its SVD, W₁ O_i W₂
/// (Van Overschee & De Moor 1996, Theorem 13 and Table 3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Weighting {
    /// N4SID proper: W₁ = I, W₂ = I.
    N4sid,
    /// MOESP: W₁ = I, W₂ = Π_{U_f}^⊥ (projection onto the orthogonal
    /// complement of the future inputs). The default: Γ_i does not depend
    /// on how the past inputs excite the states.
    #[default]
    Moesp,
    /// CVA: W₁ = (Y_f/U_f^⊥ (Y_f/U_f^⊥)ᵀ)^{-1/2}, W₂ = Π_{U_f}^⊥. The
    /// singular values are then canonical correlations (≤ 1).
    Cva,
}

/// What [`n4sid`](super::n4sid) estimates and how.
#[derive(Debug, Clone, PartialEq)]
pub struct N4sidSettings {
    /// Sample time h (s) of every experiment.
    pub h: f64,
    /// Number of block rows i of the past and of the future (U_p, U_f, Y_p,
    /// Y_f each have i block rows). Must exceed the order divided by the
    /// number of outputs; 10–30 is typical.
    pub horizon: usize,
    /// Model order n; `None` picks it from the largest gap of the logarithm
    /// of the singular values of W₁ O_i W₂ among orders 1..=`max_order`.
    pub order: Option<usize>,
    /// Largest order considered (and accepted when `order` is fixed).
    pub max_order: usize,
    /// Weighting of the oblique projection.
    pub weighting: Weighting,
    /// Estimate the direct feedthrough D; otherwise D = 0 (strictly proper,
    /// as for forces to velocities of a vessel).
    pub estimate_d: bool,
    /// Number of rows of the data matrix [U_f; U_p; Y_p; Y_f]ᵀ added to the
    /// triangular factor per QR update; `None` uses 8 × the row count
    /// 2i(m + l). Memory is (chunk + 2i(m + l)) · 2i(m + l) doubles.
    pub chunk_rows: Option<usize>,
}

impl N4sidSettings {
    /// Defaults for sample time `h`: horizon 10, order from the singular
    /// values up to 10, MOESP weighting, D = 0.
    pub fn new(h: f64) -> Self {
        N4sidSettings {
            h,
            horizon: 10,
            order: None,
            max_order: 10,
            weighting: Weighting::default(),
            estimate_d: false,
            chunk_rows: None,
        }
    }
}
