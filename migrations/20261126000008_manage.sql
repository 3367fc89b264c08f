-- Managing data: a run can be excluded from identification (with the reason
-- and when), and runs, models and campaigns renamed. Runs with no model or
-- discovery report built from them, and model versions nothing was derived
-- from, are deleted outright (DELETE routes); rows referencing them go in
-- the same transaction.

ALTER TABLE run ADD COLUMN excluded BOOLEAN NOT NULL DEFAULT FALSE;
ALTER TABLE run ADD COLUMN excluded_reason TEXT;   -- why (required when excluded)
ALTER TABLE run ADD COLUMN excluded_at TEXT;       -- RFC 3339, when it was excluded
ALTER TABLE model ADD COLUMN notes TEXT;           -- free notes of the engineer
CREATE INDEX model_parent ON model(parent_id);
