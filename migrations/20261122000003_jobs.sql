-- Background jobs (identification, discovery, …): a persisted queue that
-- survives restarts. Portable SQL like the other migrations: TEXT ids
-- (UUIDv7), TEXT JSON documents, and TEXT timestamps in RFC 3339 UTC with
-- exactly three fractional digits, so that they compare correctly as text
-- (the lease expiry and the queue order depend on it).

CREATE TABLE job (
    id               TEXT PRIMARY KEY,
    kind             TEXT NOT NULL,              -- the registered handler, e.g. 'identify'
    campaign_id      TEXT REFERENCES campaign(id),
    request          TEXT NOT NULL,              -- JSON: kind, campaign_id, run_ids, method, settings, model_id
    state            TEXT NOT NULL
        CHECK (state IN ('queued', 'running', 'succeeded', 'failed', 'cancelled', 'interrupted')),
    progress         DOUBLE PRECISION NOT NULL DEFAULT 0,   -- 0–1 of the current attempt
    stage            TEXT NOT NULL DEFAULT '',
    result           TEXT,                       -- JSON written by the handler on success
    error            TEXT,                       -- JSON {message, field?} on failure or interruption
    attempts         INTEGER NOT NULL DEFAULT 0, -- claims so far (a restart after a crash is one more)
    max_attempts     INTEGER NOT NULL,
    cancel_requested BOOLEAN NOT NULL DEFAULT FALSE,
    worker           TEXT,                       -- the claiming worker (process + slot)
    lease_until      TEXT,                       -- a running job whose lease expired is orphaned
    created_at       TEXT NOT NULL,
    started_at       TEXT,
    finished_at      TEXT,
    updated_at       TEXT NOT NULL
);
CREATE INDEX job_queue ON job(state, created_at);
CREATE INDEX job_campaign ON job(campaign_id);
