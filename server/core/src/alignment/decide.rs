//! Which clock offset a run is merged with.
//!
//! In order of precedence:
//! 1. `user_run` — set by hand for this run;
//! 2. `user_campaign` — set by hand for the campaign (the same two computers);
//! 3. `own` — the run's own estimate, when it is informative, unless the
//!    campaign's pool already holds it with at least one other run: then
//!    `pooled`, the inverse-variance mean of this run's estimate and the
//!    consistent others', is at least as precise. On 75 campaigns of the
//!    independent truth (`seatrial-truth`, seeds 1–75) the own ±2σ of 17
//!    of 599 informative runs missed the truth, in 15 campaigns; the pooled
//!    ±2σ missed it in 3 campaigns (every run of a campaign now shares it);
//! 4. `pooled` — the campaign's offset pooled from its informative runs
//!    ([`super::pool_offsets`]);
//! 5. `weak_own` — the run's own, uninformative estimate, with a loud
//!    warning: there was nothing better.
//!
//! A run the pool left out as inconsistent (its clocks may have been reset)
//! keeps its own informative estimate.

use serde::{Deserialize, Serialize};

use super::AlignError;
use super::offset::OffsetEstimate;

/// Largest clock offset accepted when set by hand (s): one day. Offsets
/// between unrelated clock origins (epoch vs. time since boot) are found by
/// the estimator; a hand-set offset corrects a weak estimate.
pub const MAX_USER_OFFSET_S: f64 = 86_400.0;

/// Where the offset a run was merged with came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum OffsetSource {
    /// Set by hand for this run.
    UserRun,
    /// Set by hand for the campaign.
    UserCampaign,
    /// The run's own, informative estimate.
    Own,
    /// The campaign's offset pooled from its informative runs.
    Pooled,
    /// The run's own estimate although it is not informative.
    WeakOwn,
}

/// A campaign's pooled offset as a run uses it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct PooledValue {
    /// Pooled offset (s).
    pub offset_s: f64,
    /// Its standard deviation (s).
    pub std_s: f64,
    /// How many runs it pools.
    pub runs: usize,
    /// Whether the run's own estimate is one of those pooled.
    #[serde(default)]
    pub includes_own: bool,
}

/// Offsets known apart from the run's own estimate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OffsetPriors {
    /// Set by hand for this run (s).
    pub user_run_s: Option<f64>,
    /// Set by hand for the campaign (s).
    pub user_campaign_s: Option<f64>,
    /// The campaign's pooled offset.
    pub pooled: Option<PooledValue>,
}

/// The offset chosen for a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chosen {
    /// Offset (s).
    pub offset_s: f64,
    /// Its standard deviation (s); `None` when set by hand.
    pub std_s: Option<f64>,
    /// Where it came from.
    pub source: OffsetSource,
}

/// Checks a hand-set offset: finite and within ±[`MAX_USER_OFFSET_S`].
///
/// # Errors
/// [`AlignError::InvalidInput`] naming `field`.
pub fn check_user_offset(field: &str, value: f64) -> Result<(), AlignError> {
    if !value.is_finite() || value.abs() > MAX_USER_OFFSET_S {
        return Err(AlignError::invalid(
            field,
            format!(
                "a clock offset set by hand must be a finite number of seconds within ±{MAX_USER_OFFSET_S} s (one day), got {value}"
            ),
        ));
    }
    Ok(())
}

/// Picks the offset by the precedence of the module documentation; `None`
/// only when there is neither an own estimate nor any prior.
///
/// # Errors
/// [`AlignError::InvalidInput`] naming `priors.user_run_s`,
/// `priors.user_campaign_s` or `priors.pooled` for a value that is not
/// finite (or a hand-set one beyond a day, or a σ that is not positive).
pub fn choose_offset(
    own: Option<&OffsetEstimate>,
    priors: &OffsetPriors,
) -> Result<Option<Chosen>, AlignError> {
    if let Some(v) = priors.user_run_s {
        check_user_offset("priors.user_run_s", v)?;
    }
    if let Some(v) = priors.user_campaign_s {
        check_user_offset("priors.user_campaign_s", v)?;
    }
    if let Some(p) = priors.pooled
        && !(p.offset_s.is_finite() && p.std_s.is_finite() && p.std_s > 0.0)
    {
        return Err(AlignError::invalid(
            "priors.pooled",
            format!(
                "the pooled offset must be finite with a positive standard deviation, got {} ± {} s",
                p.offset_s, p.std_s
            ),
        ));
    }
    let pooled = |p: PooledValue| Chosen {
        offset_s: p.offset_s,
        std_s: Some(p.std_s),
        source: OffsetSource::Pooled,
    };
    let by_hand = |offset_s, source| Chosen {
        offset_s,
        std_s: None,
        source,
    };
    Ok(if let Some(v) = priors.user_run_s {
        Some(by_hand(v, OffsetSource::UserRun))
    } else if let Some(v) = priors.user_campaign_s {
        Some(by_hand(v, OffsetSource::UserCampaign))
    } else if let Some(p) = priors.pooled.filter(|p| p.includes_own && p.runs >= 2) {
        Some(pooled(p))
    } else if let Some(e) = own.filter(|e| e.informative) {
        Some(Chosen {
            offset_s: e.offset_s,
            std_s: Some(e.std_error_s),
            source: OffsetSource::Own,
        })
    } else if let Some(p) = priors.pooled {
        Some(pooled(p))
    } else {
        own.map(|e| Chosen {
            offset_s: e.offset_s,
            std_s: Some(e.std_error_s),
            source: OffsetSource::WeakOwn,
        })
    })
}
