//! Vessel models in Fossen's notation: ν = [u v w p q r]ᵀ, η = [x y z φ θ ψ]ᵀ,
//! τ = [X Y Z K M N]ᵀ, M ν̇ + C(ν)ν + D(ν)ν + g(η) = τ, η̇ = J(η)ν.
//!
//! - [`state_space`]: continuous (A, B, C, D) models, exact ZOH
//!   discretization to (Φ, Γ), poles, discrete simulation.
//! - [`vessel`]: the thesis's M ν̇ + D̄ ν = γ with γ = τ − g(η)
//!   (eq. 2.9–2.12), A = −M⁻¹D̄, B = M⁻¹, with an optional constant load b;
//!   a [`Predictor`](crate::validation::Predictor).
//! - [`structure`]: physical plausibility of M and D̄ (symmetry, positive
//!   definiteness, dissipativity) in words.
//! - [`projection`]: the nearest physical (M, D̄) when an estimate is not.
//! - [`coriolis`]: C(ν) from M (Fossen 2011, eq. 6.43), 6-DOF and 3-DOF.
//! - [`lpv`]: sub-models on a forward-speed grid, nearest (eq. 2.17) or
//!   interpolated (eq. 2.18) scheduling; a `Predictor` scheduled on u.
//! - [`lpv_schedule`]: the sub-models' weights at a speed, and the optional
//!   extension beyond the grid (damping linear, load quadratic in u₀).
//! - [`quadratic_damping`]: D_q|δ|δ, the quadratic hull damping about
//!   straight-ahead motion that linear sub-models cannot carry.
//! - [`error`]: the typed errors of all of the above.
//! - `predict` (private): k-step and free-run loops shared by the predictors.

pub mod coriolis;
pub mod current;
pub mod error;
pub mod lpv;
pub mod lpv_schedule;
pub(crate) mod predict;
pub mod projection;
pub mod quadratic_damping;
pub mod state_space;
pub mod structure;
pub mod vessel;

pub use coriolis::{coriolis, coriolis_3dof, coriolis_6dof, skew};
pub use error::ModelError;
pub use lpv::{DiscreteLpv, LpvModel};
pub use lpv_schedule::{Blend, Extension, ScheduleWeights, Scheduling};
pub use projection::{Projection, project_physical};
pub use state_space::{DiscreteStateSpace, StateSpace};
pub use structure::StructureReport;
pub use vessel::LinearVesselModel;
