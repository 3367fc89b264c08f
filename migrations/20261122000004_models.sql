-- Identified models, versioned. A lineage groups the versions of one model
-- (re-identification of a campaign with the same method, or a model augmented
-- by missing-physics discovery); version counts from 1 within a lineage.
-- Provenance: the runs, method and settings, software version, the job, time.

CREATE TABLE model (
    id                TEXT PRIMARY KEY,
    lineage_id        TEXT NOT NULL,
    version           INTEGER NOT NULL,
    parent_id         TEXT REFERENCES model(id),
    campaign_id       TEXT NOT NULL REFERENCES campaign(id),
    vessel_id         TEXT NOT NULL REFERENCES vessel(id),
    kind              TEXT NOT NULL,        -- 'lpv' | 'dp_ship' | 'state_space'
    method            TEXT NOT NULL,        -- 'lambda_kf' | 'parallel_ekf' | 'n4sid' | 'discovery'
    name              TEXT NOT NULL,
    settings          TEXT NOT NULL,        -- JSON: the method's settings as used
    run_ids           TEXT NOT NULL,        -- JSON: estimation runs
    validation_run_ids TEXT NOT NULL,       -- JSON: runs held out for validation
    software_version  TEXT NOT NULL,
    job_id            TEXT,
    document          TEXT NOT NULL,        -- JSON: the model (matrices, parameters, uncertainties)
    validation        TEXT NOT NULL,        -- JSON: validation reports per held-out run
    created_at        TEXT NOT NULL,
    UNIQUE (lineage_id, version)
);
CREATE INDEX model_campaign ON model(campaign_id);
