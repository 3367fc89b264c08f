-- Vessels, campaigns and their plans. Portable SQL: TEXT ids (UUIDv7),
-- TEXT timestamps (RFC 3339), TEXT JSON documents, BLOB samples (BYTEA on
-- PostgreSQL). No AUTOINCREMENT, no SQLite-only types.

CREATE TABLE vessel (
    id          TEXT PRIMARY KEY,
    name        TEXT NOT NULL,
    kind        TEXT NOT NULL,
    profile     TEXT NOT NULL,           -- JSON: seatrial_core::planning::VesselProfile
    created_at  TEXT NOT NULL
);

CREATE TABLE campaign (
    id          TEXT PRIMARY KEY,
    vessel_id   TEXT NOT NULL REFERENCES vessel(id),
    name        TEXT NOT NULL,
    spec        TEXT NOT NULL,           -- JSON: seatrial_core::planning::CampaignSpec
    created_at  TEXT NOT NULL
);
CREATE INDEX campaign_vessel ON campaign(vessel_id);

-- A plan is regenerated on request; every generation is a new version and
-- the newest is the campaign's plan.
CREATE TABLE plan (
    id           TEXT PRIMARY KEY,
    campaign_id  TEXT NOT NULL REFERENCES campaign(id),
    version      INTEGER NOT NULL,
    totals       TEXT NOT NULL,          -- JSON: PlanTotals
    created_at   TEXT NOT NULL,
    UNIQUE (campaign_id, version)
);

CREATE TABLE experiment (
    id            TEXT PRIMARY KEY,
    plan_id       TEXT NOT NULL REFERENCES plan(id),
    seq           INTEGER NOT NULL,
    code          TEXT NOT NULL,
    family        TEXT NOT NULL,
    detail        TEXT NOT NULL,         -- JSON: Experiment (channels, analysis, warnings)
    sample_rate_hz DOUBLE PRECISION NOT NULL,
    n_samples     INTEGER NOT NULL,
    columns       TEXT NOT NULL,         -- JSON array of column names
    samples       BLOB NOT NULL,         -- little-endian f64, column after column
    UNIQUE (plan_id, seq)
);
