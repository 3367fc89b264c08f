-- Soft deletes of vessels and campaigns (issue 16), as runs and models have
-- them: the row stays with who deleted it, when and why, so the campaigns,
-- runs and models under it stay readable by id (and every model's
-- provenance whole); lists leave it out (?deleted=true lists it), and a
-- deleted vessel's campaigns leave the lists too. POST …/{id}/restore undoes it.

ALTER TABLE vessel ADD COLUMN deleted_at TEXT;    -- RFC 3339; NULL: not deleted
ALTER TABLE vessel ADD COLUMN deleted_by TEXT;    -- the acting user's name
ALTER TABLE vessel ADD COLUMN delete_reason TEXT; -- why (optional)
ALTER TABLE campaign ADD COLUMN deleted_at TEXT;
ALTER TABLE campaign ADD COLUMN deleted_by TEXT;
ALTER TABLE campaign ADD COLUMN delete_reason TEXT;
