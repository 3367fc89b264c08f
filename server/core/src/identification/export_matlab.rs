//! A model document as a MATLAB/Octave script: running it defines one
//! struct `model` with every matrix of the model, its standard deviations,
//! the inputs and outputs in order, g(η), the logged controller, and the
//! parameter table — what an engineer loads to design an MPC or DP
//! controller without parsing JSON.
//!
//! Numbers are written as the shortest text that reads back as the same
//! f64; non-finite numbers never occur in a stored model, and are written
//! as `NaN` if they did, so the script still runs.

use std::fmt::Write;

use super::document::{Matrix, ModelDocument, to_rows};
use super::lambda_coriolis::document_inertia;

/// A MATLAB string literal ('' escapes a quote; control characters dropped).
fn string(s: &str) -> String {
    let clean: String = s.chars().filter(|c| !c.is_control()).collect();
    format!("'{}'", clean.replace('\'', "''"))
}

/// The shortest text that reads back as the same f64.
fn number(x: f64) -> String {
    if !x.is_finite() {
        "NaN".into()
    } else if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `[a b; c d]`.
fn matrix(m: &Matrix) -> String {
    let rows: Vec<String> = m
        .iter()
        .map(|r| r.iter().map(|x| number(*x)).collect::<Vec<_>>().join(" "))
        .collect();
    format!("[{}]", rows.join("; "))
}

/// A row vector `[a b c]`.
fn vector(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter().map(|x| number(*x)).collect::<Vec<_>>().join(" ")
    )
}

/// A column vector `[a; b; c]`.
fn column(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter().map(|x| number(*x)).collect::<Vec<_>>().join("; ")
    )
}

/// A cell array of strings `{'a', 'b'}`.
fn cell(v: &[String]) -> String {
    format!(
        "{{{}}}",
        v.iter().map(|s| string(s)).collect::<Vec<_>>().join(", ")
    )
}

/// The script for model `name`, version `version`.
pub fn matlab_script(doc: &ModelDocument, name: &str, version: i64) -> String {
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(
        w,
        "% {} v{version} — exported by seatrial",
        name.replace(['\n', '\r'], " ")
    );
    let _ = writeln!(
        w,
        "% Run this script (MATLAB or Octave) to define the struct `model`."
    );
    let _ = writeln!(
        w,
        "% SI units: N, N·m, m/s, rad/s, kg, kg·m²; angles in rad."
    );
    let _ = writeln!(w, "model = struct();");
    let _ = writeln!(w, "model.name = {};", string(name));
    let _ = writeln!(w, "model.version = {version};");
    let _ = writeln!(w, "model.method = {};", string(doc.method.name()));
    let dofs: Vec<String> = doc.dofs.iter().map(|d| d.name().to_string()).collect();
    let _ = writeln!(
        w,
        "model.dofs = {};  % row/column order of every matrix",
        cell(&dofs)
    );
    let _ = writeln!(w, "model.inputs = {};", cell(&doc.inputs));
    let _ = writeln!(w, "model.outputs = {};", cell(&doc.outputs));
    if let Some(r) = &doc.restoring {
        let p = &r.params;
        let _ = writeln!(
            w,
            "% g(eta): lumped restoring, g = [(W-B) sin(theta); -(W-B) cos(theta) sin(phi); -(W-B) cos(theta) cos(phi); (zG W - zB B) cos(theta) sin(phi); (zG W - zB B) sin(theta); 0]"
        );
        let _ = writeln!(
            w,
            "model.restoring.W_minus_B = {};  % N",
            number(p.weight_minus_buoyancy_n)
        );
        let _ = writeln!(
            w,
            "model.restoring.zG_W_minus_zB_B = {};  % N·m",
            number(p.zg_weight_minus_zb_buoyancy_nm)
        );
        let _ = writeln!(
            w,
            "model.restoring.tether_pitch_moment = {};  % N·m",
            number(p.tether_pitch_moment_nm)
        );
    }
    if let Some(l) = &doc.lpv {
        let _ = writeln!(
            w,
            "% LPV on forward speed u: at grid speed i, M(:,:,i) nu_dot + Dbar(:,:,i) nu + b(:,i) = tau - g(eta)"
        );
        let _ = writeln!(
            w,
            "% (nu_dot = A nu + B (tau - g(eta) - b)); between grid points interpolate or take the nearest."
        );
        let m_c = l
            .coriolis_second_order
            .then(|| document_inertia(l))
            .flatten();
        if l.coriolis_second_order {
            let _ = writeln!(
                w,
                "% Second-order Coriolis: add C(d)*d to the left-hand side, with d = nu but u = 0 and C from {} (Fossen 2011, eq. 6.43):",
                if m_c.is_some() {
                    "model.lpv.coriolis_M, the vehicle's M pooled over the grid points by inverse variance"
                } else {
                    "M(:,:,i)"
                }
            );
            let _ = writeln!(
                w,
                "% C = [zeros(3), -S(M11*d1 + M12*d2); -S(M11*d1 + M12*d2), -S(M21*d1 + M22*d2)], S(a)*b = cross(a, b), d1 = d(1:3), d2 = d(4:6)."
            );
        }
        let _ = writeln!(
            w,
            "model.lpv.coriolis_second_order = {};",
            if l.coriolis_second_order {
                "true"
            } else {
                "false"
            }
        );
        if let Some(m) = &m_c {
            let _ = writeln!(
                w,
                "model.lpv.coriolis_M = {};  % kg, kg*m, kg*m^2",
                matrix(&to_rows(m))
            );
        }
        if let Some(d) = &l.quadratic_damping {
            let _ = writeln!(
                w,
                "% Quadratic damping: add Dq .* abs(d) .* d to the left-hand side, d = nu but u = 0 (one Dq for every grid speed)."
            );
            let _ = writeln!(
                w,
                "model.lpv.quadratic_damping = {};  % N*s^2/m^2 (linear DOFs), N*m*s^2/rad^2 (rotations)",
                vector(d)
            );
        }
        let _ = writeln!(w, "model.lpv.t_lambda_s = {};", number(l.t_lambda_s));
        let _ = writeln!(w, "model.lpv.structure = {};", string(&l.structure));
        let speeds: Vec<f64> = l.points.iter().map(|p| p.speed_mps).collect();
        let _ = writeln!(w, "model.lpv.speeds_mps = {};", vector(&speeds));
        if let (Some(e), Some(&lo), Some(&hi)) = (l.extension, speeds.first(), speeds.last()) {
            let _ = writeln!(w, "% {}", e.describe(lo, hi));
            let _ = writeln!(
                w,
                "model.lpv.extension_mps = {};",
                vector(&[e.from_mps, e.to_mps])
            );
        }
        for (i, p) in l.points.iter().enumerate() {
            let k = i + 1;
            for (field, m) in [
                ("M", &p.m),
                ("M_std", &p.m_std),
                ("Dbar", &p.d_bar),
                ("Dbar_std", &p.d_bar_std),
                ("A", &p.a),
                ("A_std", &p.a_std),
                ("B", &p.b),
                ("B_std", &p.b_std),
            ] {
                let _ = writeln!(w, "model.lpv.{field}(:,:,{k}) = {};", matrix(m));
            }
            let n = p.m.len();
            let load = p.load.clone().unwrap_or_else(|| vec![0.0; n]);
            let _ = writeln!(w, "model.lpv.b(:,{k}) = {};", column(&load));
        }
        if let Some(c) = &l.logged_controller {
            let _ = writeln!(
                w,
                "% The logs were made by a controller faster than the log: predictions on those logs use M - c*K_nu and Dbar - c*K_eta*J."
            );
            let _ = writeln!(
                w,
                "model.lpv.logged_controller.rate_hz = {};",
                number(c.rate_hz)
            );
            let _ = writeln!(
                w,
                "model.lpv.logged_controller.log_h_s = {};",
                number(c.log_h_s)
            );
            let _ = writeln!(w, "model.lpv.logged_controller.c_s = {};", number(c.c_s));
            let _ = writeln!(w, "model.lpv.logged_controller.K_nu = {};", matrix(&c.k_nu));
            let _ = writeln!(
                w,
                "model.lpv.logged_controller.K_eta = {};  % columns: phi, theta",
                matrix(&c.k_attitude)
            );
        }
    }
    if let Some(ss) = &doc.state_space {
        let _ = writeln!(
            w,
            "% Innovation form, sample time h: x(k+1) = Phi x(k) + Gamma (u(k) - u0) + K e(k), y(k) = C x(k) + D (u(k) - u0) + e(k)"
        );
        let _ = writeln!(w, "model.ss.h = {};", number(ss.h));
        let _ = writeln!(w, "model.ss.order = {};", ss.order);
        for (field, m) in [
            ("Phi", &ss.phi),
            ("Gamma", &ss.gamma),
            ("C", &ss.c),
            ("D", &ss.d),
            ("K", &ss.k),
        ] {
            let _ = writeln!(w, "model.ss.{field} = {};", matrix(m));
        }
        if let Some(a) = &ss.a_continuous {
            let _ = writeln!(w, "model.ss.A = {};", matrix(a));
        }
        if let Some(b) = &ss.b_continuous {
            let _ = writeln!(w, "model.ss.B = {};", matrix(b));
        }
        let _ = writeln!(w, "model.ss.u0 = {};", column(&ss.u_offset));
        let _ = writeln!(
            w,
            "model.ss.singular_values = {};",
            vector(&ss.singular_values)
        );
    }
    if let Some(dp) = &doc.dp_ship {
        let _ = writeln!(
            w,
            "% DP ship in Bis units ({}; L = {} m, time unit {} s): M'' nu_dot + D'' nu = T'' K'' u",
            dp.units.replace(['\n', '\r'], " "),
            number(dp.length_m),
            number(dp.time_unit_s)
        );
        for (field, m) in [
            ("M", &dp.m),
            ("T", &dp.t_config),
            ("A_h", &dp.a_h),
            ("A_h_std", &dp.a_h_std),
            ("D", &dp.d),
            ("A", &dp.a),
            ("B", &dp.b),
            ("A_si", &dp.a_si),
            ("B_si", &dp.b_si),
        ] {
            let _ = writeln!(w, "model.dp.{field} = {};", matrix(m));
        }
        let _ = writeln!(w, "model.dp.K = {};", vector(&dp.k));
        let _ = writeln!(w, "model.dp.K_std = {};", vector(&dp.k_std));
        let _ = writeln!(w, "model.dp.theta = {};", vector(&dp.theta));
        let _ = writeln!(w, "model.dp.theta_std = {};", vector(&dp.theta_std));
    }
    let _ = writeln!(
        w,
        "% Every estimated parameter: group, symbol, grid speed (NaN: none), value, std (NaN: none), unit."
    );
    let _ = writeln!(
        w,
        "model.parameters = struct('group', {{}}, 'symbol', {{}}, 'grid_speed_mps', {{}}, 'value', {{}}, 'std', {{}}, 'unit', {{}});"
    );
    for (i, p) in doc.parameters.iter().enumerate() {
        let _ = writeln!(
            w,
            "model.parameters({}) = struct('group', {}, 'symbol', {}, 'grid_speed_mps', {}, 'value', {}, 'std', {}, 'unit', {});",
            i + 1,
            string(&p.group),
            string(&p.symbol),
            p.grid_speed_mps.map_or("NaN".into(), number),
            number(p.value),
            p.std.map_or("NaN".into(), number),
            string(&p.unit)
        );
    }
    let notes: Vec<String> = doc
        .structure_findings
        .iter()
        .chain(&doc.notes)
        .cloned()
        .collect();
    let _ = writeln!(w, "model.notes = {};", cell(&notes));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::restoring::RestoringParams;
    use crate::identification::document::{
        LoggedController, ParameterRow, RestoringDoc, SpeedExtension,
    };
    use crate::identification::tests::lpv_doc;
    use crate::planning::dof::Dof;

    fn doc() -> ModelDocument {
        let m = vec![vec![512.25, -3.5e-7], vec![-3.5e-7, 61.0]];
        let d = |u: f64| vec![vec![100.0 * u, 0.0], vec![1e-300, 25.0]];
        let mut doc = lpv_doc(
            vec![Dof::Surge, Dof::Yaw],
            vec![(0.5, m.clone(), d(0.5)), (1.5, m, d(1.5))],
        );
        doc.inputs = vec!["tau_X".into(), "tau_N".into()];
        doc.outputs = vec!["u".into(), "r".into()];
        doc.restoring = Some(RestoringDoc {
            parameters: vec![],
            evidence: vec![],
            params: RestoringParams {
                weight_minus_buoyancy_n: 67.5,
                zg_weight_minus_zb_buoyancy_nm: 275.25,
                tether_pitch_moment_nm: 0.0,
            },
        });
        let lpv = doc.lpv.as_mut().unwrap();
        for p in &mut lpv.points {
            p.m_std = vec![vec![2.0, 0.1], vec![0.1, 0.5]];
            p.b_std = vec![vec![1e-5; 2]; 2];
            p.load = Some(vec![3.0, -0.25]);
            p.load_std = Some(vec![0.1, 0.01]);
        }
        lpv.logged_controller = Some(LoggedController {
            rate_hz: 20.0,
            log_h_s: 0.1,
            c_s: 0.025,
            k_nu: vec![vec![-400.0, 0.0], vec![0.0, -60.0]],
            k_attitude: vec![vec![0.0; 2]; 2],
        });
        doc.parameters = vec![ParameterRow {
            group: "M".into(),
            symbol: "M[surge,surge]".into(),
            grid_speed_mps: Some(0.5),
            value: 512.25,
            std: None,
            unit: "kg".into(),
        }];
        doc.lpv.as_mut().unwrap().extension = Some(SpeedExtension {
            from_mps: 0.2,
            to_mps: 1.5,
        });
        doc.notes = vec!["the pilot's note: it's fine".into()];
        doc
    }

    /// Reads `name = [..; ..];` back into rows of numbers.
    fn read_matrix(script: &str, prefix: &str) -> Vec<Vec<f64>> {
        let line = script
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no {prefix} in\n{script}"));
        let inner = &line[line.find('[').unwrap() + 1..line.rfind(']').unwrap()];
        inner
            .split(';')
            .map(|r| r.split_whitespace().map(|x| x.parse().unwrap()).collect())
            .collect()
    }

    #[test]
    fn every_matrix_reads_back_exactly_and_strings_are_quoted() {
        let d = doc();
        let s = matlab_script(&d, "Surveyor 'A'", 3);
        let lpv = d.lpv.as_ref().unwrap();
        for (k, p) in lpv.points.iter().enumerate() {
            for (field, m) in [
                ("M", &p.m),
                ("Dbar", &p.d_bar),
                ("A", &p.a),
                ("B_std", &p.b_std),
            ] {
                let prefix = format!("model.lpv.{field}(:,:,{}) =", k + 1);
                assert_eq!(&read_matrix(&s, &prefix), m, "{prefix}");
            }
        }
        assert_eq!(
            read_matrix(&s, "model.lpv.speeds_mps ="),
            vec![vec![0.5, 1.5]]
        );
        // The extension below the grid, in numbers and in words.
        assert_eq!(
            read_matrix(&s, "model.lpv.extension_mps ="),
            vec![vec![0.2, 1.5]]
        );
        assert!(
            s.contains("% Beyond the grid the model extrapolates below 0.50 m/s down to 0.20 m/s"),
            "{s}"
        );
        assert_eq!(
            read_matrix(&s, "model.lpv.b(:,2) ="),
            vec![vec![3.0], vec![-0.25]]
        );
        assert_eq!(
            read_matrix(&s, "model.lpv.logged_controller.K_nu ="),
            vec![vec![-400.0, 0.0], vec![0.0, -60.0]]
        );
        assert!(s.contains("model.restoring.W_minus_B = 67.5;"));
        assert!(s.contains("model.name = 'Surveyor ''A''';"));
        assert!(s.contains("model.dofs = {'surge', 'yaw'};"));
        assert!(s.contains("'std', NaN, 'unit', 'kg');"));
        assert!(s.contains("model.notes = {'the pilot''s note: it''s fine'};"));
        assert!(!s.to_lowercase().contains("inf"));
        // One statement per line: brackets and quotes close on their line.
        for l in s.lines().filter(|l| !l.starts_with('%')) {
            let code = l.split("  %").next().unwrap();
            assert_eq!(code.matches('[').count(), code.matches(']').count(), "{l}");
            assert_eq!(code.matches('\'').count() % 2, 0, "{l}");
        }
    }
}
