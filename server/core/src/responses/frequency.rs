//! Frequency response H(f) = C (λI − A)⁻¹ B + D of every input → output
//! channel, λ = j2πf for a continuous model and λ = e^{j2πfh} for a
//! discrete one (as `scipy.signal.freqresp` / `dfreqresp`), as magnitude in
//! dB and unwrapped phase in degrees.

use std::f64::consts::PI;

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use super::poles::poles;
use super::{LinearModel, LinearModels, finite, ratio_unit};

/// H(f) for every channel: `out[k]` is the p × m matrix at `freqs_hz[k]`;
/// `None` where λI − A is singular (f on a pole).
pub fn response(m: &LinearModel, freqs_hz: &[f64]) -> Vec<Option<DMatrix<Complex<f64>>>> {
    let n = m.n_states();
    let to_c = |x: &DMatrix<f64>| x.map(|v| Complex::new(v, 0.0));
    let (a, b, c, d) = (to_c(&m.a), to_c(&m.b), to_c(&m.c), to_c(&m.d));
    freqs_hz
        .iter()
        .map(|&f| {
            let w = 2.0 * PI * f;
            let lambda = if m.continuous() {
                Complex::new(0.0, w)
            } else {
                Complex::new(0.0, w * m.sample_time_s).exp()
            };
            let mut s = -a.clone();
            for i in 0..n {
                s[(i, i)] += lambda;
            }
            let x = s.lu().solve(&b)?;
            let h = &c * x + &d;
            h.iter()
                .all(|z| z.re.is_finite() && z.im.is_finite())
                .then_some(h)
        })
        .collect()
}

/// Phase unwrapped along the frequencies (degrees, jumps > 180° folded,
/// as `numpy.unwrap(…, period=360)`).
pub fn unwrap_deg(phase: &[Option<f64>]) -> Vec<Option<f64>> {
    let mut out = Vec::with_capacity(phase.len());
    let mut last: Option<f64> = None;
    let mut shift = 0.0;
    for p in phase {
        let Some(p) = *p else {
            out.push(None);
            continue;
        };
        if let Some(l) = last {
            let mut v = p + shift;
            while v - l > 180.0 {
                v -= 360.0;
                shift -= 360.0;
            }
            while v - l < -180.0 {
                v += 360.0;
                shift += 360.0;
            }
            out.push(Some(v));
            last = Some(v);
        } else {
            out.push(Some(p));
            last = Some(p);
        }
    }
    out
}

/// A frequency grid for a Bode plot: `points` log-spaced frequencies from
/// 1/30 of the slowest pole's to 30× the fastest's (Hz), up to the
/// Nyquist frequency of a discrete model.
pub fn log_grid(models: &LinearModels, points: usize) -> Vec<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    let mut nyquist = f64::INFINITY;
    for (_, m) in &models.points {
        let h = m.sample_time_s;
        if h > 0.0 {
            nyquist = nyquist.min(0.5 / h);
        }
        for z in poles(m) {
            let w = if h > 0.0 {
                if z.norm() == 0.0 {
                    continue;
                }
                (z.ln() / h).norm()
            } else {
                z.norm()
            };
            if w > 0.0 && w.is_finite() {
                lo = lo.min(w / (2.0 * PI));
                hi = hi.max(w / (2.0 * PI));
            }
        }
    }
    if !lo.is_finite() {
        (lo, hi) = (0.01, 1.0);
    }
    let lo = (lo / 30.0).max(1e-5);
    let hi = (hi * 30.0).min(nyquist).max(lo * 10.0).min(nyquist);
    let points = points.max(2);
    let (l0, l1) = (lo.ln(), hi.ln());
    (0..points)
        .map(|k| (l0 + (l1 - l0) * k as f64 / (points - 1) as f64).exp())
        .collect()
}

/// One channel's Bode series.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelResponse {
    /// Input name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Unit of |H| (output unit per input unit); dB are re 1 of it.
    pub unit: String,
    /// 20·log10 |H| (dB); null where H = 0 or undefined (on a pole).
    pub magnitude_db: Vec<Option<f64>>,
    /// Unwrapped phase of H (degrees); null likewise.
    pub phase_deg: Vec<Option<f64>>,
}

/// The Bode series of one operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PointResponse {
    /// Grid forward speed (m/s) of an LPV point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// Every channel, input-major.
    pub channels: Vec<ChannelResponse>,
}

/// The Bode series of every point and channel at `freqs_hz`.
pub fn bode(models: &LinearModels, freqs_hz: &[f64]) -> Vec<PointResponse> {
    models
        .points
        .iter()
        .map(|(speed, m)| {
            let h = response(m, freqs_hz);
            let mut channels = Vec::new();
            for (j, input) in models.inputs.iter().enumerate() {
                for (i, output) in models.outputs.iter().enumerate() {
                    let at = |k: usize| h[k].as_ref().map(|x| x[(i, j)]);
                    let magnitude_db = (0..freqs_hz.len())
                        .map(|k| at(k).and_then(|z| finite(20.0 * z.norm().log10())))
                        .collect();
                    let raw: Vec<Option<f64>> = (0..freqs_hz.len())
                        .map(|k| {
                            at(k)
                                .filter(|z| z.norm() > 0.0)
                                .map(|z| z.arg().to_degrees())
                        })
                        .collect();
                    channels.push(ChannelResponse {
                        input: input.name.clone(),
                        output: output.name.clone(),
                        unit: ratio_unit(&output.unit, &input.unit),
                        magnitude_db,
                        phase_deg: unwrap_deg(&raw),
                    });
                }
            }
            PointResponse {
                grid_speed_mps: *speed,
                channels,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::responses::surge_channel as one;

    fn lag(t: f64, k: f64) -> LinearModel {
        // ẋ = −x/T + (k/T) u, y = x: g = k / (1 + sT).
        LinearModel {
            a: DMatrix::from_element(1, 1, -1.0 / t),
            b: DMatrix::from_element(1, 1, k / t),
            c: DMatrix::from_element(1, 1, 1.0),
            d: DMatrix::zeros(1, 1),
            sample_time_s: 0.0,
        }
    }

    #[test]
    fn first_order_lag_is_minus_3_db_and_minus_45_degrees_at_its_corner() {
        let t = 2.0;
        let fc = 1.0 / (2.0 * PI * t);
        let b = bode(&one(lag(t, 1.0)), &[fc / 1000.0, fc, fc * 1000.0]);
        let ch = &b[0].channels[0];
        assert_eq!(ch.unit, "m/s per N");
        assert!(ch.magnitude_db[0].unwrap().abs() < 1e-5);
        assert!((ch.magnitude_db[1].unwrap() + 10.0 * 2.0_f64.log10()).abs() < 1e-12);
        assert!((ch.phase_deg[1].unwrap() + 45.0).abs() < 1e-12);
        // −20 dB/decade far above: −60 dB at 1000 fc, phase → −90°.
        assert!((ch.magnitude_db[2].unwrap() + 60.0).abs() < 1e-3);
        assert!((ch.phase_deg[2].unwrap() + 90.0).abs() < 0.1);
    }

    #[test]
    fn discrete_response_matches_the_closed_form() {
        // x⁺ = a x + (1 − a) u: H(z) = (1 − a)/(z − a), z = e^{j2πfh}.
        let (a, h) = (0.9, 0.1);
        let m = LinearModel {
            a: DMatrix::from_element(1, 1, a),
            b: DMatrix::from_element(1, 1, 1.0 - a),
            c: DMatrix::from_element(1, 1, 1.0),
            d: DMatrix::zeros(1, 1),
            sample_time_s: h,
        };
        for f in [0.01, 0.5, 2.0, 4.9] {
            let z = Complex::new(0.0, 2.0 * PI * f * h).exp();
            let want = Complex::new(1.0 - a, 0.0) / (z - a);
            let got = response(&m, &[f])[0].as_ref().unwrap()[(0, 0)];
            assert!((got - want).norm() < 1e-14, "f = {f}");
        }
        let g = log_grid(&one(m), 50);
        assert!((g[49] - 5.0).abs() < 1e-9, "up to Nyquist 1/(2h)");
    }

    #[test]
    fn phase_unwraps_across_minus_180_degrees() {
        // Third-order lag 1/(1 + s)³ reaches −270°.
        let mut m = lag(1.0, 1.0);
        m.a = DMatrix::from_row_slice(3, 3, &[-1.0, 1.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0, -1.0]);
        m.b = DMatrix::from_row_slice(3, 1, &[0.0, 0.0, 1.0]);
        m.c = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 0.0]);
        let freqs: Vec<f64> = (0..200)
            .map(|k| 10f64.powf(-3.0 + 5.0 * k as f64 / 199.0))
            .collect();
        let b = bode(&one(m), &freqs);
        let ph = &b[0].channels[0].phase_deg;
        assert!((ph[199].unwrap() + 270.0).abs() < 1.0, "{:?}", ph[199]);
        assert!(ph.windows(2).all(|w| w[1].unwrap() <= w[0].unwrap() + 1e-9));
    }
}
