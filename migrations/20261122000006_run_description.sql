-- What a run is, for runs flown without (or beside) a plan: the supervisor's
-- description (NULL = not said: the planned experiment's value, else the
-- inferred one applies) and what processing inferred from the data.

ALTER TABLE run ADD COLUMN role TEXT;                        -- 'static' | 'dynamic' | 'recursive' | 'validation'
ALTER TABLE run ADD COLUMN grid_speed_mps DOUBLE PRECISION;  -- SI, whatever unit it was given in
ALTER TABLE run ADD COLUMN excited_dofs TEXT;                -- JSON array of DOF names
ALTER TABLE run ADD COLUMN signal TEXT;                      -- 'square' | 'prbs' | 'multisine' | 'random_binary' | 'other'
ALTER TABLE run ADD COLUMN notes TEXT;
ALTER TABLE run ADD COLUMN inferred TEXT;                    -- JSON: InferredDescription (values, reasons, evidence)
