//! Plans and their experiments; schedules stored as little-endian f64
//! blobs, column after column. A plan version lists its experiments through
//! `plan_experiment`; an experiment unchanged by a re-plan is shared by the
//! versions that hold it ([`super::plan_revision`]).

use seatrial_core::planning::{Experiment, PlanTotals, Schedule};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::Db;

/// A stored plan without its experiments' samples.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct StoredPlan {
    /// Id (UUIDv7).
    pub id: String,
    /// Campaign.
    pub campaign_id: String,
    /// Version, from 1; the newest is the campaign's plan.
    pub version: i64,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// Totals: count, run time, set-up time, total trial time.
    pub totals: PlanTotals,
    /// Experiments in run order.
    pub experiments: Vec<StoredExperiment>,
    /// What this version changed against the version before it; none for
    /// the first version (and for versions stored before re-planning was
    /// versioned).
    pub changes: Option<PlanChanges>,
}

/// A stored experiment (description and checks; samples separately).
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct StoredExperiment {
    /// Id (UUIDv7): the `{eid}` of the schedule routes and a run's
    /// `experiment_id`. Kept by every re-plan that leaves the experiment
    /// unchanged.
    pub id: String,
    /// Description, channels, analysis, warnings (`seq`: the place in this
    /// version's run order).
    #[serde(flatten)]
    pub experiment: Experiment,
}

/// An experiment named in a plan's changes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
pub struct ExperimentChange {
    /// Experiment id (for a removed experiment: the previous version's).
    pub id: String,
    /// Its code.
    pub code: String,
    /// A changed experiment: the id of the experiment it replaces.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaces: Option<String>,
}

/// A run matched to an experiment that a re-plan removed or changed: it no
/// longer covers the plan, and the supervisor decides what becomes of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
pub struct UnmatchedRun {
    /// Run id.
    pub run_id: String,
    /// Run name.
    pub name: String,
    /// The experiment it was flown for.
    pub experiment_id: String,
    /// That experiment's code.
    pub code: String,
    /// `removed` (no such experiment any more) or `changed` (its schedule changed).
    pub reason: String,
    /// A changed experiment: the id of the experiment that replaces it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaced_by: Option<String>,
}

/// Experiment counts of a re-plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
pub struct ChangeCounts {
    /// New identities.
    pub added: usize,
    /// Identities dropped.
    pub removed: usize,
    /// Same identity, new content: new id.
    pub changed: usize,
    /// Same identity and content: same id.
    pub unchanged: usize,
}

/// What a plan version changed against the previous one. An experiment is
/// identified by family, grid speed, DOFs, static sign and repetition; it
/// is unchanged when its description and every schedule sample are too.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
pub struct PlanChanges {
    /// The version compared with.
    pub previous_version: i64,
    /// Counts.
    pub counts: ChangeCounts,
    /// Experiments added.
    pub added: Vec<ExperimentChange>,
    /// Experiments of the previous version no longer planned.
    pub removed: Vec<ExperimentChange>,
    /// Experiments whose schedule or description changed (new ids).
    pub changed: Vec<ExperimentChange>,
    /// Ids of the experiments carried over unchanged.
    pub unchanged: Vec<String>,
    /// Runs matched to removed or changed experiments when the version was made.
    pub unmatched_runs: Vec<UnmatchedRun>,
}

#[derive(sqlx::FromRow)]
pub(crate) struct PlanRow {
    pub id: String,
    pub campaign_id: String,
    pub version: i64,
    pub totals: String,
    pub created_at: String,
    pub fingerprint: Option<String>,
    pub changes: Option<String>,
}

pub(crate) const PLAN_COLUMNS: &str =
    "id, campaign_id, version, totals, created_at, fingerprint, changes";

/// An experiment of one version, with what the comparison needs.
#[derive(sqlx::FromRow)]
pub(crate) struct ExperimentRow {
    pub id: String,
    pub seq: i64,
    pub detail: String,
    pub identity: Option<String>,
    pub fingerprint: Option<String>,
}

#[derive(sqlx::FromRow)]
pub(crate) struct ScheduleRow {
    pub sample_rate_hz: f64,
    pub n_samples: i64,
    pub columns: String,
    pub samples: Vec<u8>,
}

pub(crate) fn encode(s: &Schedule) -> Vec<u8> {
    let mut out = Vec::with_capacity(s.values.len() * s.len() * 8);
    for col in &s.values {
        for v in col {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

pub(crate) fn decode(r: ScheduleRow) -> anyhow::Result<Schedule> {
    let columns: Vec<String> = serde_json::from_str(&r.columns)?;
    let n = usize::try_from(r.n_samples)?;
    anyhow::ensure!(
        r.samples.len() == columns.len() * n * 8,
        "schedule blob has the wrong size"
    );
    let values = r
        .samples
        .chunks_exact(n.max(1) * 8)
        .take(columns.len())
        .map(|c| {
            c.chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
                .collect()
        })
        .collect();
    Ok(Schedule {
        sample_rate_hz: r.sample_rate_hz,
        columns,
        values,
    })
}

/// SHA-256 (hex) of an experiment's content: its description without the
/// run-order position, and its schedule (rate, column names, samples).
pub fn fingerprint(e: &Experiment, s: &Schedule) -> anyhow::Result<String> {
    let mut described = e.clone();
    described.seq = 0;
    Ok(content_hash(&serde_json::to_string(&described)?, s))
}

/// [`fingerprint`] of a stored experiment from its `detail` text as stored
/// (hashing the text itself, not a re-serialization of what it parses to,
/// which need not give the same digits).
pub(crate) fn stored_fingerprint(detail: &str, s: &Schedule) -> String {
    // `seq` is the first field of the stored description.
    let described = match detail.strip_prefix("{\"seq\":") {
        Some(rest) => {
            let digits = rest
                .find(|c: char| !c.is_ascii_digit())
                .unwrap_or(rest.len());
            format!("{{\"seq\":0{}", &rest[digits..])
        }
        None => detail.to_string(),
    };
    content_hash(&described, s)
}

fn content_hash(described: &str, s: &Schedule) -> String {
    let mut h = Sha256::new();
    h.update(described.as_bytes());
    h.update(s.sample_rate_hz.to_le_bytes());
    for c in &s.columns {
        h.update(c.as_bytes());
        h.update([0]);
    }
    h.update(encode(s));
    hex::encode(h.finalize())
}

/// SHA-256 (hex) of a plan: its totals and its experiments' fingerprints
/// in run order.
pub fn plan_fingerprint(totals: &PlanTotals, experiments: &[&str]) -> anyhow::Result<String> {
    let mut h = Sha256::new();
    h.update(serde_json::to_vec(totals)?);
    for f in experiments {
        h.update(f.as_bytes());
    }
    Ok(hex::encode(h.finalize()))
}

/// The experiments of plan `plan_id` in its run order.
pub(crate) async fn experiment_rows(
    conn: &mut sqlx::SqliteConnection,
    plan_id: &str,
) -> anyhow::Result<Vec<ExperimentRow>> {
    Ok(sqlx::query_as::<_, ExperimentRow>(
        "SELECT e.id, pe.seq, e.detail, e.identity, e.fingerprint \
         FROM plan_experiment pe JOIN experiment e ON e.id = pe.experiment_id \
         WHERE pe.plan_id = $1 ORDER BY pe.seq",
    )
    .bind(plan_id)
    .fetch_all(conn)
    .await?)
}

/// The newest plan row of a campaign.
pub(crate) async fn latest_row(
    conn: &mut sqlx::SqliteConnection,
    campaign_id: &str,
) -> anyhow::Result<Option<PlanRow>> {
    Ok(sqlx::query_as::<_, PlanRow>(sqlx::AssertSqlSafe(format!(
        "SELECT {PLAN_COLUMNS} FROM plan WHERE campaign_id = $1 ORDER BY version DESC LIMIT 1"
    )))
    .bind(campaign_id)
    .fetch_optional(conn)
    .await?)
}

/// A stored experiment from its row, with the version's run-order position.
pub(crate) fn stored_experiment(r: &ExperimentRow) -> anyhow::Result<StoredExperiment> {
    let mut experiment: Experiment = serde_json::from_str(&r.detail)?;
    experiment.seq = u32::try_from(r.seq)?;
    Ok(StoredExperiment {
        id: r.id.clone(),
        experiment,
    })
}

/// A plan from its row and its experiments' rows.
pub(crate) fn stored_plan(p: PlanRow, rows: &[ExperimentRow]) -> anyhow::Result<StoredPlan> {
    Ok(StoredPlan {
        id: p.id,
        campaign_id: p.campaign_id,
        version: p.version,
        created_at: p.created_at,
        totals: serde_json::from_str(&p.totals)?,
        experiments: rows
            .iter()
            .map(stored_experiment)
            .collect::<anyhow::Result<_>>()?,
        changes: p.changes.as_deref().map(serde_json::from_str).transpose()?,
    })
}

/// The newest plan of a campaign.
pub async fn latest(db: &Db, campaign_id: &str) -> anyhow::Result<Option<StoredPlan>> {
    let mut conn = db.acquire().await?;
    let Some(p) = latest_row(&mut conn, campaign_id).await? else {
        return Ok(None);
    };
    let rows = experiment_rows(&mut conn, &p.id).await?;
    Ok(Some(stored_plan(p, &rows)?))
}

/// The schedule of experiment `eid`.
pub(crate) async fn schedule(
    conn: &mut sqlx::SqliteConnection,
    eid: &str,
) -> anyhow::Result<Schedule> {
    let r = sqlx::query_as::<_, ScheduleRow>(
        "SELECT sample_rate_hz, n_samples, columns, samples FROM experiment WHERE id = $1",
    )
    .bind(eid)
    .fetch_one(conn)
    .await?;
    decode(r)
}

/// One experiment of any of a campaign's plan versions, with its schedule;
/// `seq` is its place in the newest version that holds it.
pub async fn experiment(
    db: &Db,
    campaign_id: &str,
    eid: &str,
) -> anyhow::Result<Option<(StoredExperiment, Schedule)>> {
    let mut conn = db.acquire().await?;
    let row = sqlx::query_as::<_, ExperimentRow>(
        "SELECT e.id, pe.seq, e.detail, e.identity, e.fingerprint \
         FROM plan_experiment pe JOIN plan p ON p.id = pe.plan_id \
         JOIN experiment e ON e.id = pe.experiment_id \
         WHERE e.id = $1 AND p.campaign_id = $2 ORDER BY p.version DESC LIMIT 1",
    )
    .bind(eid)
    .bind(campaign_id)
    .fetch_optional(&mut *conn)
    .await?;
    let Some(r) = row else { return Ok(None) };
    let schedule = schedule(&mut conn, &r.id).await?;
    Ok(Some((stored_experiment(&r)?, schedule)))
}
