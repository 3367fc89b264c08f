-- Clock offsets of two-file runs set by hand (seconds added to navigation
-- time stamps to put them on the control clock): per run, and per campaign
-- (the same two computers throughout). Absent row: no offset set by hand.
-- The offsets estimated from the data live in each run's summary
-- (alignment report); the campaign's pooled offset is computed from those.

CREATE TABLE run_clock_offset (
    run_id          TEXT PRIMARY KEY REFERENCES run(id) ON DELETE CASCADE,
    clock_offset_s  DOUBLE PRECISION NOT NULL,
    updated_at      TEXT NOT NULL
);

CREATE TABLE campaign_clock_offset (
    campaign_id     TEXT PRIMARY KEY REFERENCES campaign(id) ON DELETE CASCADE,
    clock_offset_s  DOUBLE PRECISION NOT NULL,
    updated_at      TEXT NOT NULL
);
