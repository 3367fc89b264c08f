//! Any model as plain state space, `ẋ = A x + B (u − u₀)` (continuous,
//! `sample_time_s` = 0) or `x⁺ = A x + B (u − u₀) + K e` (discrete), with
//! `y − y₀ = C x + D (u − u₀) (+ e)`: one point per LPV grid speed, one for a
//! DP ship or an N4SID model. Every state, input and output has its name and
//! SI unit; the constant loads b of an LPV point are its input operating
//! point u₀ (ν̇ = A ν + B (γ − b)). As JSON (`seatrial-ss/1`) and as a long
//! CSV with one matrix entry per row.

use std::fmt::Write;

use serde::Serialize;

use super::discrete::discretize;
use super::document::{Matrix, ModelDocument, ModelKind};
use super::export::csv_field as q;
use super::export_terms::{ExportedTerm, model_terms};
use crate::planning::dof::Dof;

/// A named signal with its unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct Channel {
    /// Name (log column or state symbol).
    pub name: String,
    /// SI unit (`-` when non-dimensional or a black-box state).
    pub unit: String,
}

/// One operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct SsPoint {
    /// Grid forward speed (m/s) of an LPV sub-model; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_speed_mps: Option<f64>,
    /// State matrix (n × n).
    #[serde(rename = "A")]
    pub a: Matrix,
    /// Input matrix (n × m).
    #[serde(rename = "B")]
    pub b: Matrix,
    /// Output matrix (p × n).
    #[serde(rename = "C")]
    pub c: Matrix,
    /// Feedthrough (p × m).
    #[serde(rename = "D")]
    pub d: Matrix,
    /// Innovation (Kalman) gain of an N4SID model (n × p).
    #[serde(rename = "K", skip_serializing_if = "Option::is_none")]
    pub k: Option<Matrix>,
    /// Input operating point u₀ (the model is driven by u − u₀): an LPV
    /// point's constant loads b, an N4SID model's mean input.
    pub u0: Vec<f64>,
    /// Output operating point y₀ (the model gives y − y₀).
    pub y0: Vec<f64>,
}

/// A model in state-space form.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct StateSpaceExport {
    /// `seatrial-ss/1`.
    pub format: String,
    /// Model name.
    pub name: String,
    /// Model version.
    pub version: i64,
    /// `lpv`, `dp_ship` or `state_space`.
    pub kind: ModelKind,
    /// The identification method.
    pub method: String,
    /// The equations the matrices belong to.
    pub equations: String,
    /// Sample time (s) of a discrete model; 0 for a continuous one.
    pub sample_time_s: f64,
    /// State names and units, in the order of A's rows.
    pub states: Vec<Channel>,
    /// Inputs, in the order of B's columns.
    pub inputs: Vec<Channel>,
    /// Outputs, in the order of C's rows.
    pub outputs: Vec<Channel>,
    /// One point per grid speed (one for a DP ship or an N4SID model).
    pub points: Vec<SsPoint>,
    /// Discovered terms per grid speed (they are not linear and not in A,
    /// B; see the Fossen export). Empty for a model without them.
    pub terms: Vec<GridTerms>,
    /// How to use it.
    pub notes: Vec<String>,
}

/// The discovered terms of one grid point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct GridTerms {
    /// Grid forward speed (m/s).
    pub grid_speed_mps: f64,
    /// The terms.
    pub terms: Vec<ExportedTerm>,
}

fn identity(n: usize) -> Matrix {
    (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect()
}

fn zeros(r: usize, c: usize) -> Matrix {
    vec![vec![0.0; c]; r]
}

/// The DOF a channel name points at: `tau_X`, `gamma_Y`, `γ_N` (force
/// columns) or `u`…`r` (velocities).
fn force_dof(name: &str) -> Option<Dof> {
    let suffix = name.rsplit('_').next()?;
    Dof::ALL
        .into_iter()
        .find(|d| d.force_column().ends_with(&format!("_{suffix}")))
        .filter(|_| name.contains('_'))
}

/// SI unit of an input column: N or N·m for a force, `-` otherwise
/// (normalized thruster commands).
pub fn input_unit(name: &str) -> String {
    force_dof(name).map_or("-", |d| d.force_unit()).to_string()
}

/// SI unit of an output column: a velocity or a pose.
pub fn output_unit(name: &str) -> String {
    if let Some(d) = Dof::ALL.into_iter().find(|d| d.velocity_symbol() == name) {
        return d.velocity_unit().into();
    }
    match name {
        "x" | "y" | "z" => "m".into(),
        "phi" | "theta" | "psi" | "ψ" => "rad".into(),
        _ => "-".into(),
    }
}

fn channels(names: &[String], unit: impl Fn(&str) -> String) -> Vec<Channel> {
    names
        .iter()
        .map(|n| Channel {
            name: n.clone(),
            unit: unit(n),
        })
        .collect()
}

fn velocity_states(dofs: &[Dof]) -> Vec<Channel> {
    dofs.iter()
        .map(|d| Channel {
            name: d.velocity_symbol().into(),
            unit: d.velocity_unit().into(),
        })
        .collect()
}

/// The state-space form of `doc`: continuous for an LPV or DP model unless
/// `h` is given (then ZOH at h), discrete at its own h for an N4SID model
/// (`Err` when `h` differs).
pub fn state_space_export(
    doc: &ModelDocument,
    name: &str,
    version: i64,
    h: Option<f64>,
) -> Result<StateSpaceExport, String> {
    let discrete = h.map(|h| discretize(doc, h)).transpose()?;
    let mut notes = Vec::new();
    let (states, inputs, outputs, points, sample_time_s, equations);
    match doc.kind {
        ModelKind::Lpv => {
            let lpv = doc.lpv.as_ref().ok_or("the LPV model has no grid points")?;
            let n = doc.dofs.len();
            states = velocity_states(&doc.dofs);
            outputs = states.clone();
            inputs = doc
                .dofs
                .iter()
                .enumerate()
                .map(|(i, d)| Channel {
                    name: doc
                        .inputs
                        .get(i)
                        .cloned()
                        .unwrap_or_else(|| format!("γ_{}", &d.force_column()[4..])),
                    unit: d.force_unit().into(),
                })
                .collect();
            points = lpv
                .points
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let (a, b) = match &discrete {
                        Some(dm) => (dm.points[i].phi.clone(), dm.points[i].gamma.clone()),
                        None => (p.a.clone(), p.b.clone()),
                    };
                    SsPoint {
                        grid_speed_mps: Some(p.speed_mps),
                        a,
                        b,
                        c: identity(n),
                        d: zeros(n, n),
                        k: None,
                        u0: p.load.clone().unwrap_or_else(|| vec![0.0; n]),
                        y0: vec![0.0; n],
                    }
                })
                .collect();
            sample_time_s = h.unwrap_or(0.0);
            equations = if h.is_some() {
                "ν(k+1) = A ν(k) + B (γ(k) − u0), y = C ν + D (γ − u0), γ = τ − g(η) held over each sample (ZOH); one point per grid forward speed"
            } else {
                "ν̇ = A ν + B (γ − u0), y = C ν + D (γ − u0), γ = τ − g(η); A = −M⁻¹D̄, B = M⁻¹, u0 = the constant loads b; one point per grid forward speed"
            }
            .into();
            notes.push("Schedule on forward speed: nearest grid point, or interpolate between neighbours; g(η) is in the JSON and NumPy exports.".into());
            if let (Some(e), Some(lo), Some(hi)) =
                (lpv.extension, lpv.points.first(), lpv.points.last())
            {
                notes.push(e.describe(lo.speed_mps, hi.speed_mps));
            }
            if lpv.logged_controller.is_some() {
                notes.push("The logs came from a controller faster than the log; A and B are the vehicle's own (see the JSON export's logged_controller).".into());
            }
        }
        ModelKind::DpShip => {
            let s = doc.dp_ship.as_ref().ok_or("the DP model is missing")?;
            let dofs = [Dof::Surge, Dof::Sway, Dof::Yaw];
            states = velocity_states(&dofs);
            outputs = states.clone();
            inputs = channels(&doc.inputs, |_| "-".into());
            let (a, b) = match &discrete {
                Some(dm) => (dm.points[0].phi.clone(), dm.points[0].gamma.clone()),
                None => (s.a_si.clone(), s.b_si.clone()),
            };
            let m = b.first().map_or(0, Vec::len);
            points = vec![SsPoint {
                grid_speed_mps: None,
                a,
                b,
                c: identity(3),
                d: zeros(3, m),
                k: None,
                u0: vec![0.0; m],
                y0: vec![0.0; 3],
            }];
            sample_time_s = h.unwrap_or(0.0);
            equations = if h.is_some() {
                "ν(k+1) = A ν(k) + B u(k) (ZOH), y = ν; η̇ = J(ψ) ν gives x, y, ψ"
            } else {
                "ν̇ = A ν + B u, y = ν (SI: m/s, m/s, rad/s; u normalized thruster commands); η̇ = J(ψ) ν gives x, y, ψ"
            }
            .into();
            notes.push(format!(
                "The SI form of the Bis model (ship length L = {} m); the Bis matrices are in the JSON and NumPy exports.",
                s.length_m
            ));
        }
        ModelKind::StateSpace => {
            let s = doc
                .state_space
                .as_ref()
                .ok_or("the state-space model is missing")?;
            states = (1..=s.order)
                .map(|i| Channel {
                    name: format!("x{i}"),
                    unit: "-".into(),
                })
                .collect();
            inputs = channels(&doc.inputs, input_unit);
            outputs = channels(&doc.outputs, output_unit);
            points = vec![SsPoint {
                grid_speed_mps: None,
                a: s.phi.clone(),
                b: s.gamma.clone(),
                c: s.c.clone(),
                d: s.d.clone(),
                k: Some(s.k.clone()),
                u0: s.u_offset.clone(),
                y0: s.y_offset.clone(),
            }];
            sample_time_s = s.h;
            equations = "x(k+1) = A x(k) + B (u(k) − u0) + K e(k), y(k) − y0 = C x(k) + D (u(k) − u0) + e(k) (innovation form; states in the model's own coordinates)".into();
        }
    }
    let terms: Vec<GridTerms> = model_terms(doc)
        .into_iter()
        .map(|(grid_speed_mps, terms)| GridTerms {
            grid_speed_mps,
            terms,
        })
        .collect();
    if !terms.is_empty() {
        notes.push("Discovered physics: A and B are the refitted linear part; the terms (non-linear damping, loads, actuator effects…) add to it as listed.".into());
    }
    Ok(StateSpaceExport {
        format: "seatrial-ss/1".into(),
        name: name.into(),
        version,
        kind: doc.kind,
        method: doc.method.name().into(),
        equations,
        sample_time_s,
        states,
        inputs,
        outputs,
        points,
        terms,
        notes,
    })
}

/// The export as CSV, one number per row:
/// `point,grid_speed_mps,sample_time_s,matrix,row,col,row_name,col_name,row_unit,col_unit,value`
/// with `matrix` one of A, B, C, D, K (rows and columns named by state,
/// input, output) and u0, y0 (`col` 0, `col_name` empty).
pub fn state_space_csv(e: &StateSpaceExport) -> String {
    let mut out = String::from(
        "point,grid_speed_mps,sample_time_s,matrix,row,col,row_name,col_name,row_unit,col_unit,value\n",
    );
    for (i, p) in e.points.iter().enumerate() {
        let speed = p.grid_speed_mps.map(|v| v.to_string()).unwrap_or_default();
        let mut row =
            |matrix: &str, r: usize, c: usize, rn: &Channel, cn: Option<&Channel>, v: f64| {
                let _ = writeln!(
                    out,
                    "{i},{speed},{},{matrix},{r},{c},{},{},{},{},{v}",
                    e.sample_time_s,
                    q(&rn.name),
                    q(cn.map_or("", |c| &c.name)),
                    q(&rn.unit),
                    q(cn.map_or("", |c| &c.unit)),
                );
            };
        let mut matrix = |name: &str, m: &Matrix, rows: &[Channel], cols: &[Channel]| {
            for (r, (vals, rn)) in m.iter().zip(rows).enumerate() {
                for (c, (v, cn)) in vals.iter().zip(cols).enumerate() {
                    row(name, r, c, rn, Some(cn), *v);
                }
            }
        };
        matrix("A", &p.a, &e.states, &e.states);
        matrix("B", &p.b, &e.states, &e.inputs);
        matrix("C", &p.c, &e.outputs, &e.states);
        matrix("D", &p.d, &e.outputs, &e.inputs);
        if let Some(k) = &p.k {
            matrix("K", k, &e.states, &e.outputs);
        }
        let column = |v: &[f64]| v.iter().map(|x| vec![*x]).collect::<Matrix>();
        let none = [Channel {
            name: String::new(),
            unit: String::new(),
        }];
        matrix("u0", &column(&p.u0), &e.inputs, &none);
        matrix("y0", &column(&p.y0), &e.outputs, &none);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::document::{Method, StateSpaceDoc};
    use crate::identification::tests::lpv_doc;

    #[test]
    fn lpv_points_are_continuous_with_loads_as_input_offsets() {
        let mut doc = lpv_doc(
            vec![Dof::Surge, Dof::Yaw],
            vec![(
                0.5,
                vec![vec![2000.0, 0.0], vec![0.0, 300.0]],
                vec![vec![500.0, 0.0], vec![0.0, 90.0]],
            )],
        );
        doc.lpv.as_mut().unwrap().points[0].load = Some(vec![12.0, -3.0]);
        let e = state_space_export(&doc, "ROV", 2, None).unwrap();
        assert_eq!(e.sample_time_s, 0.0);
        assert_eq!(e.states[1].name, "r");
        assert_eq!(e.states[1].unit, "rad/s");
        assert_eq!(e.inputs[1].unit, "N·m");
        let p = &e.points[0];
        assert_eq!(p.a, doc.lpv.as_ref().unwrap().points[0].a);
        assert_eq!(p.u0, vec![12.0, -3.0]);
        assert_eq!(p.c, identity(2));
        let d = state_space_export(&doc, "ROV", 2, Some(0.1)).unwrap();
        assert_eq!(d.sample_time_s, 0.1);
        assert!((d.points[0].a[0][0] - (-500.0 * 0.1 / 2000.0f64).exp()).abs() < 1e-14);
        let csv = state_space_csv(&e);
        assert!(csv.contains("\n0,0.5,0,A,0,0,u,u,m/s,m/s,-0.25\n"), "{csv}");
        assert!(csv.contains("\n0,0.5,0,u0,0,0,γ_X,,N,,12\n"), "{csv}");
        // 4 A + 4 B + 4 C + 4 D + 2 u0 + 2 y0 entries.
        assert_eq!(csv.lines().count(), 1 + 20);
    }

    #[test]
    fn n4sid_models_are_discrete_with_named_channels() {
        let mut doc = lpv_doc(vec![Dof::Surge, Dof::Yaw], vec![]);
        doc.kind = ModelKind::StateSpace;
        doc.method = Method::N4sid;
        doc.lpv = None;
        doc.inputs = vec!["tau_X".into(), "tau_N".into()];
        doc.outputs = vec!["u".into(), "r".into()];
        doc.state_space = Some(StateSpaceDoc {
            h: 0.1,
            order: 1,
            phi: vec![vec![0.9]],
            gamma: vec![vec![1.0, 2.0]],
            c: vec![vec![1.0], vec![0.5]],
            d: zeros(2, 2),
            k: vec![vec![0.3, 0.1]],
            singular_values: vec![1.0],
            a_continuous: None,
            b_continuous: None,
            u_offset: vec![100.0, 0.0],
            y_offset: vec![0.5, 0.0],
        });
        let e = state_space_export(&doc, "n4", 1, None).unwrap();
        assert_eq!(e.sample_time_s, 0.1);
        assert_eq!(
            e.outputs,
            vec![
                Channel {
                    name: "u".into(),
                    unit: "m/s".into()
                },
                Channel {
                    name: "r".into(),
                    unit: "rad/s".into()
                }
            ]
        );
        assert_eq!(e.inputs[1].unit, "N·m");
        assert_eq!(e.points[0].k, Some(vec![vec![0.3, 0.1]]));
        assert!(state_space_export(&doc, "n4", 1, Some(0.2)).is_err());
        let csv = state_space_csv(&e);
        assert!(csv.contains("\n0,,0.1,C,1,0,r,x1,rad/s,-,0.5\n"), "{csv}");
        assert!(csv.contains("\n0,,0.1,K,0,1,x1,r,-,rad/s,0.1\n"), "{csv}");
        assert!(csv.contains("\n0,,0.1,u0,0,0,tau_X,,N,,100\n"), "{csv}");
        assert_eq!(input_unit("thr_3"), "-");
        assert_eq!(input_unit("gamma_K"), "N·m");
    }
}
