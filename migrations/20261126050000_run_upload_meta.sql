-- The `meta` part a run was uploaded with (JSON): its processing options
-- (rate_hz, shared_channel, clock_offset_s), kept so that a run a stopped
-- server left `stored` is processed at the next start as it would have been.
ALTER TABLE run ADD COLUMN upload_meta TEXT;
