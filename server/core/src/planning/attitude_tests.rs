//! The Surveyor plan flown through the project's own ROV simulator: roll
//! and pitch excitation stays within its planned attitude, and the
//! λ-filter identification of the flown campaign recovers the truth.

use nalgebra::DMatrix;

use super::dof::Dof;
use super::examples::{surveyor_campaign, surveyor_rov};
use super::statics::static_angle;
use super::{ExperimentFamily, generate_plan};
use crate::estimation::NoProgress;
use crate::identification::{
    LambdaCampaignSettings, RunInput, identify_lambda_campaign, infer_description,
};
use crate::logs::{LogRole, ParseOptions, input_columns, parse_log, to_uniform};
use crate::simulation::rov::RovTruth;
use crate::simulation::trials::{TrialSettings, fly_campaign};
use crate::validation::nrmse_fit;

fn min_eigenvalue(a: &[Vec<f64>]) -> f64 {
    let n = a.len();
    let m = DMatrix::from_fn(n, n, |i, j| 0.5 * (a[i][j] + a[j][i]));
    m.symmetric_eigenvalues().min()
}

/// Every run's largest |φ|, |θ| stays within 1.5 × the planned amplitude
/// A = min(max_angle, 10°) (under the former rate excitation the Surveyor
/// reached 25–45°), a dynamic roll or pitch run still reads as dynamic to
/// `describe`, and the λ-filter identification of the whole flown campaign
/// gives a physical model with roll and pitch inertia and z_G·W − z_B·B
/// close to the truth.
#[test]
fn surveyor_plan_flown_by_the_simulator_stays_near_level_and_identifies() {
    let profile = surveyor_rov();
    let plan = generate_plan(&profile, &surveyor_campaign(7)).unwrap();
    for code in ["DYN-2kn-roll-r1", "REC-2kn-r1", "VAL-r1"] {
        let e = &plan
            .experiments
            .iter()
            .find(|p| p.experiment.code == code)
            .unwrap()
            .experiment;
        eprintln!("{code} ({:.1} s): {}", e.duration_s, e.instruction);
        for c in e.channels.iter().filter(|c| c.excited) {
            eprintln!(
                "  {} ±{:.3} {} {:?} slew {:?}; PE {:?}/{:?}, band {:?}",
                c.column,
                c.amplitude,
                c.unit,
                c.waveform,
                c.rate_limit,
                c.analysis.as_ref().map(|a| a.pe_order),
                c.analysis.as_ref().map(|a| a.pe_required),
                c.analysis.as_ref().and_then(|a| a.band_hz),
            );
        }
        for w in &e.warnings {
            eprintln!("  warning: {w}");
        }
    }
    let truth = RovTruth::surveyor_like();
    let settings = TrialSettings {
        seed: 11,
        ..TrialSettings::default()
    };
    let flown = fly_campaign(&profile, &truth, &plan, &settings, |_| true).unwrap();
    let bound = |d: Dof| 1.5 * static_angle(&profile, d);
    let mut worst = [(0.0_f64, String::new()), (0.0_f64, String::new())];
    let mut violations = Vec::new();
    for f in &flown {
        for (slot, d) in [Dof::Roll, Dof::Pitch].into_iter().enumerate() {
            let peak = f.record.eta_true.column(d.index()).amax();
            if f.family != ExperimentFamily::Static && peak > worst[slot].0 {
                worst[slot] = (peak, f.code.clone());
            }
            if peak > bound(d) {
                violations.push(format!(
                    "{} {}: {:.1}°",
                    f.code,
                    d.name(),
                    peak.to_degrees()
                ));
            }
        }
    }
    eprintln!(
        "largest |φ| {:.1}° ({}), |θ| {:.1}° ({})",
        worst[0].0.to_degrees(),
        worst[0].1,
        worst[1].0.to_degrees(),
        worst[1].1
    );

    let runs: Vec<RunInput> = flown
        .iter()
        .map(|f| {
            let e = &plan
                .experiments
                .iter()
                .find(|p| p.experiment.seq == f.seq)
                .unwrap()
                .experiment;
            let parsed = parse_log(
                f.csv.as_bytes(),
                &ParseOptions::for_vessel(&profile, LogRole::Single, None),
            )
            .unwrap();
            let (record, _) = to_uniform(&parsed.table, None).unwrap();
            RunInput {
                run_id: e.code.clone(),
                name: e.code.clone(),
                family: Some(e.family),
                grid_speed_mps: e.grid_speed_mps,
                excited_dofs: e.dofs.clone(),
                record,
            }
        })
        .collect();
    let inputs = input_columns(&profile);
    let grid = plan.grid_speeds();
    // A dynamic attitude excitation switches many times: the data read it
    // as a dynamic roll or pitch run, not as a static hold (one step).
    for r in runs.iter().filter(|r| {
        r.family == Some(ExperimentFamily::Dynamic)
            && r.excited_dofs
                .iter()
                .any(|d| matches!(d, Dof::Roll | Dof::Pitch))
    }) {
        let d = infer_description(&r.record, &profile, &inputs, &grid).unwrap();
        assert_eq!(
            d.family,
            ExperimentFamily::Dynamic,
            "{}: {}",
            r.run_id,
            d.role_reason
        );
        assert_eq!(
            d.excited_dofs, r.excited_dofs,
            "{}: {}",
            r.run_id, d.excited_dofs_reason
        );
    }
    let out = identify_lambda_campaign(
        &profile,
        &grid,
        &inputs,
        &runs,
        &LambdaCampaignSettings::default(),
        &mut NoProgress,
    )
    .unwrap();
    let doc = &out.document;
    let lpv = doc.lpv.as_ref().unwrap();
    // Projections of the raw estimate onto the physical set, for the record
    // (the stored M and D̄ are checked below); a raw M that is not positive
    // definite would mean the inertia is not determined.
    let not_physical: Vec<&String> = doc
        .structure_findings
        .iter()
        .filter(|f| f.contains("not physical"))
        .collect();
    let restoring = doc.restoring.as_ref().expect("g(η) estimated");
    let bg_true = -truth.restoring.r_b[2] * truth.restoring.buoyancy;
    let bg = restoring.params.zg_weight_minus_zb_buoyancy_nm;
    eprintln!(
        "z_G·W − z_B·B = {bg:.0} N·m (truth {bg_true:.0}); W − B = {:.0} N (truth {:.0})",
        restoring.params.weight_minus_buoyancy_n,
        truth.restoring.weight - truth.restoring.buoyancy
    );
    let mut worst_inertia = 0.0_f64;
    for p in &lpv.points {
        let (m44, m55) = (p.m[3][3], p.m[4][4]);
        let (e44, e55) = (m44 / truth.m[(3, 3)] - 1.0, m55 / truth.m[(4, 4)] - 1.0);
        worst_inertia = worst_inertia.max(e44.abs()).max(e55.abs());
        eprintln!(
            "{:.2} m/s: M44 {m44:.0} ({:+.1} %), M55 {m55:.0} ({:+.1} %), D44 {:.0}, D55 {:.0}; min eig M {:.0}, sym D̄ {:.0}",
            p.speed_mps,
            100.0 * e44,
            100.0 * e55,
            p.d_bar[3][3],
            p.d_bar[4][4],
            min_eigenvalue(&p.m),
            min_eigenvalue(&p.d_bar),
        );
    }
    for f in &not_physical {
        eprintln!("finding: {f}");
    }
    // The validation fits against the measurement-noise ceiling: the fit
    // of the noise-free truth to the logged ν.
    let val = flown
        .iter()
        .find(|f| f.family == ExperimentFamily::Validation)
        .unwrap();
    for (i, ch) in out.validation[0].report.channels.iter().enumerate() {
        let logged: Vec<f64> = val.record.nu.column(i).iter().copied().collect();
        let exact: Vec<f64> = val.record.nu_true.column(i).iter().copied().collect();
        eprintln!(
            "validation {}: 1-step {:.3}, free run {:.3}; noise ceiling {:.3}, std {:.4}",
            ch.output,
            ch.fit_one_step.unwrap_or(f64::NAN),
            ch.fit_simulation.unwrap_or(f64::NAN),
            nrmse_fit(&logged, &exact).unwrap_or(f64::NAN),
            val.record.nu_true.column(i).variance().sqrt(),
        );
    }
    assert!(violations.is_empty(), "beyond 1.5 A: {violations:?}");
    assert!(
        !not_physical.iter().any(|f| f.contains("eigenvalue")),
        "{not_physical:?}"
    );
    for p in &lpv.points {
        assert!(min_eigenvalue(&p.m) > 0.0, "M at {} m/s", p.speed_mps);
        assert!(min_eigenvalue(&p.d_bar) >= 0.0, "D̄ at {} m/s", p.speed_mps);
    }
    assert!(
        (bg - bg_true).abs() < 0.05 * bg_true,
        "z_G·W − z_B·B = {bg:.0}, truth {bg_true:.0}"
    );
    assert!(
        worst_inertia < 0.2,
        "roll/pitch inertia off by {worst_inertia:.2}"
    );
}
