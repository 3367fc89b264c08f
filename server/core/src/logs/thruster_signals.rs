//! Thruster logs as loggers record them: the column `thr_j` may carry the
//! propeller's shaft speed, pitch or measured thrust instead of the command
//! u_j of τ = T K u; [`read_thruster_commands`] turns it into u_j (see
//! [`ThrusterSignal`]) before anything reads the record.

use crate::planning::vessel::{ThrusterSignal, VesselProfile};
use crate::timeseries::UniformRecord;

use super::schema::thruster_column;

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
