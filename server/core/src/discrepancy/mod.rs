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
//!    noise floor are reported as unexplained, with their signature; a narrow
//!    line of one size in every run's residual force ([`lines`]) is reported
//!    as a periodic force from outside the model, with its frequency and
//!    size, and terms fitted through it in its DOF are withdrawn; a model
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
//! Also proven on PI-flown planned campaigns with an LPV λ baseline
//! (`identification::discover_campaign` tests, `tests/api_discovery.rs`
//! through REST): quadratic damping, Coriolis, lag, delay, tether, current,
//! saturation, two pairs and a clean case, named at both grid speeds.
//!
//! Choices that matter:
//! - C(ν) is built from the model's own M and a current acts through its
//!   own D̄ and M, both refitted to a fixed point ([`fit`]): built from the
//!   baseline's M, which had absorbed part of C(ν)ν, the scale came out
//!   0.7–0.86 (69 % of the gap on seeds 13 and 15); now 1.00 on seeds
//!   11–15;
//! - a current turning in the body frame adds M ν̇_c = M·r·[v_c, −u_c] to
//!   D̄ ν_c;
//! - saturation levels are searched down to 2 % of the largest command:
//!   under closed-loop control the command winds up to the controller's
//!   own limit, far above the hull's τ_max;
//! - a lag must be faster than the hull's M_rr/D̄_rr (the two time
//!   constants are interchangeable in the transfer function), and a
//!   refitted row must keep M_rr > 0, D̄_rr ≥ 0;
//! - a shape optimum on the edge of its search range is a bound, not an
//!   estimate, and is not significant.
//!
//! Not done yet / weaker than it looks:
//! - a current under PI-flown planned runs is named first, but its
//!   magnitude comes out about half the truth (0.10 vs 0.18 m/s, direction
//!   21° and 68° at the two speeds against 34°) and the sway fit improves
//!   only 0.43 → 0.64; open-loop runs recover it to 1 %. Not the 20 Hz
//!   command in a 10 Hz log (same at 10 Hz), not the baseline (D̄_uu 1595
//!   and 1451 against 1500). The likely cause: at one grid speed under
//!   speed hold, τ ≈ D̄(u_ref − u_c) is nearly constant, so u_c trades
//!   against a small D̄ error (ΔD̄·u_ref/D̄) and the HAC std (± 0.008 m/s)
//!   understates it. The current is a property of the site, not of the
//!   speed: fitting one V_c across all grid points (or the four-heading
//!   deciding run) is the fix, not built;
//! - a current that varies slowly (random walk) is named as a current and
//!   kept in the model as its mean; [`drift`] then refits the current in
//!   15 s windows (M, D̄ held), tests their spread (χ²) and whether they
//!   wander (von Neumann ratio), and gives the random walk's σ (seeds
//!   11–13: 0.0108, 0.0094, 0.0075 against 0.01 m/s per √s; steady
//!   currents pass as steady). Held-out free runs cannot follow a
//!   wandering current (seed 14 names nothing); an observer with the
//!   current as a state is the model for that, not built. On PI-flown
//!   runs a steady current's windows disagree without wandering, and the
//!   report says the current's size is uncertain rather than drifting;
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
//!   n·(n − 1) cross-flow candidates (30 for six DOFs); a damping term
//!   (quadratic, cubic, cross-flow) with a negative coefficient, which
//!   would feed energy into the hull, is not significant;
//! - the std of the C(ν) scale (≈ 5·10⁻⁴) does not carry the uncertainty
//!   of the M it is built from;
//! - the noise floor assumes noise on ν only: attitude noise ≳ 1e-3 rad
//!   through a stiff restoring (roll/pitch) shows as ≈ 10 dB of
//!   low-frequency "unexplained" structure (the proof flies 2e-4 rad);
//! - heave saturation under PI control leaves 14–17 dB of low-frequency
//!   heave structure "unexplained"; not yet located (a likely cause: the
//!   20 Hz controller's commands switch within a 10 Hz log interval, so
//!   the logged command is not the one held);
//! - the suite (13 cases) takes ≈ 22 s wall on 2 cores in release.

pub mod candidates;
pub mod data;
pub mod discover;
pub mod drift;
pub mod error;
pub mod evidence;
pub mod experiment;
pub mod fit;
pub mod lines;
pub mod locate;
mod lookalike;
pub mod model;
mod narrate;
pub mod proof;
pub mod report;
pub mod residual;
pub mod select;
pub mod svf;

pub use candidates::{Effect, Family, LibrarySettings, RestoringShape};
pub use data::{Baseline, Record, Restoring};
pub use discover::{DiscoverySettings, discover, discover_from, refit_holding};
pub use error::DiscoveryError;
pub use experiment::ExperimentProposal;
pub use model::{AugmentedModel, ModelTerm};
pub use report::{DiscoveryReport, Verdict};

#[cfg(test)]
mod tests;
