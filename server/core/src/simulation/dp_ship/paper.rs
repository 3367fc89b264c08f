//! The published numbers of Fossen, Sagatun & Sørensen (1995), "Identification
//! of dynamically positioned ships", sec. 4: the supply vessel (L = 76.2 m) in
//! the Bis system (lengths in L, time in √(L/g), forces in m·g).
//!
//! Read from the paper as printed; eq. 29 and 52 are 3 × 6 matrices typeset in
//! two halves of three columns each. T″ has cos α = 0, sin α = 1 (the bow
//! azimuth u6 at α = 90°).
//!
//! Consistency of the printed numbers (checked in the tests): M″⁻¹·T″·K″ from
//! eq. 29, 30, 49 reproduces eq. 52 to its four decimals except B″₂₅, B″₃₅,
//! B″₃₆ (0.0019, 0.0111, 0.0078 against 0.0020, 0.0113, 0.0079): K″₅ and K″₆
//! are printed with two digits, and eq. 52 matches K″₅ ≈ 2.848·10⁻³,
//! K″₆ ≈ 2.61·10⁻³, both within the rounding of eq. 49. Likewise
//! M″⁻¹·A″_h·M″ reproduces eq. 51 except A″₃₂ (−0.0046 against −0.0045):
//! that entry moves by ≈ 15× the rounding of A″_h,32.

/// Ship length L (m), Fig. 1: the Bis length unit.
pub const LENGTH_M: f64 = 76.2;

/// Acceleration of gravity (m/s²) of the Bis units.
pub const GRAVITY: f64 = 9.81;

/// Thruster configuration matrix T″ (eq. 29), rows surge, sway, yaw; columns
/// u1 port main, u2 starboard main, u3 aft tunnel I, u4 aft tunnel II, u5 bow
/// tunnel, u6 bow azimuth.
pub const T_CONFIG: [[f64; 6]; 3] = [
    [1.0000, 1.0000, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 1.0000, 1.0000, 1.0000, 1.0000],
    [0.0472, -0.0472, -0.4108, -0.3858, 0.4554, 0.3373],
];

/// Inertia matrix M″ including added mass (eq. 30).
pub const M_INERTIA: [[f64; 3]; 3] = [
    [1.1274, 0.0, 0.0],
    [0.0, 1.8902, -0.0744],
    [0.0, -0.0744, 0.1278],
];

/// Identified momentum-equation matrix A″_h = −D″·M″⁻¹ (eq. 48).
pub const A_H: [[f64; 3]; 3] = [
    [-0.0318, 0.0, 0.0],
    [0.0, -0.0602, 0.0618],
    [0.0, -0.0075, -0.2454],
];

/// Identified thrust coefficients K″ = diag{K″1, …, K″6} (eq. 49).
pub const K_THRUST: [f64; 6] = [9.3e-3, 9.3e-3, 2.0e-3, 2.0e-3, 2.8e-3, 2.6e-3];

/// Identified θ″1 … θ″9 (eq. 46–49): A″_h entries (1,1), (2,2), (2,3), (3,2),
/// (3,3), then K″1 = K″2, K″3 = K″4, K″5, K″6.
pub const THETA: [f64; 9] = [
    -0.0318, -0.0602, 0.0618, -0.0075, -0.2454, 9.3e-3, 2.0e-3, 2.8e-3, 2.6e-3,
];

/// State-space A″ = M″⁻¹·A″_h·M″ as printed (eq. 51).
pub const A_STATE_SPACE: [[f64; 3]; 3] = [
    [-0.0318, 0.0, 0.0],
    [0.0, -0.0628, -0.0030],
    [0.0, -0.0045, -0.2428],
];

/// State-space B″ = M″⁻¹·T″·K″ as printed (eq. 52).
pub const B_STATE_SPACE: [[f64; 6]; 3] = [
    [0.0082, 0.0082, 0.0, 0.0, 0.0, 0.0],
    [0.0001, -0.0001, 0.0008, 0.0008, 0.0020, 0.0017],
    [0.0035, -0.0035, -0.0059, -0.0055, 0.0113, 0.0079],
];

/// Sample time of the sea trials in Bis time, h″ = 1 s / √(L/g).
///
/// The paper plots 600 samples per run (Fig. 5–8) and gives no rate; 1 Hz is
/// what the figures imply: ≈ 1400 m travelled at ≤ 4 m/s in Fig. 5, and a
/// 180° turn at ≤ 1°/s in Fig. 7, both over 600 samples.
pub fn sample_time_bis() -> f64 {
    1.0 / bis_time_unit_s()
}

/// The Bis time unit √(L/g) in seconds (≈ 2.787 s).
pub fn bis_time_unit_s() -> f64 {
    (LENGTH_M / GRAVITY).sqrt()
}

/// Samples per manoeuvre in Fig. 5–8.
pub const SAMPLES_PER_RUN: usize = 600;
