//! Thruster logs as loggers record them: the column `thr_j` may carry the
//! propeller's shaft speed, pitch or measured thrust instead of the command
//! u_j of τ = T K u, and an azimuth may log its angle α_j (`azi_j`);
//! [`read_thruster_commands`] turns them into the commanded inputs (see
//! [`ThrusterSignal`], [`commanded_inputs`]) before anything reads the
//! record.

use crate::planning::vessel::{InputChannels, ThrusterSignal, VesselKind, VesselProfile};
use crate::timeseries::UniformRecord;

use super::schema::{azimuth_angle_column, input_columns, thruster_column};

/// One input of τ = Σ_c T_c·K_{g(c)}·u_c as identification regresses on it:
/// a thruster's command `thr_j`, or an azimuth with a logged angle split
/// into its body-axis components `thr_j_x` = u_j cos α_j and `thr_j_y` =
/// u_j sin α_j, whose columns of T″ are then fixed: (1, 0, −l_y/L) and
/// (0, 1, l_x/L).
#[derive(Debug, Clone, PartialEq)]
pub struct CommandedInput {
    /// Record column.
    pub column: String,
    /// Its column of T (one entry per modeled DOF; T″ of a DP vessel).
    pub t: Vec<f64>,
    /// The thruster it belongs to (0-based), for its thrust coefficient.
    pub thruster: usize,
}

/// Derived column of the body-x component of azimuth `i` (from 1).
pub fn azimuth_x_column(i: usize) -> String {
    format!("thr_{i}_x")
}

/// Derived column of the body-y component of azimuth `i` (from 1).
pub fn azimuth_y_column(i: usize) -> String {
    format!("thr_{i}_y")
}

/// The commanded inputs of a thruster-actuated profile, in thruster order
/// (an azimuth with a logged angle gives two); empty for a vessel logging
/// τ. Only for a validated profile (a logged angle implies a DP vessel
/// with its length).
pub fn commanded_inputs(vessel: &VesselProfile) -> Vec<CommandedInput> {
    let InputChannels::Thrusters {
        thrusters,
        configuration,
    } = &vessel.inputs
    else {
        return Vec::new();
    };
    let length = vessel
        .dp_prior
        .as_ref()
        .filter(|_| vessel.kind == VesselKind::Dp3)
        .map(|p| p.length_m);
    let mut out = Vec::new();
    for (j, th) in thrusters.iter().enumerate() {
        match (th.logged_angle, length) {
            (Some(a), Some(l)) => {
                out.push(CommandedInput {
                    column: azimuth_x_column(j + 1),
                    t: a.column(0.0, l).to_vec(),
                    thruster: j,
                });
                out.push(CommandedInput {
                    column: azimuth_y_column(j + 1),
                    t: a.column(std::f64::consts::FRAC_PI_2, l).to_vec(),
                    thruster: j,
                });
            }
            _ => out.push(CommandedInput {
                column: thruster_column(j + 1),
                t: configuration.iter().map(|r| r[j]).collect(),
                thruster: j,
            }),
        }
    }
    out
}

/// The record columns identification reads as inputs: the commanded
/// inputs' columns, or `tau_*` of a vessel logging τ.
pub fn commanded_columns(vessel: &VesselProfile) -> Vec<String> {
    match &vessel.inputs {
        InputChannels::GeneralizedForces => input_columns(vessel),
        InputChannels::Thrusters { .. } => commanded_inputs(vessel)
            .into_iter()
            .map(|c| c.column)
            .collect(),
    }
}

/// A command beyond this multiple of the thruster's `max_command` is not a
/// command: most likely shaft speed or pitch logged undeclared.
const NOT_A_COMMAND: f64 = 3.0;

/// What [`read_thruster_commands`] read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ThrusterReading {
    /// What was converted, e.g. "thr_1 (port main propeller) logged as
    /// shaft speed n (rpm), u = |n|·n/(180 rpm)²: read as the thruster
    /// command u of τ = T·K·u"; `None` when every thruster logs its command.
    pub note: Option<String>,
    /// Command columns far beyond their thruster's `max_command`, each with
    /// what to declare.
    pub warnings: Vec<(String, String)>,
}

/// Replaces each thruster column of `rec` that the profile says is not a
/// command by the command u_j = f(logged value) (NaN stays NaN), and says
/// what was read; warns about a column declared a command whose values
/// reach [`NOT_A_COMMAND`] × `max_command`. A column the record lacks is
/// left to the required-column checks.
pub fn read_thruster_commands(vessel: &VesselProfile, rec: &mut UniformRecord) -> ThrusterReading {
    let mut read = Vec::new();
    let mut warnings = Vec::new();
    for (j, th) in vessel.thrusters().iter().enumerate() {
        let name = thruster_column(j + 1);
        let Some(k) = rec.names.iter().position(|n| *n == name) else {
            continue;
        };
        let Some(how) = th.signal.describe() else {
            let peak = rec.data[k]
                .iter()
                .filter(|x| x.is_finite())
                .fold(0.0f64, |m, x| m.max(x.abs()));
            if peak > NOT_A_COMMAND * th.max_command {
                warnings.push((
                    name.clone(),
                    format!(
                        "{name} ({}) reaches {} where its commands stay within ±{}: if the \
                         logger records shaft speed, pitch or thrust, declare the thruster's \
                         signal in the vessel profile (it is read as the command u as logged)",
                        th.name,
                        crate::numbers::sig3(peak),
                        crate::numbers::sig3(th.max_command)
                    ),
                ));
            }
            continue;
        };
        let signal: ThrusterSignal = th.signal;
        for x in &mut rec.data[k] {
            *x = signal.command(*x);
        }
        read.push(format!("{name} ({}) logged as {how}", th.name));
    }
    for (j, th) in vessel.thrusters().iter().enumerate() {
        let Some(a) = th.logged_angle else { continue };
        let (Some(u), Some(alpha)) = (
            rec.column(&thruster_column(j + 1)),
            rec.column(&azimuth_angle_column(j + 1)),
        ) else {
            continue;
        };
        let scale = a.unit.radians();
        let (x, y): (Vec<f64>, Vec<f64>) = u
            .iter()
            .zip(alpha)
            .map(|(u, a)| {
                let (s, c) = (a * scale).sin_cos();
                (u * c, u * s)
            })
            .unzip();
        rec.names.push(azimuth_x_column(j + 1));
        rec.data.push(x);
        rec.names.push(azimuth_y_column(j + 1));
        rec.data.push(y);
        read.push(format!(
            "{} ({}) turned as logged in {} ({}): split into {} = u cos α and {} = u sin α",
            thruster_column(j + 1),
            th.name,
            azimuth_angle_column(j + 1),
            a.unit.symbol(),
            azimuth_x_column(j + 1),
            azimuth_y_column(j + 1)
        ));
    }
    ThrusterReading {
        note: (!read.is_empty()).then(|| {
            format!(
                "{}: read as the thruster command u of τ = T·K·u",
                read.join("; ")
            )
        }),
        warnings,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::supply_vessel;
    use crate::planning::vessel::InputChannels;

    fn record(columns: &[(&str, Vec<f64>)]) -> UniformRecord {
        UniformRecord {
            sample_rate_hz: 1.0,
            t0: 0.0,
            names: columns.iter().map(|(n, _)| n.to_string()).collect(),
            data: columns.iter().map(|(_, v)| v.clone()).collect(),
            valid: std::iter::once(0..columns[0].1.len()).collect(),
        }
    }

    #[test]
    fn logged_speed_pitch_and_thrust_become_commands() {
        let mut v = supply_vessel();
        let InputChannels::Thrusters { thrusters, .. } = &mut v.inputs else {
            unreachable!()
        };
        thrusters[0].signal = ThrusterSignal::ShaftSpeed { rated_rpm: 200.0 };
        thrusters[2].signal = ThrusterSignal::Pitch {
            zero_thrust: 5.0,
            full_ahead: 85.0,
        };
        thrusters[4].signal = ThrusterSignal::Thrust { rated_n: 1.5e5 };
        v.validate().unwrap();
        let mut rec = record(&[
            ("t", vec![0.0, 1.0, 2.0]),
            ("thr_1", vec![100.0, -200.0, f64::NAN]),
            ("thr_2", vec![0.3, -0.2, 0.1]),
            ("thr_3", vec![45.0, 5.0, -35.0]),
            ("thr_5", vec![7.5e4, -1.5e5, 0.0]),
        ]);
        let reading = read_thruster_commands(&v, &mut rec);
        assert!(reading.warnings.is_empty());
        let note = reading.note.unwrap();
        // u = |n|n/n_rated²: 100 rpm of 200 is a quarter of full thrust.
        assert_eq!(&rec.data[1][..2], &[0.25, -1.0]);
        assert!(rec.data[1][2].is_nan());
        // Commands stay as logged.
        assert_eq!(rec.data[2], vec![0.3, -0.2, 0.1]);
        // (p − p₀)|p − p₀|/(p_full − p₀)²: 40/80 → 0.25, p₀ → 0, −40/80 → −0.25.
        assert_eq!(rec.data[3], vec![0.25, 0.0, -0.25]);
        assert_eq!(rec.data[4], vec![0.5, -1.0, 0.0]);
        assert!(note.contains("thr_1 (port main propeller) logged as shaft speed n (rpm)"));
        assert!(note.contains("thr_3") && note.contains("thr_5") && !note.contains("thr_2"));

        let mut plain = record(&[("t", vec![0.0]), ("thr_1", vec![0.5])]);
        assert_eq!(
            read_thruster_commands(&supply_vessel(), &mut plain),
            ThrusterReading::default()
        );
        assert_eq!(plain.data[1], vec![0.5]);

        // Shaft speed logged but not declared: kept, and said so.
        let mut rpm = record(&[("t", vec![0.0, 1.0]), ("thr_2", vec![150.0, -160.0])]);
        let reading = read_thruster_commands(&supply_vessel(), &mut rpm);
        assert_eq!(rpm.data[1], vec![150.0, -160.0]);
        assert_eq!(reading.note, None);
        assert_eq!(reading.warnings.len(), 1);
        let (column, message) = &reading.warnings[0];
        assert_eq!(column, "thr_2");
        assert!(
            message.contains("reaches 160") && message.contains("declare"),
            "{message}"
        );
    }

    /// An azimuth logging its angle in degrees: u split into u cos α and
    /// u sin α, T″ columns (1, 0, −y/L) and (0, 1, x/L); its configuration
    /// column must be T″ at some angle from its position.
    #[test]
    fn a_turning_azimuth_is_split_into_body_components() {
        use crate::planning::vessel::{HeadingUnit, LoggedAngle};
        let mut v = supply_vessel();
        let l = v.dp_prior.as_ref().unwrap().length_m;
        let (x, y) = (30.0, -2.0);
        let InputChannels::Thrusters {
            thrusters,
            configuration,
        } = &mut v.inputs
        else {
            unreachable!()
        };
        // The bow azimuth (thr_6), planned at 90°: column (0, 1, x/L).
        for (r, value) in configuration.iter_mut().zip([0.0, 1.0, x / l]) {
            r[5] = value;
        }
        thrusters[5].logged_angle = Some(LoggedAngle {
            unit: HeadingUnit::Deg,
            x_m: x,
            y_m: y,
        });
        v.validate().unwrap();
        let inputs = commanded_inputs(&v);
        let cols: Vec<&str> = inputs.iter().map(|c| c.column.as_str()).collect();
        assert_eq!(
            cols,
            [
                "thr_1", "thr_2", "thr_3", "thr_4", "thr_5", "thr_6_x", "thr_6_y"
            ]
        );
        assert_eq!(inputs[5].t, vec![1.0, 0.0, -y / l]);
        assert!((inputs[6].t[0]).abs() < 1e-15 && inputs[6].t[1] == 1.0);
        assert!((inputs[6].t[2] - x / l).abs() < 1e-15);
        assert_eq!(inputs[6].thruster, 5);
        assert_eq!(
            crate::logs::schema::required_columns(&v, crate::logs::LogRole::Single, None)
                .iter()
                .filter(|c| c.starts_with("azi_"))
                .collect::<Vec<_>>(),
            ["azi_6"]
        );

        let mut rec = record(&[
            ("t", vec![0.0, 1.0]),
            ("thr_6", vec![0.5, -1.0]),
            ("azi_6", vec![60.0, -90.0]),
        ]);
        let note = read_thruster_commands(&v, &mut rec).note.unwrap();
        assert!(
            note.contains("thr_6 (bow azimuth thruster) turned as logged in azi_6 (°)"),
            "{note}"
        );
        let x_col = rec.column("thr_6_x").unwrap();
        let y_col = rec.column("thr_6_y").unwrap();
        assert!(
            (x_col[0] - 0.25).abs() < 1e-15 && (y_col[0] - 0.5 * 3f64.sqrt() / 2.0).abs() < 1e-15
        );
        assert!(x_col[1].abs() < 1e-15 && (y_col[1] - 1.0).abs() < 1e-15);
        // Σ T″_c u_c over the components is T″(α)·u.
        let alpha = 60f64.to_radians();
        let want = [
            alpha.cos(),
            alpha.sin(),
            (x * alpha.sin() - y * alpha.cos()) / l,
        ];
        for (i, w) in want.iter().enumerate() {
            let got = inputs[5].t[i] * x_col[0] + inputs[6].t[i] * y_col[0];
            assert!((got - 0.5 * w).abs() < 1e-15, "row {i}");
        }

        // A column that is no direction at the position, a tunnel, no L.
        let mut bad = v.clone();
        if let InputChannels::Thrusters { configuration, .. } = &mut bad.inputs {
            configuration[2][5] = 0.0;
        }
        let e = bad.validate().unwrap_err();
        assert_eq!(e.field, "inputs.configuration");
        assert!(e.to_string().contains("column thr_6"), "{e}");
        let mut bad = v.clone();
        if let InputChannels::Thrusters { thrusters, .. } = &mut bad.inputs {
            thrusters[5].kind = crate::planning::vessel::ThrusterKind::Tunnel;
        }
        assert_eq!(
            bad.validate().unwrap_err().field,
            "inputs.thrusters[5].logged_angle"
        );
        let mut bad = v;
        bad.dp_prior = None;
        assert_eq!(
            bad.validate().unwrap_err().field,
            "inputs.thrusters[5].logged_angle"
        );
    }

    #[test]
    fn bad_signals_name_their_field() {
        let mut v = supply_vessel();
        let InputChannels::Thrusters { thrusters, .. } = &mut v.inputs else {
            unreachable!()
        };
        thrusters[1].signal = ThrusterSignal::ShaftSpeed { rated_rpm: 0.0 };
        assert_eq!(
            v.validate().unwrap_err().field,
            "inputs.thrusters[1].signal.rated_rpm"
        );
        let InputChannels::Thrusters { thrusters, .. } = &mut v.inputs else {
            unreachable!()
        };
        thrusters[1].signal = ThrusterSignal::Pitch {
            zero_thrust: 2.0,
            full_ahead: 2.0,
        };
        assert_eq!(
            v.validate().unwrap_err().field,
            "inputs.thrusters[1].signal.full_ahead"
        );
    }
}
