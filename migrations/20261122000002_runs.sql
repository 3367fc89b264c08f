-- Uploaded runs. The bytes live in content-addressed files (<data>/blobs/<sha256>),
-- written and fsynced before the row that references them; a run is never
-- deleted when its processing fails (status 'rejected', error kept).

CREATE TABLE blob (
    sha256      TEXT PRIMARY KEY,
    size_bytes  BIGINT NOT NULL,
    created_at  TEXT NOT NULL
);

CREATE TABLE run (
    id             TEXT PRIMARY KEY,
    campaign_id    TEXT NOT NULL REFERENCES campaign(id),
    experiment_id  TEXT REFERENCES experiment(id),
    name           TEXT NOT NULL,
    layout         TEXT NOT NULL,        -- 'single' | 'split' (control + nav)
    status         TEXT NOT NULL,        -- 'stored' | 'accepted' | 'rejected'
    error          TEXT,                 -- JSON: why it was rejected
    summary        TEXT,                 -- JSON: rows, rates, gaps, warnings, alignment
    created_at     TEXT NOT NULL
);
CREATE INDEX run_campaign ON run(campaign_id);

CREATE TABLE run_file (
    run_id      TEXT NOT NULL REFERENCES run(id),
    role        TEXT NOT NULL,           -- 'file' | 'control' | 'nav'
    filename    TEXT NOT NULL,
    sha256      TEXT NOT NULL REFERENCES blob(sha256),
    size_bytes  BIGINT NOT NULL,
    PRIMARY KEY (run_id, role)
);

CREATE TABLE run_quality (
    run_id      TEXT PRIMARY KEY REFERENCES run(id),
    report      TEXT NOT NULL,           -- JSON: seatrial_core::quality::QualityReport
    created_at  TEXT NOT NULL
);
