-- Missing-physics discovery reports. One row per `discover` job: the model it
-- examined, the augmented model it stored as that model's next version (none
-- when nothing was named), the runs used, and the report (JSON: location,
-- ranked hypotheses with evidence, before/after fits and plots, ambiguities
-- with the deciding experiment, unexplained structure) per grid speed.

CREATE TABLE discrepancy (
    id                 TEXT PRIMARY KEY,
    model_id           TEXT NOT NULL REFERENCES model(id),
    augmented_model_id TEXT REFERENCES model(id),
    campaign_id        TEXT NOT NULL REFERENCES campaign(id),
    job_id             TEXT,
    settings           TEXT NOT NULL,        -- JSON: settings as used
    run_ids            TEXT NOT NULL,        -- JSON: runs the augmentation was fitted on
    validation_run_ids TEXT NOT NULL,        -- JSON: runs held out for before/after
    summary            TEXT NOT NULL,        -- JSON: the story in sentences
    report             TEXT NOT NULL,        -- JSON: the full report
    software_version   TEXT NOT NULL,
    created_at         TEXT NOT NULL
);
CREATE INDEX discrepancy_model ON discrepancy(model_id);
