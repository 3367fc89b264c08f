//! Missing-physics discovery: locate where a baseline model and the
//! recordings part, name the left-out physics, model it.
//!
//! Input: a baseline M ν̇ + D̄ ν = γ, γ = τ − g(η) (thesis eq. 2.7–2.9,
//! [`Baseline`]), estimation and validation runs ([`Record`]: commanded τ,
//! measured ν and η at a uniform h). [`discover`] returns a
//! [`DiscoveryReport`]:
//!
//! 1. **Locate** ([`locate`]): the baseline simulated on the recorded inputs
//!    (free run, k-step, 1-step) per DOF, per time segment, per octave band
//!    (1-step residual PSD against the sensor-noise floor, whitened by the
//!    predictor's own noise shape), per operating condition (forward speed,
//!    heading, input amplitude), in short sentences.
//! 2. **Name** ([`candidates`], [`fit`], [`select`]): a library of terms with
//!    their regressor signatures in M·ν̇ + C(ν)ν + D(ν)ν + g(η) = τ —
//!    quadratic damping |ν_i|ν_i, cubic damping ν_i³, cross-flow damping
//!    |ν_j|ν_i (every ordered pair of modeled DOFs), C(ν)ν from M and its
//!    single products, restoring
//!    shapes, constant loads (tether), current through D̄(ν − ν_c), missing
//!    coupling, actuator lag, delay, saturation, dead zone. Each is fitted as
//!    an augmentation of the baseline (λ-filter equation error with the
//!    touched rows refitted, HAC covariances; actuator shapes by a profile of
//!    the row's k-step output error), screened by significance and ΔBIC with
//!    the effective sample count, and chosen greedily by cross-validated
//!    free-run NRMSE (eq. 1.13) on runs left out of the fit.
//! 3. **Model it** ([`model`]): the augmented model with coefficients,
//!    covariances and a simulator / k-step predictor (also a
//!    [`crate::validation::Predictor`] with u = [τ | η]).
//! 4. **Show it**: before/after fits per channel on the validation runs,
//!    residual whiteness (±2.576/√N, zero crossings), decimated series.
//! 5. **Ask** ([`experiment`]): when a look-alike gains almost as much on
//!    held-out runs, both fitted models are simulated on runs the vessel can
//!    fly (force columns within the profile's limits, one or four headings)
//!    and the run that separates them most is proposed in planner terms.
//! 6. **Be honest**: bands of the augmented model's residual still above the
//!    noise floor are reported as unexplained, with their signature; a model
//!    that already fits names nothing.
//!
//! # STATUS
//! Done: everything above, proven ([`proof`], `tests/proof.rs`) on the
//! project's ROV truth (`simulation::rov`: Surveyor-like, coupled M,
//! coupled D̄ frozen at 0.5 m/s) with the baseline the product identifies
//! (`estimation::lambda::identify`, fully coupled, prior from the profile;
//! [`Baseline::from_model`] takes a `models::LinearVesselModel`):
//! quadratic damping, cubic damping (ν³ in surge, sway, heave or yaw),
//! cross-flow damping (|ν_j|ν_i for sway–yaw, yaw–sway, surge–sway,
//! sway–surge; `RovTruth::{cubic_damping, cross_damping}`), Coriolis,
//! tether (pitch moment or sway/heave force),
//! constant current, lag, delay (the simulator delays every DOF alike:
//! [`Effect::CommonInputDelay`]), saturation, three pairs and a clean case,
//! DOFs and magnitudes drawn from seeded ranges; one seed per case in the
//! suite, four more behind `#[ignore]`; `examples/discovery_table.rs` prints
//! the table. Whiteness uses `validation::correlation` and
//! `validation::residuals::zero_crossings`.
//!
//! Not done yet / weaker than it looks:
//! - a current that varies slowly (random walk) is fitted as a constant and
//!   named as a current (`proof::extra_cases`; seed 11: |V_c(0)| = 0.156,
//!   fitted 0.180 m/s); no time-varying current term;
//! - the C(ν) scale comes out ≈ 0.86 ± 0.02 against a true 1 (the coupled
//!   baseline absorbs part of C(ν)ν): named right, 85 % of the gap, but its
//!   std does not cover the truth;
//! - ambiguity is judged pairwise: a current at one heading looks like two
//!   constant loads (surge + sway) together, which is not flagged;
//! - cubic and cross-flow damping are separate families from quadratic
//!   damping, so a cubic and a quadratic term in one DOF that gain about
//!   equally are flagged as an ambiguity (with a deciding run), as are
//!   |ν_j|ν_i against a Coriolis product ν_j·ν_i; the proof conceals each
//!   alone (at 40–80 % of the linear force at 0.4 of the velocity limit)
//!   and both are named over quadratic damping, but no case conceals a
//!   quadratic and a cubic term in the same DOF, nor a cross-flow term
//!   driven by a DOF outside the horizontal plane; the library offers
//!   n·(n − 1) cross-flow candidates (30 for six DOFs);
//! - cubic vs quadratic damping is close: on seed 11 the held-out gains
//!   are 0.044 vs 0.042 (cubic case) and 0.040 vs 0.037 (quadratic case),
//!   both flagged as ambiguous with a deciding run; seeds 12–15 name both
//!   right. The fitted cross-flow coefficient is not constrained to be
//!   dissipative: on Coriolis seed 13 a |u|v term of −882 ± 107 joins
//!   after C(ν)ν;
//! - Coriolis alone closes only 69 % of the gap on seeds 13 and 15 (C(ν)
//!   scale 0.70 and 0.74), with or without the cubic and cross-flow
//!   families (checked with both off); the other cases pass seeds 12–15;
//! - the noise floor assumes noise on ν only: attitude noise ≳ 1e-3 rad
//!   through a stiff restoring (roll/pitch) shows as ≈ 10 dB of
//!   low-frequency "unexplained" structure (the proof flies 2e-4 rad);
//! - the proof forms γ with the interval mean ½(g(η_k) + g(η_k+1)); the
//!   log pipeline's sampled g(η_k) biases the λ baseline's D̄ by K·h/2 on
//!   restoring DOFs (+25 % in roll), which discovery then reports as
//!   unexplained roll/pitch structure rather than naming a term;
//! - LPV baselines (one model per grid speed) are not handled;
//! - the suite (13 cases) takes ≈ 40 s of CPU in release (≈ 40 s wall on
//!   2 cores shared with another build; ≈ 26 s of CPU before the 36
//!   cubic and cross-flow candidates joined the library); the current and
//!   shape profiles dominate.

pub mod candidates;
pub mod data;
pub mod discover;
pub mod error;
pub mod evidence;
pub mod experiment;
pub mod fit;
pub mod locate;
pub mod model;
pub mod proof;
pub mod report;
pub mod residual;
pub mod select;
pub mod svf;

pub use candidates::{Effect, Family, LibrarySettings, RestoringShape};
pub use data::{Baseline, Record, Restoring};
pub use discover::{DiscoverySettings, discover};
pub use error::DiscoveryError;
pub use experiment::ExperimentProposal;
pub use model::{AugmentedModel, ModelTerm};
pub use report::DiscoveryReport;

#[cfg(test)]
mod tests;
