//! Static runs (thesis sec. 3.4, Tables 3.2–3.3), designed for what the
//! identification does with them. In a steady hold ν̇ = 0, so the thrust
//! balances damping, restoring and constant loads alone:
//!
//! - **surge**: steady flight at the grid speed (the operating point);
//! - **sway, heave, yaw**: a steady speed (yaw: rate) of +level in one run,
//!   −level in its pair. D̄·ν + b = τ at two levels separates the damping
//!   D̄ from the constant load b (current, tether);
//! - **roll, pitch**: a steady attitude of +θ in one run, −θ in its pair,
//!   flown by the attitude reference `phi_ref` / `theta_ref`. The rate is
//!   zero in the hold, so damping drops out and the moment is
//!   (z_G W − z_B B)·sin θ + b: the two holds separate g(η) from b. At a
//!   grid speed of 0 these are the station-keeping holds of thesis eq.
//!   2.1–2.4 ([`crate::estimation::restoring`]); at a forward speed the
//!   joint fit of g(η) with M and D̄ (`identification::joint_restoring`)
//!   takes them as its steady-attitude data.
//!
//! A rate hold in roll or pitch ("bring pitch to +0.15 rad/s") tells
//! nothing about g(η): a metacentrically stable vehicle cannot keep rolling,
//! and the attitude never holds still.

use super::campaign::ExperimentFamily;
use super::design::SQUARE_HOLD_TIME_CONSTANTS;
use super::dof::Dof;
use super::error::PlanError;
use super::plan::{ChannelSpec, Ctx, ExperimentHead, PlannedExperiment, assemble, fmt_speed};
use super::vessel::VesselProfile;
use super::waveform::Waveform;

/// Hold angle of a roll or pitch static run when the profile sets no
/// `max_angle` (rad): 10°, where sin θ = 0.17 gives a restoring moment
/// well above thrust noise and cos θ = 0.985 leaves the heave balance
/// almost as upright.
pub const STATIC_ATTITUDE_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// Time constant of the attitude loop (the pilot's or autopilot's), in
/// time constants T of the DOF: taken twice as slow as the rate response
/// below it. It sets the clock of dynamic attitude excitation (a PRBS chip
/// lasts one attitude time constant, a square-wave level five) as T sets a
/// rate or speed channel's.
pub const ATTITUDE_LOOP_TIME_CONSTANTS: f64 = 2.0;

/// Settling allowance of an attitude hold, in time constants of the DOF:
/// 5 time constants of the attitude loop, twice the 5·T of a rate hold.
pub const ATTITUDE_SETTLE_TIME_CONSTANTS: f64 =
    ATTITUDE_LOOP_TIME_CONSTANTS * SQUARE_HOLD_TIME_CONSTANTS;

/// True for the DOFs whose static runs hold an attitude.
pub fn holds_attitude(d: Dof) -> bool {
    matches!(d, Dof::Roll | Dof::Pitch)
}

/// The attitude reference column of roll or pitch: `phi_ref`, `theta_ref`.
pub fn attitude_column(d: Dof) -> &'static str {
    match d {
        Dof::Roll => "phi_ref",
        _ => "theta_ref",
    }
}

/// The hold angle of a roll or pitch static run (rad): 10°, or the
/// profile's `max_angle` when smaller.
pub fn static_angle(vessel: &VesselProfile, d: Dof) -> f64 {
    vessel
        .limit(d)
        .max_angle
        .map_or(STATIC_ATTITUDE_RAD, |m| m.min(STATIC_ATTITUDE_RAD))
}

/// Largest attitude amplitude of roll or pitch (rad): the profile's
/// `max_angle`, or 10° when it sets none. Dynamic runs excite roll and
/// pitch between ±[`static_angle`] by default; a per-DOF amplitude may go
/// up to this.
pub fn attitude_limit(vessel: &VesselProfile, d: Dof) -> f64 {
    vessel.limit(d).max_angle.unwrap_or(STATIC_ATTITUDE_RAD)
}

fn signed(sign: i8) -> &'static str {
    if sign > 0 { "+" } else { "−" }
}

/// The channel that holds `d` in a static run, its settling time and what
/// the pilot reads.
fn hold_channel(
    ctx: &Ctx<'_>,
    gi: usize,
    d: Dof,
    sign: i8,
) -> Result<(super::plan::ChannelPlan, f64, String), PlanError> {
    let u0 = ctx.speeds[gi];
    let hold = ctx.spec.durations.static_hold_s;
    let t = ctx.vessel.limit(d).time_constant_s;
    let at = fmt_speed(ctx, gi);
    let mut p = ctx.held(d, u0);
    p.excited = true;
    if d == Dof::Surge {
        let settle = SQUARE_HOLD_TIME_CONSTANTS * t;
        let words = format!(
            "Fly forward at a steady {at} with no other motion: let the speed settle (≈ {settle:.0} s), then hold it {hold:.0} s more."
        );
        return Ok((p, settle, words));
    }
    p.waveform = Waveform::Step {
        sign: f64::from(sign),
    };
    let other = format!(
        "STA-{}-{}{}",
        ctx.speed_label(gi),
        d.name(),
        if sign > 0 { "-" } else { "+" }
    );
    if holds_attitude(d) {
        let angle = static_angle(ctx.vessel, d);
        let settle = ATTITUDE_SETTLE_TIME_CONSTANTS * t;
        p.column = attitude_column(d).into();
        p.unit = "rad".into();
        p.amplitude = angle;
        p.limit = angle;
        // The attitude is brought over no faster than the DOF's rate limit.
        p.rate_limit = Some(ctx.vessel.limit(d).max_velocity);
        let (name, deg, s, o) = (d.name(), angle.to_degrees(), signed(sign), signed(-sign));
        let words = format!(
            "At a steady {at}, hold {name} at {s}{deg:.0}° ({s}{angle:.3} rad) by attitude control: let it settle (≈ {settle:.0} s), then hold it {hold:.0} s more; no other motion. Its pair {other} holds {name} at {o}{deg:.0}°: together they give the restoring moment apart from the damping."
        );
        return Ok((p, settle, words));
    }
    let level = ctx.amplitude(d)?;
    p.amplitude = level;
    let settle = SQUARE_HOLD_TIME_CONSTANTS * t;
    let ramp = p.rate_limit.map_or(0.0, |r| level / r);
    let words = if p.column.starts_with("tau_") {
        format!(
            "At a steady {at}, apply {}{level:.0} {} in {} and keep it until the {} speed is steady (≈ {:.0} s), then {hold:.0} s more; no other motion. Its pair {other} applies {}{level:.0} {}.",
            signed(sign),
            p.unit,
            d.name(),
            d.name(),
            ramp + settle,
            signed(-sign),
            p.unit
        )
    } else {
        format!(
            "At a steady {at}, hold a steady {} {} of {}{level:.3} {}: let it settle (≈ {:.0} s), then hold it {hold:.0} s more; no other motion. Its pair {other} holds {}{level:.3} {}: together they separate damping from current.",
            d.name(),
            if d.is_angular() { "rate" } else { "speed" },
            signed(sign),
            p.unit,
            ramp + settle,
            signed(-sign),
            p.unit
        )
    };
    Ok((p, ramp + settle, words))
}

/// The static runs of grid point `gi`: surge alone at the grid speed, then
/// +level and −level in every other modelled DOF.
pub(super) fn rov_static(
    ctx: &Ctx<'_>,
    gi: usize,
    reps: u32,
    out: &mut Vec<PlannedExperiment>,
) -> Result<(), PlanError> {
    let u0 = ctx.speeds[gi];
    let dofs = &ctx.vessel.dofs;
    let hold = ctx.spec.durations.static_hold_s;
    for &d in dofs {
        let signs: &[i8] = if d == Dof::Surge { &[1] } else { &[1, -1] };
        for &sign in signs {
            for rep in 1..=reps {
                let (held, settle, instruction) = hold_channel(ctx, gi, d, sign)?;
                let duration = settle + hold;
                let mut held = Some(held);
                let channels = dofs
                    .iter()
                    .map(|&c| ChannelSpec {
                        plan: if c == d {
                            held.take().unwrap_or_else(|| ctx.held(c, u0))
                        } else {
                            ctx.held(c, u0)
                        },
                        duration_s: duration,
                    })
                    .collect();
                let code = format!(
                    "STA-{}-{}{}-r{rep}",
                    ctx.speed_label(gi),
                    d.name(),
                    match (d, sign > 0) {
                        (Dof::Surge, _) => "",
                        (_, true) => "+",
                        (_, false) => "-",
                    }
                );
                out.push(assemble(
                    ctx,
                    ExperimentHead {
                        code,
                        family: ExperimentFamily::Static,
                        grid_index: Some(gi),
                        dofs: vec![d],
                        sign: (d != Dof::Surge).then_some(sign),
                        repetition: rep,
                        instruction,
                        pe_required: 1,
                        field: format!("excitation.per_dof.{}", d.name()),
                    },
                    channels,
                )?);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::restoring::{
        RestoringSettings, StaticRecord, SteadySettings, estimate_restoring,
    };
    use crate::planning::campaign::{SpeedGrid, SpeedUnit};
    use crate::planning::examples::{surveyor_campaign, surveyor_rov};
    use crate::planning::generate_plan;
    use crate::simulation::rov::RovTruth;
    use crate::simulation::trials::{MeasurementNoise, TrialSettings, fly_campaign};

    /// The planned roll and pitch holds at 0 kn (with the surge hold),
    /// flown through this project's own ROV simulator
    /// (`simulation::trials` over the Surveyor-like truth: W − B = −250 N,
    /// z_G W − z_B B = 0.2 m·B, no tether) and logged with its navigation
    /// noise, give the station-keeping estimate of g(η) (thesis eq.
    /// 2.1–2.4) they are designed for.
    #[test]
    fn planned_attitude_holds_flown_by_the_simulator_give_the_restoring_moment() {
        let profile = surveyor_rov();
        let mut spec = surveyor_campaign(3);
        spec.grid = SpeedGrid {
            unit: SpeedUnit::Knots,
            speeds: vec![0.0],
        };
        spec.families = vec![ExperimentFamily::Static];
        let plan = generate_plan(&profile, &spec).unwrap();
        let pitch_up = plan
            .experiments
            .iter()
            .find(|p| p.experiment.code == "STA-0kn-pitch+-r1")
            .unwrap();
        let words = &pitch_up.experiment.instruction;
        assert!(words.contains("hold pitch at +10°"), "{words}");
        assert!(
            words.contains("STA-0kn-pitch- holds pitch at −10°"),
            "{words}"
        );
        assert!(pitch_up.schedule.columns.contains(&"theta_ref".to_string()));

        let truth = RovTruth::surveyor_like();
        let settings = TrialSettings {
            seed: 5,
            noise: MeasurementNoise {
                // A fibre-optic gyro: the steady-segment test holds |p|, |q|,
                // |r| ≤ 0.01 rad/s, which a MEMS gyro's 0.005 rad/s breaks
                // every few samples.
                nu: [0.01, 0.01, 0.01, 0.001, 0.001, 0.001],
                ..MeasurementNoise::default()
            },
            ..TrialSettings::default()
        };
        let flown = fly_campaign(&profile, &truth, &plan, &settings, |e| {
            e.dofs.iter().any(|&d| holds_attitude(d) || d == Dof::Surge)
        })
        .unwrap();
        assert_eq!(flown.len(), 5);
        for f in &flown {
            // The hold reached its angle: the last 10 s sit at ±10°.
            let Some(d) = [Dof::Roll, Dof::Pitch]
                .into_iter()
                .find(|d| f.code.contains(d.name()))
            else {
                continue;
            };
            let col = f.record.eta_true.column(d.index());
            let n = col.len();
            let tail = col.rows(n - 100, 100).mean();
            let want = if f.code.contains('+') { 10.0 } else { -10.0 };
            assert!(
                (tail.to_degrees() - want).abs() < 0.3,
                "{}: {}°",
                f.code,
                tail.to_degrees()
            );
        }
        let h = flown[0].record.t[1] - flown[0].record.t[0];
        let records: Vec<StaticRecord<'_>> = flown
            .iter()
            .map(|f| StaticRecord {
                h,
                nu: &f.record.nu,
                eta: &f.record.eta,
                tau: &f.record.tau_commanded,
            })
            .collect();
        // The simulated controller feeds back noise-free ν, so the logged τ
        // is smooth and its own noise would make the steadiness tolerance
        // vanish: 1 % of each DOF's force limit stands in for thrust noise.
        let mut tolerance = [0.0; 6];
        for d in Dof::ALL {
            tolerance[d.index()] = 0.01 * profile.limit(d).max_force;
        }
        let estimator = RestoringSettings {
            steady: SteadySettings {
                tau_tolerance: Some(tolerance),
                ..SteadySettings::default()
            },
            ..RestoringSettings::default()
        };
        let est = estimate_restoring(&records, &estimator).unwrap();
        let r = &truth.restoring;
        let bg = -r.r_b[2] * r.buoyancy;
        eprintln!(
            "z_G W − z_B B = {:.0} ± {:.0} N·m (truth {bg:.0}); W − B = {:.1} ± {:.1} N (truth {:.1}); τ_θ = {:.1} N·m; {} steady segments",
            est.params.zg_weight_minus_zb_buoyancy_nm,
            est.std.zg_weight_minus_zb_buoyancy_nm,
            est.params.weight_minus_buoyancy_n,
            est.std.weight_minus_buoyancy_n,
            r.weight - r.buoyancy,
            est.params.tether_pitch_moment_nm,
            est.segments.len()
        );
        let got = est.params.zg_weight_minus_zb_buoyancy_nm;
        assert!(
            (got - bg).abs() < 0.02 * bg,
            "z_G W − z_B B = {got:.0} ± {:.0}, truth {bg:.0}",
            est.std.zg_weight_minus_zb_buoyancy_nm
        );
        let wb = est.params.weight_minus_buoyancy_n;
        assert!(
            (wb - (r.weight - r.buoyancy)).abs() < 25.0,
            "W − B = {wb:.1} ± {:.1}, truth −250",
            est.std.weight_minus_buoyancy_n
        );
        assert!(est.params.tether_pitch_moment_nm.abs() < 0.01 * bg);
    }
}
