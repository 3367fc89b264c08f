//! What a run is, inferred from its data alone, on campaigns nobody planned:
//! ten vessels drawn by the independent truth (`seatrial-truth`, not the
//! five the REST test uploads), flown by another team's autopilot (velocity
//! loops on u, v, w, r; attitude loops on φ, θ). Role, grid speed and
//! excited DOFs must be what was flown on every run — including the sway
//! and heave runs of small vehicles whose yaw or pitch loop, holding
//! against the coupling, moves as much as the excited DOF (told apart by
//! the sign of the actuators' work), and the validation run, whose surge
//! staircase dwarfs the other DOFs' excitation.

mod support;

use seatrial_core::identification::infer_description;
use seatrial_truth::{CampaignSpec, Vessel, fly_campaign};
use support::open_world::{profile_for, to_input};

#[test]
fn every_run_of_ten_drawn_vessels_is_described_as_flown() {
    let spec = CampaignSpec::default();
    let (mut runs, mut misses) = (0, Vec::new());
    for seed in 6..=15 {
        let campaign = fly_campaign(&Vessel::draw(seed), &spec, seed);
        let profile = profile_for(&campaign);
        let inputs: Vec<String> = profile
            .dofs
            .iter()
            .map(|d| d.force_column().to_string())
            .collect();
        for run in &campaign.runs {
            let record = to_input(&profile, run, false).record;
            let d = infer_description(&record, &profile, &inputs, &spec.grid_speeds)
                .expect("a 10 Hz log is described");
            let m = &run.meta;
            let flown: Vec<&str> = m.excited.iter().map(|x| x.label()).collect();
            let inferred: Vec<&str> = d.excited_dofs.iter().map(|x| x.name()).collect();
            runs += 1;
            if d.role.name() != m.role.label()
                || d.grid_speed_mps != m.grid_speed
                || inferred != flown
            {
                misses.push(format!(
                    "seed {seed} {}: {} at {:?} exciting {inferred:?} ({}; {})",
                    m.name,
                    d.role.name(),
                    d.grid_speed_mps,
                    d.role_reason,
                    d.excited_dofs_reason
                ));
            }
        }
    }
    assert!(
        misses.is_empty(),
        "{} of {runs} runs described otherwise than flown:\n{}",
        misses.len(),
        misses.join("\n")
    );
}
