//! A model as NumPy arrays (`numpy.load("model.npz")`): every matrix of the
//! document stacked over the LPV grid speeds, their standard deviations,
//! the loads, g(η), names and units as string arrays, the continuous A, B
//! and their ZOH discretization A_d, B_d at sample time `h`, and a JSON
//! `metadata` string with the rest (name, version, equations, discovered
//! terms, notes). Array names are listed in the README.

use serde_json::json;

use super::discrete::discretize;
use super::document::{Matrix, ModelDocument, ModelKind};
use super::export_state_space::state_space_export;
use super::export_terms::model_terms;
use super::npz::{NpyArray, npz_bytes};

fn names(ch: &[super::export_state_space::Channel]) -> (Vec<String>, Vec<String>) {
    ch.iter().map(|c| (c.name.clone(), c.unit.clone())).unzip()
}

/// The arrays of `doc` (model `name`, `version`), with A_d, B_d at `h` (s;
/// for an N4SID model `h` must be its own sample time, and A, B are
/// already discrete).
pub fn npz_arrays(
    doc: &ModelDocument,
    name: &str,
    version: i64,
    h: f64,
) -> Result<Vec<NpyArray>, String> {
    let ss = state_space_export(doc, name, version, None)?;
    let zoh = discretize(doc, h)?;
    let mut out = Vec::new();
    let (state_names, state_units) = names(&ss.states);
    let (input_names, input_units) = names(&ss.inputs);
    let (output_names, output_units) = names(&ss.outputs);
    let dofs: Vec<String> = doc.dofs.iter().map(|d| d.name().to_string()).collect();
    out.push(NpyArray::strings("dofs", &dofs));
    out.push(NpyArray::strings("state_names", &state_names));
    out.push(NpyArray::strings("state_units", &state_units));
    out.push(NpyArray::strings("input_names", &input_names));
    out.push(NpyArray::strings("input_units", &input_units));
    out.push(NpyArray::strings("output_names", &output_names));
    out.push(NpyArray::strings("output_units", &output_units));
    out.push(NpyArray::scalar("h", h));
    let stack = |name: &str, f: &dyn Fn(usize) -> Matrix, n: usize| {
        NpyArray::stack(name, &(0..n).map(f).collect::<Vec<_>>())
    };
    let p = zoh.points.len();
    out.push(stack("Ad", &|i| zoh.points[i].phi.clone(), p)?);
    out.push(stack("Bd", &|i| zoh.points[i].gamma.clone(), p)?);
    match doc.kind {
        ModelKind::Lpv => {
            let lpv = doc.lpv.as_ref().ok_or("the LPV model has no grid points")?;
            let pts = &lpv.points;
            let n = doc.dofs.len();
            let speeds: Vec<f64> = pts.iter().map(|p| p.speed_mps).collect();
            out.push(NpyArray::f64("grid_speeds_mps", vec![speeds.len()], speeds));
            out.push(NpyArray::scalar("t_lambda_s", lpv.t_lambda_s));
            for (key, get) in [
                ("M", (|p| &p.m) as fn(&super::document::LpvPoint) -> &Matrix),
                ("M_std", |p| &p.m_std),
                ("Dbar", |p| &p.d_bar),
                ("Dbar_std", |p| &p.d_bar_std),
                ("A", |p| &p.a),
                ("A_std", |p| &p.a_std),
                ("B", |p| &p.b),
                ("B_std", |p| &p.b_std),
            ] {
                out.push(stack(key, &|i| get(&pts[i]).clone(), pts.len())?);
            }
            let zero = vec![0.0; n];
            let loads: Vec<Vec<f64>> = pts
                .iter()
                .map(|p| p.load.clone().unwrap_or_else(|| zero.clone()))
                .collect();
            let load_std: Vec<Vec<f64>> = pts
                .iter()
                .map(|p| p.load_std.clone().unwrap_or_else(|| zero.clone()))
                .collect();
            out.push(NpyArray::rows("b", &loads)?);
            out.push(NpyArray::rows("b_std", &load_std)?);
            if let Some(c) = &lpv.logged_controller {
                out.push(NpyArray::matrix("controller_K_nu", &c.k_nu)?);
                out.push(NpyArray::matrix("controller_K_eta", &c.k_attitude)?);
                out.push(NpyArray::scalar("controller_c_s", c.c_s));
                out.push(NpyArray::scalar("controller_rate_hz", c.rate_hz));
            }
        }
        ModelKind::DpShip => {
            let s = doc.dp_ship.as_ref().ok_or("the DP model is missing")?;
            out.push(NpyArray::matrix("A", &s.a_si)?);
            out.push(NpyArray::matrix("B", &s.b_si)?);
            for (key, m) in [
                ("M_bis", &s.m),
                ("T_bis", &s.t_config),
                ("A_h_bis", &s.a_h),
                ("A_h_std_bis", &s.a_h_std),
                ("D_bis", &s.d),
                ("A_bis", &s.a),
                ("B_bis", &s.b),
            ] {
                out.push(NpyArray::matrix(key, m)?);
            }
            for (key, v) in [
                ("K_bis", &s.k),
                ("K_std_bis", &s.k_std),
                ("theta_bis", &s.theta),
                ("theta_std_bis", &s.theta_std),
            ] {
                out.push(NpyArray::f64(key, vec![v.len()], v.clone()));
            }
            out.push(NpyArray::scalar("length_m", s.length_m));
            out.push(NpyArray::scalar("time_unit_s", s.time_unit_s));
        }
        ModelKind::StateSpace => {
            let s = doc
                .state_space
                .as_ref()
                .ok_or("the state-space model is missing")?;
            for (key, m) in [
                ("A", &s.phi),
                ("B", &s.gamma),
                ("C", &s.c),
                ("D", &s.d),
                ("K", &s.k),
            ] {
                out.push(NpyArray::matrix(key, m)?);
            }
            out.push(NpyArray::f64(
                "u0",
                vec![s.u_offset.len()],
                s.u_offset.clone(),
            ));
            out.push(NpyArray::f64(
                "y0",
                vec![s.y_offset.len()],
                s.y_offset.clone(),
            ));
            out.push(NpyArray::f64(
                "singular_values",
                vec![s.singular_values.len()],
                s.singular_values.clone(),
            ));
            if let (Some(a), Some(b)) = (&s.a_continuous, &s.b_continuous) {
                out.push(NpyArray::matrix("A_continuous", a)?);
                out.push(NpyArray::matrix("B_continuous", b)?);
            }
        }
    }
    if let Some(r) = &doc.restoring {
        let g = &r.params;
        out.push(NpyArray::strings(
            "g_names",
            &[
                "W_minus_B".into(),
                "zG_W_minus_zB_B".into(),
                "tether_pitch_moment".into(),
            ],
        ));
        out.push(NpyArray::f64(
            "g_values",
            vec![3],
            vec![
                g.weight_minus_buoyancy_n,
                g.zg_weight_minus_zb_buoyancy_nm,
                g.tether_pitch_moment_nm,
            ],
        ));
        out.push(NpyArray::strings(
            "g_units",
            &["N".into(), "N·m".into(), "N·m".into()],
        ));
    }
    let terms: Vec<serde_json::Value> = model_terms(doc)
        .into_iter()
        .map(|(speed, terms)| json!({ "grid_speed_mps": speed, "terms": terms }))
        .collect();
    let metadata = json!({
        "format": "seatrial-npz/1",
        "name": name,
        "version": version,
        "kind": doc.kind,
        "method": doc.method.name(),
        "equations": ss.equations,
        "sample_time_s": ss.sample_time_s,
        "h": h,
        "restoring": doc.restoring.as_ref().map(|r| &r.parameters),
        "terms": terms,
        "notes": ss.notes.iter().chain(&doc.notes).collect::<Vec<_>>(),
    });
    out.push(NpyArray::text("metadata", &metadata.to_string()));
    Ok(out)
}

/// The `.npz` file of `doc` (see [`npz_arrays`]).
pub fn npz_export(
    doc: &ModelDocument,
    name: &str,
    version: i64,
    h: f64,
) -> Result<Vec<u8>, String> {
    npz_bytes(&npz_arrays(doc, name, version, h)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::npz::{NpyData, read_npz};
    use crate::identification::tests::surge_pitch_doc;

    #[test]
    fn lpv_arrays_read_back_equal_to_the_document() {
        let mut doc = surge_pitch_doc();
        doc.lpv.as_mut().unwrap().points[1].load = Some(vec![3.0, -0.25]);
        let back = read_npz(&npz_export(&doc, "Ærø", 3, 0.1).unwrap()).unwrap();
        let get = |k: &str| {
            back.iter()
                .find(|a| a.name == k)
                .unwrap_or_else(|| panic!("{k}"))
        };
        let flat = |k: &str| match &get(k).data {
            NpyData::F64(v) => v.clone(),
            NpyData::Str(_) => panic!("{k} is text"),
        };
        let lpv = doc.lpv.as_ref().unwrap();
        assert_eq!(get("M").shape, vec![2, 2, 2]);
        let m: Vec<f64> = lpv
            .points
            .iter()
            .flat_map(|p| p.m.iter().flatten().copied())
            .collect();
        assert_eq!(flat("M"), m);
        let a: Vec<f64> = lpv
            .points
            .iter()
            .flat_map(|p| p.a.iter().flatten().copied())
            .collect();
        assert_eq!(flat("A"), a);
        assert_eq!(flat("b"), vec![0.0, 0.0, 3.0, -0.25]);
        assert_eq!(flat("grid_speeds_mps"), vec![0.5, 1.0]);
        let zoh = discretize(&doc, 0.1).unwrap();
        assert_eq!(flat("Ad")[4..8], zoh.points[1].phi.concat()[..]);
        assert_eq!(
            get("state_names").data,
            NpyData::Str(vec!["u".into(), "q".into()])
        );
        assert_eq!(
            get("input_units").data,
            NpyData::Str(vec!["N".into(), "N·m".into()])
        );
        let NpyData::Str(meta) = &get("metadata").data else {
            panic!()
        };
        let meta: serde_json::Value = serde_json::from_str(&meta[0]).unwrap();
        assert_eq!(
            (meta["name"].as_str(), meta["version"].as_i64()),
            (Some("Ærø"), Some(3))
        );
    }
}
