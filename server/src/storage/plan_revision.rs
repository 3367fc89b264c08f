//! Storing a (re-)generated plan as a version that keeps what did not
//! change: experiments with the identity and content of one the campaign
//! already holds keep that row and id (runs stay matched), an identical
//! plan stores nothing, and every new version records what it changed
//! against the previous one ([`PlanChanges`]). One transaction.

use std::collections::HashMap;

use seatrial_core::planning::revision::{Keyed, identity, revise};
use seatrial_core::planning::{CampaignSpec, Plan};

use super::plans::{
    ChangeCounts, ExperimentChange, ExperimentRow, PlanChanges, StoredPlan, UnmatchedRun, encode,
    experiment_rows, fingerprint, latest_row, plan_fingerprint, schedule, stored_experiment,
    stored_fingerprint, stored_plan,
};
use super::{Db, lock_row, new_id, now};

/// A generated plan with its experiments' identities and fingerprints.
pub struct Fingerprinted {
    /// The plan.
    pub plan: Plan,
    /// Per experiment: identity and content fingerprint.
    pub keys: Vec<(String, String)>,
    /// The plan's fingerprint.
    pub fingerprint: String,
}

impl Fingerprinted {
    /// Fingerprints `plan` (hashes every sample: call it off the async runtime).
    pub fn new(plan: Plan) -> anyhow::Result<Self> {
        let keys = plan
            .experiments
            .iter()
            .map(|p| {
                Ok((
                    identity(&p.experiment),
                    fingerprint(&p.experiment, &p.schedule)?,
                ))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let prints: Vec<&str> = keys.iter().map(|(_, f)| f.as_str()).collect();
        let fingerprint = plan_fingerprint(&plan.totals, &prints)?;
        Ok(Fingerprinted {
            plan,
            keys,
            fingerprint,
        })
    }
}

/// The outcome of storing a plan.
pub struct Stored {
    /// The campaign's newest plan after the call.
    pub plan: StoredPlan,
    /// False when the plan was identical to the newest version, which is
    /// returned as it was (nothing stored).
    pub created: bool,
}

/// Fills in identity and fingerprint of experiments (and the plan) stored
/// before they were recorded.
async fn backfill(
    conn: &mut sqlx::SqliteConnection,
    plan_id: &str,
    totals: &str,
    rows: &mut [ExperimentRow],
) -> anyhow::Result<String> {
    for r in rows.iter_mut() {
        if r.identity.is_some() && r.fingerprint.is_some() {
            continue;
        }
        let e = stored_experiment(r)?.experiment;
        let s = schedule(conn, &r.id).await?;
        let (id, fp) = (identity(&e), stored_fingerprint(&r.detail, &s));
        sqlx::query("UPDATE experiment SET identity = $1, fingerprint = $2 WHERE id = $3")
            .bind(&id)
            .bind(&fp)
            .bind(&r.id)
            .execute(&mut *conn)
            .await?;
        r.identity = Some(id);
        r.fingerprint = Some(fp);
    }
    let prints: Vec<&str> = rows
        .iter()
        .map(|r| r.fingerprint.as_deref().unwrap_or(""))
        .collect();
    let fp = plan_fingerprint(&serde_json::from_str(totals)?, &prints)?;
    sqlx::query("UPDATE plan SET fingerprint = $1 WHERE id = $2")
        .bind(&fp)
        .bind(plan_id)
        .execute(&mut *conn)
        .await?;
    Ok(fp)
}

/// Runs of the campaign matched to `gone` (old id → (code, replacement)).
async fn unmatched_runs(
    conn: &mut sqlx::SqliteConnection,
    campaign_id: &str,
    gone: &HashMap<String, (String, Option<String>)>,
) -> anyhow::Result<Vec<UnmatchedRun>> {
    if gone.is_empty() {
        return Ok(Vec::new());
    }
    let runs: Vec<(String, String, String)> = sqlx::query_as(
        "SELECT id, name, experiment_id FROM run \
         WHERE campaign_id = $1 AND experiment_id IS NOT NULL ORDER BY id",
    )
    .bind(campaign_id)
    .fetch_all(conn)
    .await?;
    Ok(runs
        .into_iter()
        .filter_map(|(run_id, name, eid)| {
            let (code, by) = gone.get(&eid)?;
            Some(UnmatchedRun {
                run_id,
                name,
                code: code.clone(),
                reason: if by.is_some() { "changed" } else { "removed" }.into(),
                replaced_by: by.clone(),
                experiment_id: eid,
            })
        })
        .collect())
}

/// Stores `new` as the campaign's next plan version (and, when given,
/// `spec` as the campaign's spec), unless it is identical to the newest
/// version. `None` when there is no such campaign.
pub async fn store(
    db: &Db,
    campaign_id: &str,
    new: &Fingerprinted,
    spec: Option<&CampaignSpec>,
) -> anyhow::Result<Option<Stored>> {
    let mut tx = db.begin().await?;
    if !lock_row(&mut tx, "campaign", campaign_id).await? {
        return Ok(None);
    }
    if let Some(spec) = spec {
        sqlx::query("UPDATE campaign SET name = $1, spec = $2 WHERE id = $3")
            .bind(&spec.name)
            .bind(serde_json::to_string(spec)?)
            .bind(campaign_id)
            .execute(&mut *tx)
            .await?;
    }
    let latest = latest_row(&mut tx, campaign_id).await?;
    let mut old_rows = Vec::new();
    let mut previous_version = None;
    if let Some(p) = latest {
        old_rows = experiment_rows(&mut tx, &p.id).await?;
        let fp = match &p.fingerprint {
            Some(fp) if old_rows.iter().all(|r| r.fingerprint.is_some()) => fp.clone(),
            _ => backfill(&mut tx, &p.id, &p.totals, &mut old_rows).await?,
        };
        if fp == new.fingerprint {
            let plan = stored_plan(p, &old_rows)?;
            tx.commit().await?;
            return Ok(Some(Stored {
                plan,
                created: false,
            }));
        }
        previous_version = Some(p.version);
    }

    // Experiments the campaign already holds, by identity and content.
    let known: HashMap<(String, String), String> = sqlx::query_as::<_, (String, String, String)>(
        "SELECT e.id, e.identity, e.fingerprint FROM experiment e JOIN plan p ON p.id = e.plan_id \
         WHERE p.campaign_id = $1 AND e.identity IS NOT NULL AND e.fingerprint IS NOT NULL",
    )
    .bind(campaign_id)
    .fetch_all(&mut *tx)
    .await?
    .into_iter()
    .map(|(id, i, f)| ((i, f), id))
    .collect();

    let old_keys: Vec<Keyed<'_>> = old_rows
        .iter()
        .map(|r| Keyed {
            identity: r.identity.as_deref().unwrap_or(""),
            fingerprint: r.fingerprint.as_deref().unwrap_or(""),
        })
        .collect();
    let new_keys: Vec<Keyed<'_>> = new
        .keys
        .iter()
        .map(|(i, f)| Keyed {
            identity: i,
            fingerprint: f,
        })
        .collect();
    let rev = revise(&old_keys, &new_keys);

    // Ids: unchanged keep the old one, others reuse a known row or get a new one.
    let mut ids: Vec<Option<String>> = vec![None; new.keys.len()];
    for &(i, j) in &rev.unchanged {
        ids[i] = Some(old_rows[j].id.clone());
    }
    let mut inserted = vec![false; new.keys.len()];
    for (i, id) in ids.iter_mut().enumerate() {
        if id.is_none() {
            *id = Some(match known.get(&new.keys[i]) {
                Some(k) => k.clone(),
                None => {
                    inserted[i] = true;
                    new_id()
                }
            });
        }
    }
    let ids: Vec<String> = ids.into_iter().flatten().collect();
    let code = |i: usize| new.plan.experiments[i].experiment.code.clone();
    let old_code = |j: usize| stored_experiment(&old_rows[j]).map(|e| e.experiment.code);

    let changes = match previous_version {
        None => None,
        Some(previous_version) => {
            let mut gone = HashMap::new();
            let mut changed = Vec::new();
            for &(i, j) in &rev.changed {
                gone.insert(old_rows[j].id.clone(), (old_code(j)?, Some(ids[i].clone())));
                changed.push(ExperimentChange {
                    id: ids[i].clone(),
                    code: code(i),
                    replaces: Some(old_rows[j].id.clone()),
                });
            }
            let mut removed = Vec::new();
            for &j in &rev.removed {
                gone.insert(old_rows[j].id.clone(), (old_code(j)?, None));
                removed.push(ExperimentChange {
                    id: old_rows[j].id.clone(),
                    code: old_code(j)?,
                    replaces: None,
                });
            }
            Some(PlanChanges {
                previous_version,
                counts: ChangeCounts {
                    added: rev.added.len(),
                    removed: rev.removed.len(),
                    changed: rev.changed.len(),
                    unchanged: rev.unchanged.len(),
                },
                added: rev
                    .added
                    .iter()
                    .map(|&i| ExperimentChange {
                        id: ids[i].clone(),
                        code: code(i),
                        replaces: None,
                    })
                    .collect(),
                removed,
                changed,
                unchanged: rev.unchanged.iter().map(|&(i, _)| ids[i].clone()).collect(),
                unmatched_runs: unmatched_runs(&mut tx, campaign_id, &gone).await?,
            })
        }
    };

    let plan_id = new_id();
    let version = previous_version.unwrap_or(0) + 1;
    let created_at = now();
    let totals = serde_json::to_string(&new.plan.totals)?;
    let changes_json = changes.as_ref().map(serde_json::to_string).transpose()?;
    sqlx::query(
        "INSERT INTO plan (id, campaign_id, version, totals, created_at, fingerprint, changes) \
         VALUES ($1, $2, $3, $4, $5, $6, $7)",
    )
    .bind(&plan_id)
    .bind(campaign_id)
    .bind(version)
    .bind(&totals)
    .bind(&created_at)
    .bind(&new.fingerprint)
    .bind(&changes_json)
    .execute(&mut *tx)
    .await?;
    for (i, p) in new.plan.experiments.iter().enumerate() {
        let e = &p.experiment;
        if inserted[i] {
            sqlx::query(
                "INSERT INTO experiment (id, plan_id, seq, code, family, detail, sample_rate_hz, \
                 n_samples, columns, samples, identity, fingerprint) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)",
            )
            .bind(&ids[i])
            .bind(&plan_id)
            .bind(i64::from(e.seq))
            .bind(&e.code)
            .bind(e.family.name())
            .bind(serde_json::to_string(e)?)
            .bind(p.schedule.sample_rate_hz)
            .bind(i64::try_from(p.schedule.len())?)
            .bind(serde_json::to_string(&p.schedule.columns)?)
            .bind(encode(&p.schedule))
            .bind(&new.keys[i].0)
            .bind(&new.keys[i].1)
            .execute(&mut *tx)
            .await?;
        }
        sqlx::query(
            "INSERT INTO plan_experiment (plan_id, experiment_id, seq) VALUES ($1, $2, $3)",
        )
        .bind(&plan_id)
        .bind(&ids[i])
        .bind(i64::from(e.seq))
        .execute(&mut *tx)
        .await?;
    }
    let rows = experiment_rows(&mut tx, &plan_id).await?;
    let plan = stored_plan(
        super::plans::PlanRow {
            id: plan_id,
            campaign_id: campaign_id.to_string(),
            version,
            totals,
            created_at,
            fingerprint: Some(new.fingerprint.clone()),
            changes: changes_json,
        },
        &rows,
    )?;
    tx.commit().await?;
    Ok(Some(Stored {
        plan,
        created: true,
    }))
}

/// Stores a freshly generated plan (fingerprinting it here): the demo's
/// seeding, where nothing else runs yet.
pub async fn insert(db: &Db, campaign_id: &str, plan: &Plan) -> anyhow::Result<StoredPlan> {
    let new = Fingerprinted::new(plan.clone())?;
    store(db, campaign_id, &new, None)
        .await?
        .map(|s| s.plan)
        .ok_or_else(|| anyhow::anyhow!("no campaign '{campaign_id}'"))
}
