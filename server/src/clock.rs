//! Clock offsets of a campaign's two-file runs: the estimates stored in the
//! runs' alignment reports, the campaign's offset pooled from them, the
//! offsets set by hand, and the priors a run is read with.
//!
//! When they are computed: at upload, from the campaign's runs stored
//! before (a weak run uploaded first keeps the source it had — its quality
//! report is not recomputed when an informative run arrives later; an
//! informative run is merged with its own estimate, which joins the pool
//! only once stored; the `GET /api/campaigns/{id}/clock-offset` view shows
//! what each would use now); at job time, from every accepted two-file run
//! of the campaign as they are then, with the offsets set by hand at that
//! moment — so a job always uses the current pooled offset, also for the
//! informative runs whose estimates it holds.

use std::collections::HashMap;

use seatrial_core::alignment::{
    Chosen, OffsetEstimate, OffsetPriors, PooledOffset, PooledValue, RunOffset, choose_offset,
    pool_offsets,
};

use crate::storage::Db;
use crate::storage::clock_offsets;
use crate::storage::runs::{self, Run};

/// The run's own offset estimate from its stored alignment report; `None`
/// for single-file runs, rejected runs, runs whose shared channel gave no
/// estimate, and reports written before estimates were calibrated.
pub fn own_estimate(run: &Run) -> Option<OffsetEstimate> {
    if run.layout != "split" || run.status != "accepted" {
        return None;
    }
    let v = run.summary.as_ref()?.pointer("/alignment/offset")?;
    serde_json::from_value(v.clone()).ok()
}

/// The campaign's offset pooled from the own estimates of `runs`.
pub fn pooled(runs: &[Run]) -> Option<PooledOffset> {
    let offsets: Vec<RunOffset> = runs
        .iter()
        .filter_map(|r| {
            own_estimate(r).map(|e| RunOffset {
                run_id: r.id.clone(),
                name: r.name.clone(),
                offset_s: e.offset_s,
                std_s: e.std_error_s,
                informative: e.informative,
            })
        })
        .collect();
    pool_offsets(&offsets)
}

/// What a campaign knows about its clocks.
#[derive(Debug, Clone, Default)]
pub struct CampaignClocks {
    /// The campaign's offset set by hand.
    pub user_campaign_s: Option<f64>,
    /// Offsets set by hand per run.
    pub user_runs: HashMap<String, f64>,
    /// The offset pooled from the runs' own estimates.
    pub pooled: Option<PooledOffset>,
}

impl CampaignClocks {
    /// Loads the campaign's offsets, pooling its stored runs' estimates.
    pub async fn load(db: &Db, campaign_id: &str) -> anyhow::Result<Self> {
        let all = runs::list(db, campaign_id).await?;
        Ok(CampaignClocks {
            user_campaign_s: clock_offsets::campaign_offset(db, campaign_id).await?,
            user_runs: clock_offsets::run_offsets(db, campaign_id).await?,
            pooled: pooled(&all),
        })
    }

    /// The priors run `run_id` is read with (its own hand-set offset, if
    /// any, the campaign's, the pooled one and whether it pools the run's
    /// own estimate — then the pool is used rather than the estimate).
    pub fn priors_for(&self, run_id: Option<&str>) -> OffsetPriors {
        OffsetPriors {
            user_run_s: run_id.and_then(|id| self.user_runs.get(id).copied()),
            user_campaign_s: self.user_campaign_s,
            pooled: self.pooled.as_ref().map(|p| PooledValue {
                offset_s: p.offset_s,
                std_s: p.std_s,
                runs: p.runs_used.len(),
                includes_own: run_id.is_some_and(|id| p.runs_used.iter().any(|u| u == id)),
            }),
        }
    }

    /// The offset a two-file run would be read with now (without reading
    /// its files): `None` for single-file runs and runs with neither an own
    /// estimate nor a prior.
    pub fn decide(&self, run: &Run) -> Option<Chosen> {
        if run.layout != "split" {
            return None;
        }
        let own = own_estimate(run);
        choose_offset(own.as_ref(), &self.priors_for(Some(&run.id)))
            .ok()
            .flatten()
    }
}
