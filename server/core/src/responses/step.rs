//! Step and impulse responses of every input → output channel from rest,
//! as `scipy.signal.step` / `impulse` (continuous) and `dstep` / `dimpulse`
//! (discrete). A continuous model is sampled by its exact ZOH
//! discretization, which is exact for a step held over each sample and
//! gives y(kΔt) = C e^{AkΔt} B for the impulse. A discrete model's impulse
//! is the unit pulse u(0) = 1. An unstable model's response is cut where it
//! has grown a thousandfold within the last half of the elapsed time, and
//! the cut is reported as `diverged_at_s` instead of ever larger numbers.

use nalgebra::DVector;
use serde::Serialize;

use super::poles::poles;
use super::{LinearModel, LinearModels, finite, ratio_unit};
use crate::models::state_space::StateSpace;

/// Samples of a continuous model's response.
const CONTINUOUS_SAMPLES: usize = 600;
/// Most samples of a discrete model's response.
const MAX_DISCRETE_SAMPLES: usize = 5000;
/// Growth over the second half of the elapsed time that counts as divergence.
const DIVERGENCE_GROWTH: f64 = 1e3;
/// Time constants of the slowest stable pole shown.
const SETTLING_TIME_CONSTANTS: f64 = 6.0;

/// Which response.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum ResponseKind {
    /// Unit step of one input at t = 0.
    Step,
    /// Unit impulse (Dirac δ for a continuous model, unit pulse for a discrete one).
    Impulse,
}

/// One channel's response.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct ChannelTimeResponse {
    /// Input name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Unit of the values (output per unit input; per unit input·s for a
    /// continuous impulse).
    pub unit: String,
    /// y(t) per entry of `time_s`; null after a divergence.
    pub values: Vec<Option<f64>>,
    /// Where an unstable response was cut (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diverged_at_s: Option<f64>,
}

/// The responses at one operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PointTimeResponse {
    /// Grid forward speed (m/s) of an LPV point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// Sample times (s).
    pub time_s: Vec<f64>,
    /// Every channel, input-major.
    pub channels: Vec<ChannelTimeResponse>,
}

/// Time shown by default: six time constants of the slowest stable pole,
/// and at least twenty of the fastest unstable one (long enough for its
/// divergence to show and be cut); 60 s for a model of integrators only.
pub fn default_horizon_s(m: &LinearModel) -> f64 {
    let h = m.sample_time_s;
    let (mut slow, mut fast_unstable) = (0.0_f64, f64::INFINITY);
    for z in poles(m) {
        let s = if h > 0.0 {
            if z.norm() == 0.0 {
                continue;
            }
            z.ln() / h
        } else {
            z
        };
        if s.re < 0.0 {
            slow = slow.max(-1.0 / s.re);
        } else if s.re > 0.0 {
            fast_unstable = fast_unstable.min(1.0 / s.re);
        }
    }
    let settle = SETTLING_TIME_CONSTANTS * slow;
    let t = if fast_unstable.is_finite() {
        settle.max(20.0 * fast_unstable)
    } else if slow > 0.0 {
        settle
    } else {
        60.0
    };
    t.clamp(1e-3, 86_400.0)
}

/// Sample time and count covering `t_end` s.
fn sampling(m: &LinearModel, t_end: f64) -> (f64, usize) {
    if m.continuous() {
        (t_end / (CONTINUOUS_SAMPLES - 1) as f64, CONTINUOUS_SAMPLES)
    } else {
        let h = m.sample_time_s;
        let n = ((t_end / h).ceil() as usize + 1).clamp(20, MAX_DISCRETE_SAMPLES);
        (h, n)
    }
}

/// Cut an unstable response where it diverges: the first sample that is
/// not finite or exceeds `DIVERGENCE_GROWTH` times the largest |y| over
/// the first half of the elapsed samples (index ≥ 10).
fn cut(values: &[f64]) -> Option<usize> {
    let mut prefix_max = Vec::with_capacity(values.len());
    let mut m = 0.0_f64;
    for v in values {
        m = m.max(v.abs());
        prefix_max.push(m);
    }
    values.iter().enumerate().position(|(k, v)| {
        if !v.is_finite() {
            return true;
        }
        if k < 10 {
            return false;
        }
        let reference = prefix_max[k / 2];
        reference > 0.0 && v.abs() > DIVERGENCE_GROWTH * reference
    })
}

/// Responses of one point: sample times, and `y[j][i][k]`, output i's
/// response to input j at sample k.
pub type SampledResponses = (Vec<f64>, Vec<Vec<Vec<f64>>>);

/// Step or impulse responses of one point over `t_end` s.
pub fn time_response(
    m: &LinearModel,
    kind: ResponseKind,
    t_end: f64,
) -> Result<SampledResponses, String> {
    let (dt, n) = sampling(m, t_end);
    let (phi, gamma) = if m.continuous() {
        let d = StateSpace::new(m.a.clone(), m.b.clone(), m.c.clone(), m.d.clone())
            .and_then(|s| s.discretize_zoh(dt))
            .map_err(|e| e.to_string())?;
        (d.phi().clone(), d.gamma().clone())
    } else {
        (m.a.clone(), m.b.clone())
    };
    let time: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    // out[j][i] = output i's response to input j.
    let mut out = vec![vec![Vec::with_capacity(n); m.n_outputs()]; m.n_inputs()];
    for (j, per_input) in out.iter_mut().enumerate() {
        let e = DVector::from_fn(m.n_inputs(), |r, _| if r == j { 1.0 } else { 0.0 });
        let mut x = DVector::zeros(m.n_states());
        for k in 0..n {
            let y = match kind {
                ResponseKind::Step => {
                    let y = &m.c * &x + &m.d * &e;
                    x = &phi * &x + &gamma * &e;
                    y
                }
                ResponseKind::Impulse if m.continuous() => {
                    // y(t) = C e^{At} B (the D δ(t) part has no finite value).
                    if k == 0 {
                        x = m.b.column(j).into_owned();
                    }
                    let y = &m.c * &x;
                    x = &phi * &x;
                    y
                }
                ResponseKind::Impulse => {
                    let u = if k == 0 {
                        e.clone()
                    } else {
                        DVector::zeros(m.n_inputs())
                    };
                    let y = &m.c * &x + &m.d * &u;
                    x = &phi * &x + &gamma * &u;
                    y
                }
            };
            for (i, series) in per_input.iter_mut().enumerate() {
                series.push(y[i]);
            }
        }
    }
    Ok((time, out))
}

/// Step or impulse responses of every point, over `t_end_s` (default:
/// [`default_horizon_s`] of the slowest point).
pub fn time_responses(
    models: &LinearModels,
    kind: ResponseKind,
    t_end_s: Option<f64>,
) -> Result<Vec<PointTimeResponse>, String> {
    let t_end = match t_end_s {
        Some(t) => t,
        None => models
            .points
            .iter()
            .map(|(_, m)| default_horizon_s(m))
            .fold(0.0, f64::max),
    };
    models
        .points
        .iter()
        .map(|(speed, m)| {
            // Poles on the stability limit (integrators) grow without bound but slowly: not cut.
            let unstable = poles(m).iter().any(|z| {
                if m.continuous() {
                    z.re > 0.0
                } else {
                    z.norm() > 1.0
                }
            });
            let (time_s, out) = time_response(m, kind, t_end)?;
            let mut channels = Vec::new();
            for (j, input) in models.inputs.iter().enumerate() {
                for (i, output) in models.outputs.iter().enumerate() {
                    let raw = &out[j][i];
                    let stop = if unstable {
                        cut(raw)
                    } else {
                        raw.iter().position(|v| !v.is_finite())
                    };
                    let unit = if kind == ResponseKind::Impulse && m.continuous() {
                        ratio_unit(&output.unit, &format!("{}·s", input.unit))
                    } else {
                        ratio_unit(&output.unit, &input.unit)
                    };
                    channels.push(ChannelTimeResponse {
                        input: input.name.clone(),
                        output: output.name.clone(),
                        unit,
                        values: raw
                            .iter()
                            .enumerate()
                            .map(|(k, v)| {
                                if stop.is_some_and(|s| k >= s) {
                                    None
                                } else {
                                    finite(*v)
                                }
                            })
                            .collect(),
                        diverged_at_s: stop.map(|s| time_s[s]),
                    });
                }
            }
            Ok(PointTimeResponse {
                grid_speed_mps: *speed,
                time_s,
                channels,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::responses::surge_channel as models;
    use nalgebra::DMatrix;

    fn scalar(a: f64, b: f64, h: f64) -> LinearModel {
        let one = |v: f64| DMatrix::from_element(1, 1, v);
        LinearModel {
            a: one(a),
            b: one(b),
            c: one(1.0),
            d: one(0.0),
            sample_time_s: h,
        }
    }

    #[test]
    fn first_order_lag_step_and_impulse_are_the_textbook_curves() {
        // g = k/(1 + sT): step k(1 − e^{−t/T}), impulse (k/T) e^{−t/T}.
        let (t, k) = (2.0, 0.5);
        let m = scalar(-1.0 / t, k / t, 0.0);
        assert!((default_horizon_s(&m) - 12.0).abs() < 1e-9);
        let r = time_responses(&models(m.clone()), ResponseKind::Step, None).unwrap();
        let ch = &r[0].channels[0];
        assert_eq!(ch.unit, "m/s per N");
        for (ts, y) in r[0].time_s.iter().zip(&ch.values) {
            assert!(
                (y.unwrap() - k * (1.0 - (-ts / t).exp())).abs() < 1e-12,
                "t = {ts}"
            );
        }
        assert!(ch.diverged_at_s.is_none());
        let r = time_responses(&models(m), ResponseKind::Impulse, Some(5.0)).unwrap();
        let ch = &r[0].channels[0];
        assert_eq!(ch.unit, "m/s per N·s");
        assert!((r[0].time_s.last().unwrap() - 5.0).abs() < 1e-12);
        for (ts, y) in r[0].time_s.iter().zip(&ch.values) {
            assert!(
                (y.unwrap() - k / t * (-ts / t).exp()).abs() < 1e-12,
                "t = {ts}"
            );
        }
    }

    #[test]
    fn discrete_step_and_pulse_responses() {
        // x⁺ = a x + (1 − a) u: step 1 − aᵏ, pulse 0 then (1 − a) a^{k−1}.
        let a = 0.8;
        let m = scalar(a, 1.0 - a, 0.1);
        let s = time_responses(&models(m.clone()), ResponseKind::Step, Some(2.0)).unwrap();
        assert_eq!(s[0].time_s.len(), 21);
        for (k, y) in s[0].channels[0].values.iter().enumerate() {
            assert!((y.unwrap() - (1.0 - a.powi(k as i32))).abs() < 1e-12);
        }
        let p = time_responses(&models(m), ResponseKind::Impulse, Some(2.0)).unwrap();
        let v = &p[0].channels[0].values;
        assert_eq!(v[0], Some(0.0));
        for (k, y) in v.iter().enumerate().skip(1) {
            assert!((y.unwrap() - (1.0 - a) * a.powi(k as i32 - 1)).abs() < 1e-12);
        }
    }

    #[test]
    fn an_unstable_response_is_cut_and_the_time_reported() {
        let m = scalar(1.0, 1.0, 0.0); // ẋ = x + u: e^t − 1
        assert!((default_horizon_s(&m) - 20.0).abs() < 1e-9);
        // By default too: a slow stable pole beside it does not hide the growth.
        let mut mixed = m.clone();
        mixed.a = DMatrix::from_diagonal(&nalgebra::dvector![1.0, -0.01]);
        mixed.b = DMatrix::from_element(2, 1, 1.0);
        mixed.c = DMatrix::from_element(1, 2, 1.0);
        let r = time_responses(&models(mixed), ResponseKind::Step, None).unwrap();
        assert!(r[0].channels[0].diverged_at_s.is_some());
        let r = time_responses(&models(m), ResponseKind::Step, Some(100.0)).unwrap();
        let ch = &r[0].channels[0];
        let at = ch.diverged_at_s.expect("diverges");
        // e^{t/2} ≈ 1000 at t ≈ 13.8 s.
        assert!((10.0..20.0).contains(&at), "{at}");
        let shown: Vec<f64> = ch.values.iter().flatten().copied().collect();
        assert!(shown.iter().all(|v| v.abs() < 1e7));
        assert!(ch.values.last().unwrap().is_none());
    }
}
