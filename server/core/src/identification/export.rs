//! Exports of a model document: the parameter table as CSV, and a Fossen-form
//! parameter set — M, D, g(η) terms, thruster configuration — in the notation
//! of Fossen's MSS toolbox and PythonVehicleSimulator (`M = MRB + MA`, `D`,
//! restoring `W`, `B`-type terms, `T`, `K`), so a simulator can be loaded with
//! it directly (`np.array(p["M"])`, `M = jsondecode(...).M` in MATLAB).

use serde::Serialize;

use super::document::{Matrix, ModelDocument, ModelKind, ParameterRow, to_rows};
use super::export_terms::{ExportedTerm, point_terms};
use super::lambda_coriolis::document_inertia;

/// A CSV field, quoted when it holds a comma, a quote or a line break.
pub(crate) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// CSV of every estimated parameter: `group,symbol,grid_speed_mps,value,std,unit`.
/// A subspace model's matrices follow its pole table, one entry per row
/// named by its channels (`C[u,x1]`, `Γ[x2,tau_X]`), with the operating
/// point `u0[tau_X]`, `y0[u]`.
pub fn parameter_csv(doc: &ModelDocument) -> String {
    let mut out = String::from("group,symbol,grid_speed_mps,value,std,unit\n");
    for p in &doc.parameters {
        let q = csv_field;
        out.push_str(&format!(
            "{},{},{},{},{},{}\n",
            q(&p.group),
            q(&p.symbol),
            p.grid_speed_mps.map(|v| v.to_string()).unwrap_or_default(),
            p.value,
            p.std.map(|v| v.to_string()).unwrap_or_default(),
            q(&p.unit)
        ));
    }
    if doc.kind == ModelKind::StateSpace
        && let Ok(e) = super::export_state_space::state_space_export(doc, "", 0, None)
    {
        out.push_str(&state_space_rows(&e));
    }
    out
}

/// The entries of a discrete state-space export as parameter rows.
fn state_space_rows(e: &super::export_state_space::StateSpaceExport) -> String {
    use super::export_state_space::Channel;
    let mut out = String::new();
    let mut row = |group: &str, symbol: String, value: f64, unit: String| {
        out.push_str(&format!(
            "{},{},,{value},,{}\n",
            csv_field(group),
            csv_field(&symbol),
            csv_field(&unit)
        ));
    };
    let per = |to: &Channel, from: &Channel| match (to.unit.as_str(), from.unit.as_str()) {
        (t, "-") => t.to_string(),
        ("-", f) => format!("1/({f})"),
        (t, f) if t == f => "-".to_string(),
        (t, f) => format!("({t})/({f})"),
    };
    for p in &e.points {
        for (group, m, rows, cols) in [
            ("Φ", &p.a, &e.states, &e.states),
            ("Γ", &p.b, &e.states, &e.inputs),
            ("C", &p.c, &e.outputs, &e.states),
            ("D", &p.d, &e.outputs, &e.inputs),
        ]
        .into_iter()
        .chain(p.k.as_ref().map(|k| ("K", k, &e.states, &e.outputs)))
        {
            for (r, vals) in m.iter().enumerate() {
                for (c, v) in vals.iter().enumerate() {
                    row(
                        group,
                        format!("{group}[{},{}]", rows[r].name, cols[c].name),
                        *v,
                        per(&rows[r], &cols[c]),
                    );
                }
            }
        }
        for (group, v, ch) in [("u0", &p.u0, &e.inputs), ("y0", &p.y0, &e.outputs)] {
            for (x, c) in v.iter().zip(ch) {
                row(group, format!("{group}[{}]", c.name), *x, c.unit.clone());
            }
        }
    }
    out
}

/// One speed's rigid-body-plus-added-mass and damping matrices.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct FossenPoint {
    /// Forward speed U (m/s) the matrices hold at.
    #[serde(rename = "U")]
    pub u: f64,
    /// M = M_RB + M_A.
    #[serde(rename = "M")]
    pub m: Matrix,
    /// Linear damping D (the λ-identified D̄).
    #[serde(rename = "D")]
    pub d: Matrix,
    /// Constant load b per DOF of M ν̇ + D ν + b + g(η) = τ (N, N·m; absent
    /// when the model has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<Vec<f64>>,
    /// Terms added by missing-physics discovery at this speed, each with
    /// its coefficients, standard deviations, units and DOF; they enter the
    /// left-hand side (damping, Coriolis, restoring, loads, current) or act
    /// on τ before it is applied (lag, delay, saturation, dead zone). Empty
    /// for a model without discovered physics.
    #[serde(default)]
    pub terms: Vec<ExportedTerm>,
}

/// A Fossen-form parameter set.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct FossenParameterSet {
    /// `seatrial-fossen/1`.
    pub format: String,
    /// The equation the matrices belong to.
    pub equation: String,
    /// DOF order of every matrix (`surge`, `sway`, …).
    pub dofs: Vec<String>,
    /// Units of the matrices.
    pub units: String,
    /// M and D per forward speed (one entry for a DP ship).
    pub points: Vec<FossenPoint>,
    /// Restoring terms g(η): name → value (SI), e.g. `W_minus_B`.
    pub restoring: Vec<ParameterRow>,
    /// Thruster configuration T (DP ship).
    #[serde(rename = "T", skip_serializing_if = "Option::is_none")]
    pub t: Option<Matrix>,
    /// Thrust coefficients K (diagonal, DP ship).
    #[serde(rename = "K", skip_serializing_if = "Option::is_none")]
    pub k: Option<Vec<f64>>,
    /// Diagonal quadratic damping D_q per DOF (N·s²/m², N·m·s²/rad²), one
    /// for every forward speed; the surge entry is 0 (the schedule on U
    /// carries surge's). Absent: linear damping only.
    #[serde(rename = "D_q", default, skip_serializing_if = "Option::is_none")]
    pub d_q: Option<Vec<f64>>,
    /// M of the second-order Coriolis–centripetal force C(δ)δ (kg, kg·m,
    /// kg·m²): one for the vehicle, each entry the inverse-variance mean of
    /// the grid points' M. Absent: no C(δ)δ, or each point's own M serves.
    #[serde(rename = "M_C", default, skip_serializing_if = "Option::is_none")]
    pub m_coriolis: Option<Matrix>,
    /// How to use it.
    pub notes: Vec<String>,
}

/// The Fossen-form set of a physical model; `Err` for a black-box
/// state-space model, which has no M, D or g(η).
pub fn fossen_parameter_set(doc: &ModelDocument) -> Result<FossenParameterSet, String> {
    let dofs = doc.dofs.iter().map(|d| d.name().to_string()).collect();
    let restoring = doc
        .restoring
        .as_ref()
        .map(|r| r.parameters.clone())
        .unwrap_or_default();
    match doc.kind {
        ModelKind::Lpv => {
            let lpv = doc.lpv.as_ref().ok_or("the LPV model has no grid points")?;
            let augmented = lpv.points.iter().any(|p| p.augmentation.is_some());
            let m_coriolis = lpv
                .coriolis_second_order
                .then(|| document_inertia(lpv))
                .flatten()
                .map(|m| to_rows(&m));
            let mut notes = vec![
                "Schedule on forward speed: nearest U, or interpolate M and D between neighbours."
                    .into(),
                "D is the λ-identified D̄ (linear damping about the grid speed).".into(),
            ];
            if let (Some(e), Some(lo), Some(hi)) =
                (lpv.extension, lpv.points.first(), lpv.points.last())
            {
                notes.push(e.describe(lo.speed_mps, hi.speed_mps));
            }
            if lpv.coriolis_second_order {
                let from = if m_coriolis.is_some() {
                    "`M_C`, the vehicle's M pooled over the grid points by inverse variance"
                } else {
                    "the point's M"
                };
                notes.push(format!("Second-order Coriolis–centripetal force: add C(δ)δ to the left-hand side, C(ν) from {from} (Fossen 2011, eq. 6.43) at δ = ν with the forward speed u set to zero — the turning, heaving and rolling forces about straight-ahead motion; the linear part about U is in D and b."));
            }
            if lpv.quadratic_damping.is_some() {
                notes.push("Quadratic damping: add D_q|δ|δ to the left-hand side, D_q diagonal (`D_q`, one for every U), δ = ν with the forward speed u set to zero — hull damping that grows with the amplitude of sway, heave and the rotations; in surge D_q times the part of |u|u beyond its tangent at U, |u|u − |U|U − 2|U|(u − U) (|u|u itself at U = 0), the tangent being in D and b per U.".into());
            }
            if augmented {
                notes.push("Discovered physics: each point's `terms` add to the left-hand side (their coefficients times the regressor named in `label`), or shape τ before it acts (lag, delay, saturation, dead zone); M and D are then the refitted ones.".into());
            }
            Ok(FossenParameterSet {
                format: "seatrial-fossen/1".into(),
                equation: {
                    let coriolis = if lpv.coriolis_second_order { " + C(δ)δ" } else { "" };
                    let quadratic = if lpv.quadratic_damping.is_some() { " + D_q|δ|δ" } else { "" };
                    if augmented {
                        format!("M·ν̇ + D·ν + b{coriolis}{quadratic} + Σ terms(ν, η) + g(η) = τ_applied (per forward speed U)")
                    } else if coriolis.is_empty() && quadratic.is_empty() {
                        "M·ν̇ + D·ν + b + g(η) = τ (per forward speed U; C(ν) from M)".into()
                    } else {
                        format!("M·ν̇ + D·ν + b{coriolis}{quadratic} + g(η) = τ (per forward speed U; δ = ν with u = 0{})", if coriolis.is_empty() { "" } else { ", C(δ) from M" })
                    }
                },
                dofs,
                units: "SI (kg, kg·m, kg·m², kg/s, N, N·m)".into(),
                points: lpv
                    .points
                    .iter()
                    .map(|p| FossenPoint {
                        u: p.speed_mps,
                        m: p.m.clone(),
                        d: p.d_bar.clone(),
                        b: p.load.clone(),
                        terms: point_terms(p),
                    })
                    .collect(),
                restoring,
                t: None,
                k: None,
                d_q: lpv.quadratic_damping.clone(),
                m_coriolis,
                notes,
            })
        }
        ModelKind::DpShip => {
            let s = doc.dp_ship.as_ref().ok_or("the DP model is missing")?;
            Ok(FossenParameterSet {
                format: "seatrial-fossen/1".into(),
                equation: "M″·ν̇″ + C″(ν″)ν″ + D″·ν″ = T″·K″·u, η̇″ = J(ψ)ν″ (Fossen et al. 1995, eq. 26; momentum form ḣ = A_h·h + T·K·u + b_h with h = M·ν, A_h = −D·M⁻¹)".into(),
                dofs,
                units: format!(
                    "{} (non-dimensional): length L = {} m, time √(L/g) = {:.4} s, mass m (displacement), force m·g, moment m·g·L; u normalized thruster commands",
                    s.units, s.length_m, s.time_unit_s
                ),
                points: vec![FossenPoint {
                    u: 0.0,
                    m: s.m.clone(),
                    d: s.d.clone(),
                    b: None,
                    terms: vec![],
                }],
                restoring,
                t: Some(s.t_config.clone()),
                k: Some(s.k.clone()),
                d_q: None,
                m_coriolis: None,
                notes: vec![
                    "Low-frequency DP model at rest (U = 0); D″ = −A″_h·M″ (eq. 39); M″ and T″ are the a-priori values (eq. 29–30), A″_h and K″ identified (eq. 48–49).".into(),
                    format!("A″_h = {:?}", s.a_h),
                    "To SI: M = m·diag(1, 1, L)·M″·diag(1, 1, L); D = m·√(g/L)·diag(1, 1, L)·D″·diag(1, 1, L); τ = m·g·diag(1, 1, L)·T″·K″·u.".into(),
                ],
            })
        }
        ModelKind::StateSpace => Err(
            "a subspace (N4SID) model is a black box in its own state coordinates: it has no M, D or g(η); export it as json"
                .into(),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::document::{LpvDoc, LpvPoint, Method, ModelKind};
    use crate::planning::dof::Dof;

    fn doc() -> ModelDocument {
        let id = vec![vec![1.0]];
        ModelDocument {
            kind: ModelKind::Lpv,
            method: Method::LambdaKf,
            dofs: vec![Dof::Surge],
            inputs: vec!["gamma_X".into()],
            outputs: vec!["u".into()],
            restoring: None,
            lpv: Some(LpvDoc {
                t_lambda_s: 1.0,
                structure: "diagonal".into(),
                coupling: vec![vec![true]],
                points: vec![LpvPoint {
                    load: None,
                    load_std: None,
                    speed_mps: 0.5,
                    m: vec![vec![2700.0]],
                    m_std: vec![vec![30.0]],
                    d_bar: vec![vec![800.0]],
                    d_bar_std: vec![vec![12.0]],
                    a: id.clone(),
                    a_std: id.clone(),
                    b: id.clone(),
                    b_std: id,
                    n_samples: 100,
                    run_ids: vec![],
                    current_force: None,
                    augmentation: None,
                }],
                logged_controller: None,
                extension: None,
                coriolis_second_order: false,
                quadratic_damping: None,
                quadratic_damping_std: None,
                current: None,
            }),
            dp_ship: None,
            state_space: None,
            parameters: vec![ParameterRow {
                group: "M".into(),
                symbol: "M[surge,surge], \"rigid\"".into(),
                grid_speed_mps: Some(0.5),
                value: 2700.0,
                std: Some(30.0),
                unit: "kg".into(),
            }],
            structure_findings: vec![],
            notes: vec![],
        }
    }

    #[test]
    fn csv_quotes_fields_and_leaves_missing_std_empty() {
        let csv = parameter_csv(&doc());
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "group,symbol,grid_speed_mps,value,std,unit");
        assert_eq!(
            lines[1],
            "M,\"M[surge,surge], \"\"rigid\"\"\",0.5,2700,30,kg"
        );
    }

    #[test]
    fn fossen_set_carries_m_and_d_per_speed_and_refuses_black_boxes() {
        let set = fossen_parameter_set(&doc()).unwrap();
        assert_eq!(set.points[0].m, vec![vec![2700.0]]);
        assert_eq!(set.points[0].d, vec![vec![800.0]]);
        let json = serde_json::to_value(&set).unwrap();
        assert_eq!(json["points"][0]["U"], 0.5);
        let mut ss = doc();
        ss.kind = ModelKind::StateSpace;
        assert!(fossen_parameter_set(&ss).unwrap_err().contains("black box"));
    }

    /// Two points with M 2700 ± 30 and 2900 ± 90 give C(δ)δ one M:
    /// (2700/900 + 2900/8100) / (1/900 + 1/8100) = 2720, in the set as
    /// `M_C` and named in its note; without C(δ)δ there is none.
    #[test]
    fn fossen_set_carries_the_pooled_inertia_of_the_coriolis_force() {
        let mut d = doc();
        assert!(fossen_parameter_set(&d).unwrap().m_coriolis.is_none());
        let lpv = d.lpv.as_mut().unwrap();
        lpv.coriolis_second_order = true;
        let mut second = lpv.points[0].clone();
        second.speed_mps = 1.0;
        second.m = vec![vec![2900.0]];
        second.m_std = vec![vec![90.0]];
        lpv.points.push(second);
        let set = fossen_parameter_set(&d).unwrap();
        let m_c = set.m_coriolis.clone().unwrap()[0][0];
        assert!((m_c - 2720.0).abs() < 1e-9, "{m_c}");
        assert!(set.notes.iter().any(|n| n.contains("`M_C`")));
        assert_eq!(serde_json::to_value(&set).unwrap()["M_C"][0][0], m_c);
        let script = super::super::export_matlab::matlab_script(&d, "rov", 1);
        assert!(script.contains("model.lpv.coriolis_M = [2720]"), "{script}");
    }

    #[test]
    fn fossen_set_of_an_augmented_model_carries_every_discovered_term() {
        use crate::discrepancy::{Effect, ModelTerm};
        use crate::identification::document::PointAugmentation;
        let mut d = doc();
        let p = &mut d.lpv.as_mut().unwrap().points[0];
        p.load = Some(vec![25.0]);
        p.augmentation = Some(PointAugmentation {
            m_ref: p.m.clone(),
            d_ref: p.d_bar.clone(),
            terms: vec![
                ModelTerm {
                    effect: Effect::QuadraticDamping { dof: Dof::Surge },
                    coefficients: vec![310.0],
                    covariance: vec![vec![100.0]],
                    shape: None,
                    shape_std: None,
                },
                ModelTerm {
                    effect: Effect::Saturation { dof: Dof::Surge },
                    coefficients: vec![],
                    covariance: vec![],
                    shape: Some(450.0),
                    shape_std: Some(12.0),
                },
            ],
        });
        let set = fossen_parameter_set(&d).unwrap();
        let terms = &set.points[0].terms;
        assert_eq!(terms.len(), 2);
        assert_eq!(set.points[0].b, Some(vec![25.0]));
        let json = serde_json::to_value(&set).unwrap();
        let q = &json["points"][0]["terms"][0];
        assert_eq!(q["dof"], "surge");
        assert_eq!(q["effect"]["effect"], "quadratic_damping");
        assert_eq!(q["coefficients"][0]["value"], 310.0);
        assert_eq!(q["coefficients"][0]["std"], 10.0);
        assert_eq!(q["coefficients"][0]["unit"], "N·s²/m²");
        let sat = &json["points"][0]["terms"][1]["shape"];
        assert_eq!(
            (
                sat["name"].as_str(),
                sat["value"].as_f64(),
                sat["std"].as_f64(),
                sat["unit"].as_str()
            ),
            (Some("tau_max"), Some(450.0), Some(12.0), Some("N"))
        );
        assert!(set.equation.contains("terms"));
    }
}
