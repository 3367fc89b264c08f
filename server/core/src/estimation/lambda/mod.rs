//! Continuous-time identification of M ν̇ + D̄ ν = γ through the
//! state-variable filter λ(s) = 1/(1+sT) and a Kalman filter over the
//! parameters (thesis eq. 1.9–1.10, sec. 2.5 eq. 2.9–2.15, app. 7.1).
//!
//! With γ = τ − g(η), A = −M⁻¹D̄ and B = M⁻¹, filtering ν̇ = Aν + Bγ through
//! λ gives ν = A_λ[λν] + B_λ[λγ] with A_λ = I + T·A, B_λ = T·B: a linear
//! regression in the entries of A_λ, B_λ without differentiating ν. The
//! parameter Kalman filter starts at the rigid-body guess (M₀, D̄₀) and
//! treats each output row as its own regression on the shared regressor.
//!
//! - [`filter`]: the exact ZOH discretization of λ and its initial state.
//! - [`transform`]: A_λ, B_λ ↔ A, B (exact sampled-data inverse or the
//!   thesis' eq. 2.14–2.15) and ZOH discretization.
//! - [`identify`](fn@identify): one operating point from a multi-experiment set.
//! - [`identify_lpv`]: one model per grid speed (eq. 2.16–2.18).
//! - [`propose_coupling`]: coupling mask from the coherence between DOFs.
//! - [`predict`]: 1-step and free-run predictions for validation (eq. 1.13).

mod coupling;
mod error;
mod errors_in_variables;
mod estimate;
mod experiment;
pub mod filter;
mod identify;
mod information;
mod kalman;
mod lpv;
mod posterior;
pub mod predict;
mod regressors;
mod robust;
mod settings;
mod statistics;
mod structure;
mod symmetric;
pub mod transform;
mod uncertainty;

#[cfg(test)]
mod tests;

pub use coupling::{
    BAND_FRACTION, CouplingProposal, MIN_COHERENCE_SAMPLES, PairEvidence, propose_coupling,
};
pub use error::LambdaError;
pub use errors_in_variables::RegressorNoise;
pub use estimate::{LambdaEstimate, UncertaintyMethod};
pub use experiment::Experiment;
pub use filter::{FilterInit, LambdaFilter};
pub use identify::{identify, identify_with_progress};
pub use information::regression_information;
pub use lpv::identify_lpv;
pub use predict::ZohModel;
pub use settings::{Exogenous, LambdaSettings, MIN_T_OVER_H, Prior};
pub use structure::{CouplingMask, Structure};
pub use symmetric::SymmetryFit;
pub use transform::{Inversion, mass_damping, zoh};
