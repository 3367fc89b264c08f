-- Re-planning keeps what did not change. A plan version lists its
-- experiments through plan_experiment (with their place in that version's
-- run order); an experiment whose identity and content are unchanged is the
-- same row, with the same id, in every version that holds it, so runs
-- matched to it stay matched. Identity: family, grid speed, DOFs, sign,
-- repetition (`identity`); content: SHA-256 of the description and the
-- schedule (`fingerprint`). A plan's fingerprint covers its totals and its
-- experiments in order: re-planning to the same fingerprint stores nothing.

CREATE TABLE plan_experiment (
    plan_id        TEXT NOT NULL REFERENCES plan(id),
    experiment_id  TEXT NOT NULL REFERENCES experiment(id),
    seq            INTEGER NOT NULL,      -- run order in this version, from 1
    PRIMARY KEY (plan_id, seq),
    UNIQUE (plan_id, experiment_id)
);
CREATE INDEX plan_experiment_experiment ON plan_experiment(experiment_id);

-- Every experiment so far belongs to the version that created it.
INSERT INTO plan_experiment (plan_id, experiment_id, seq)
    SELECT plan_id, id, seq FROM experiment;

ALTER TABLE experiment ADD COLUMN identity TEXT;     -- NULL: computed when first compared
ALTER TABLE experiment ADD COLUMN fingerprint TEXT;  -- NULL: computed when first compared
ALTER TABLE plan ADD COLUMN fingerprint TEXT;        -- NULL: computed when first compared
ALTER TABLE plan ADD COLUMN changes TEXT;            -- JSON: PlanChanges against the previous version
