-- Soft deletes with undo (issue 16): a deleted run or model version stays
-- in its table with who deleted it, when and why, so the provenance of
-- every model built from it stays readable; lists leave it out (it is
-- listed with ?deleted=true) and POST …/{id}/restore undoes the delete.
-- The audit trail records the reason of a write beside who and when.

ALTER TABLE run ADD COLUMN deleted_at TEXT;       -- RFC 3339; NULL: not deleted
ALTER TABLE run ADD COLUMN deleted_by TEXT;       -- the acting user's name
ALTER TABLE run ADD COLUMN delete_reason TEXT;    -- why (optional)
ALTER TABLE model ADD COLUMN deleted_at TEXT;
ALTER TABLE model ADD COLUMN deleted_by TEXT;
ALTER TABLE model ADD COLUMN delete_reason TEXT;
ALTER TABLE audit ADD COLUMN note TEXT;           -- the reason given with the write, if any
