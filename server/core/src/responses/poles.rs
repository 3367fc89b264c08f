//! Poles and per-channel zeros. The poles are the eigenvalues of A; the
//! zeros are those of each single input → output transfer function
//! g(s) = c (sI − A)⁻¹ b + d (per-channel SISO zeros, not the MIMO
//! transmission zeros): with d ≠ 0 the eigenvalues of A − b c / d, with
//! d = 0 the roots of det(sI − A + b c) − det(sI − A) = c adj(sI − A) b
//! (the matrix determinant lemma).

use nalgebra::Complex;
use serde::Serialize;

use super::polynomial::{characteristic, roots};
use super::{LinearModel, LinearModels};

/// Below this share of the largest coefficient a polynomial coefficient is
/// rounding (the cancelled leading terms of the zero polynomial).
const COEFF_REL_TOL: f64 = 1e-9;

/// |Re s| (s⁻¹) at or below which a root lies on the imaginary axis.
const AXIS_TOL: f64 = 1e-9;

/// A pole or zero with what it means in time.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PlaneRoot {
    /// Real part (rad/s for a continuous model; the z plane for a discrete one).
    pub re: f64,
    /// Imaginary part (likewise).
    pub im: f64,
    /// Natural frequency ωₙ = |s| (rad/s) of the continuous root s (s =
    /// ln z / h for a discrete one); absent at z = 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub natural_frequency_rad_s: Option<f64>,
    /// Damping ratio ζ = −Re s / |s|; absent at s = 0 and z = 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Time constant 1 / |Re s| (s); absent when Re s = 0 to working
    /// precision (|Re s| ≤ 1e-9 s⁻¹: a root on the imaginary axis or at the
    /// origin, whose round-off would read as a time constant of centuries).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_constant_s: Option<f64>,
}

impl PlaneRoot {
    /// The root `z` of a model with sample time `h` (0: continuous).
    pub fn of(z: Complex<f64>, h: f64) -> PlaneRoot {
        let s = if h > 0.0 {
            (z.norm() > 0.0).then(|| z.ln() / h)
        } else {
            Some(z)
        };
        let wn = s.map(|s| s.norm()).filter(|w| w.is_finite());
        PlaneRoot {
            re: z.re,
            im: z.im,
            natural_frequency_rad_s: wn,
            damping: s.zip(wn).filter(|(_, w)| *w > 0.0).map(|(s, w)| -s.re / w),
            time_constant_s: s
                .filter(|s| s.re.abs() > AXIS_TOL)
                .map(|s| 1.0 / s.re.abs()),
        }
    }
}

/// The zeros of one input → output channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelZeros {
    /// Input name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Zeros of the channel's transfer function.
    pub zeros: Vec<PlaneRoot>,
    /// The input does not reach the output at all (g ≡ 0): no zeros to speak of.
    pub no_transfer: bool,
}

/// Poles and zeros at one operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PoleZeroMap {
    /// Grid forward speed (m/s) of an LPV point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// `s` (continuous, rad/s) or `z` (discrete, unit circle = stability limit).
    pub plane: String,
    /// Sample time (s) of a discrete model; 0 for continuous.
    pub sample_time_s: f64,
    /// Eigenvalues of A.
    pub poles: Vec<PlaneRoot>,
    /// All poles strictly inside the stability region.
    pub stable: bool,
    /// Per-channel SISO zeros, input-major.
    pub channels: Vec<ChannelZeros>,
}

/// Eigenvalues of A.
pub fn poles(m: &LinearModel) -> Vec<Complex<f64>> {
    if m.n_states() == 0 {
        return Vec::new();
    }
    m.a.complex_eigenvalues().iter().copied().collect()
}

/// Whether a root lies strictly inside the stability region.
pub fn is_stable_root(z: Complex<f64>, continuous: bool) -> bool {
    if continuous {
        z.re < 0.0
    } else {
        z.norm() < 1.0
    }
}

/// Zeros of input `j` → output `i`; `None` when the channel transfers nothing.
pub fn channel_zeros(m: &LinearModel, i: usize, j: usize) -> Option<Vec<Complex<f64>>> {
    let b = m.b.column(j).into_owned();
    let c = m.c.row(i).into_owned();
    let d = m.d[(i, j)];
    let bc = &b * &c;
    if d != 0.0 {
        let a = &m.a - bc / d;
        return Some(a.complex_eigenvalues().iter().copied().collect());
    }
    let p0 = characteristic(&m.a);
    let p1 = characteristic(&(&m.a - &bc));
    let num: Vec<f64> = p1.iter().zip(&p0).map(|(x, y)| x - y).collect();
    let size = p0.iter().chain(&p1).fold(0.0_f64, |s, c| s.max(c.abs()));
    let largest = num.iter().fold(0.0_f64, |s, c| s.max(c.abs()));
    if largest <= 1e-10 * size {
        return None;
    }
    Some(roots(&num, COEFF_REL_TOL))
}

/// The pole-zero map of every operating point.
pub fn pole_zero_maps(models: &LinearModels) -> Vec<PoleZeroMap> {
    models
        .points
        .iter()
        .map(|(speed, m)| {
            let h = m.sample_time_s;
            let p = poles(m);
            let mut channels = Vec::new();
            for (j, input) in models.inputs.iter().enumerate() {
                for (i, output) in models.outputs.iter().enumerate() {
                    let z = channel_zeros(m, i, j);
                    channels.push(ChannelZeros {
                        input: input.name.clone(),
                        output: output.name.clone(),
                        no_transfer: z.is_none(),
                        zeros: z
                            .unwrap_or_default()
                            .into_iter()
                            .filter(|z| z.re.is_finite() && z.im.is_finite())
                            .map(|z| PlaneRoot::of(z, h))
                            .collect(),
                    });
                }
            }
            PoleZeroMap {
                grid_speed_mps: *speed,
                plane: if m.continuous() { "s" } else { "z" }.into(),
                sample_time_s: h,
                stable: p.iter().all(|z| is_stable_root(*z, m.continuous())),
                poles: p.into_iter().map(|z| PlaneRoot::of(z, h)).collect(),
                channels,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// g(s) = (s + 2) / ((s + 1)(s + 3)) in controllable canonical form, plus `d`.
    fn known(d: f64, h: f64) -> LinearModel {
        LinearModel {
            a: DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -3.0, -4.0]),
            b: DMatrix::from_row_slice(2, 1, &[0.0, 1.0]),
            c: DMatrix::from_row_slice(1, 2, &[2.0, 1.0]),
            d: DMatrix::from_element(1, 1, d),
            sample_time_s: h,
        }
    }

    fn sorted(mut r: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
        r.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        r
    }

    #[test]
    fn poles_and_zero_of_a_known_transfer_function() {
        let m = known(0.0, 0.0);
        let p = sorted(poles(&m));
        assert!((p[0].re + 3.0).abs() < 1e-12 && (p[1].re + 1.0).abs() < 1e-12);
        let z = channel_zeros(&m, 0, 0).unwrap();
        assert_eq!(z.len(), 1);
        assert!(
            (z[0].re + 2.0).abs() < 1e-10 && z[0].im.abs() < 1e-12,
            "{z:?}"
        );
        // With d = 1: g = (s² + 5s + 5)/(s² + 4s + 3), zeros (−5 ± √5)/2.
        let z = sorted(channel_zeros(&known(1.0, 0.0), 0, 0).unwrap());
        let s5 = 5.0_f64.sqrt();
        assert!((z[0].re - (-5.0 - s5) / 2.0).abs() < 1e-10);
        assert!((z[1].re - (-5.0 + s5) / 2.0).abs() < 1e-10);
    }

    #[test]
    fn a_relative_degree_two_channel_has_no_finite_zero_and_a_cut_channel_none() {
        // 1 / ((s + 1)(s + 3)): c = [1, 0].
        let mut m = known(0.0, 0.0);
        m.c = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
        assert!(channel_zeros(&m, 0, 0).unwrap().is_empty());
        m.c = DMatrix::zeros(1, 2);
        assert!(channel_zeros(&m, 0, 0).is_none());
    }

    #[test]
    fn damping_natural_frequency_and_time_constant() {
        // s = −1 ± 2j: ωₙ = √5, ζ = 1/√5.
        let r = PlaneRoot::of(Complex::new(-1.0, 2.0), 0.0);
        assert!((r.natural_frequency_rad_s.unwrap() - 5.0_f64.sqrt()).abs() < 1e-12);
        assert!((r.damping.unwrap() - 1.0 / 5.0_f64.sqrt()).abs() < 1e-12);
        assert!((r.time_constant_s.unwrap() - 1.0).abs() < 1e-12);
        // The discrete pole z = e^{−h} of a 1 s lag sampled at h = 0.1 s.
        let r = PlaneRoot::of(Complex::new((-0.1_f64).exp(), 0.0), 0.1);
        assert!((r.time_constant_s.unwrap() - 1.0).abs() < 1e-12);
        assert!((r.damping.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(
            PlaneRoot::of(Complex::new(0.0, 0.0), 0.1).natural_frequency_rad_s,
            None
        );
        // A continuous root at 4e-16 (round-off of an integrator's zero)
        // has no time constant, not one of 2.5e15 s; 1e-8 s⁻¹ still has one.
        assert_eq!(
            PlaneRoot::of(Complex::new(4e-16, 0.0), 0.0).time_constant_s,
            None
        );
        assert_eq!(
            PlaneRoot::of(Complex::new(1.0 + 1e-17, 0.0), 0.1).time_constant_s,
            None
        );
        assert!(
            PlaneRoot::of(Complex::new(-1e-8, 0.0), 0.0)
                .time_constant_s
                .is_some()
        );
    }

    #[test]
    fn maps_name_channels_and_judge_stability() {
        let models = crate::responses::surge_channel(known(0.0, 0.0));
        let maps = pole_zero_maps(&models);
        assert!(maps[0].stable);
        assert_eq!(maps[0].plane, "s");
        assert_eq!(maps[0].channels[0].input, "tau_X");
        assert_eq!(maps[0].channels[0].zeros.len(), 1);
        let mut unstable = known(0.0, 0.0);
        unstable.a[(1, 0)] = 3.0; // s² + 4s − 3: one root > 0
        let models = LinearModels {
            points: vec![(None, unstable)],
            ..models
        };
        assert!(!pole_zero_maps(&models)[0].stable);
    }
}
