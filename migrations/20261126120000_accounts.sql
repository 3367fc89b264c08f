-- Accounts and roles (issue 17): users with a role, browser sessions,
-- personal API tokens and the audit trail of every write. Conventions as
-- elsewhere: TEXT ids (UUIDv7), RFC 3339 TEXT timestamps in UTC. Secrets
-- are never stored: passwords as argon2id PHC strings, session cookies and
-- API tokens as the SHA-256 (hex) of their 256-bit random value.

-- `app_user`, not `user`: a reserved word in PostgreSQL.
CREATE TABLE app_user (
    id             TEXT PRIMARY KEY,
    name           TEXT NOT NULL UNIQUE,          -- login name
    role           TEXT NOT NULL CHECK (role IN ('viewer', 'supervisor', 'engineer', 'admin')),
    password_hash  TEXT NOT NULL,                 -- argon2id PHC string
    disabled_at    TEXT,                          -- NULL: may sign in
    created_at     TEXT NOT NULL,
    created_by     TEXT                           -- user id; NULL: the first admin, made at start
);

CREATE TABLE session (
    id          TEXT PRIMARY KEY,
    user_id     TEXT NOT NULL REFERENCES app_user(id),
    token_hash  TEXT NOT NULL UNIQUE,             -- SHA-256 of the cookie value
    created_at  TEXT NOT NULL,
    expires_at  TEXT NOT NULL
);
CREATE INDEX session_user ON session(user_id);

CREATE TABLE api_token (
    id            TEXT PRIMARY KEY,
    user_id       TEXT NOT NULL REFERENCES app_user(id),
    name          TEXT NOT NULL,
    role          TEXT NOT NULL CHECK (role IN ('viewer', 'supervisor', 'engineer', 'admin')),
    token_hash    TEXT NOT NULL UNIQUE,           -- SHA-256 of the token
    prefix        TEXT NOT NULL,                  -- the token's first characters, to tell tokens apart
    created_at    TEXT NOT NULL,
    expires_at    TEXT,                           -- NULL: until revoked
    last_used_at  TEXT,
    revoked_at    TEXT                            -- NULL: valid
);
CREATE INDEX api_token_user ON api_token(user_id);

-- One row per write request (and per sign-in attempt), newest id last.
CREATE TABLE audit (
    id         TEXT PRIMARY KEY,                  -- UUIDv7: ordered by time
    at         TEXT NOT NULL,
    user_id    TEXT,                              -- NULL: local mode, or a failed sign-in
    user_name  TEXT NOT NULL,
    via        TEXT NOT NULL CHECK (via IN ('session', 'token', 'local', 'login')),
    method     TEXT NOT NULL,
    route      TEXT NOT NULL,                     -- the route template, e.g. /api/runs/{id}
    path       TEXT NOT NULL,                     -- the path as requested
    target_id  TEXT,                              -- the `{id}` of the route, or the id created
    status     INTEGER NOT NULL
);
CREATE INDEX audit_user ON audit(user_id);
