//! Accounts: users with a role, browser sessions and personal API tokens.
//! Secrets are stored only as hashes (see the accounts migration); the
//! hashing itself is in `http::auth::secrets`.

use serde::{Deserialize, Serialize};

use super::{Db, Page, new_id, now};

/// What a user (or a token) may do; each role includes the ones before it.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, utoipa::ToSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Reads everything.
    Viewer,
    /// Also plans campaigns, uploads and edits runs, runs jobs.
    Supervisor,
    /// Also creates vessel profiles, sets campaign clock offsets, edits and deletes models.
    Engineer,
    /// Also manages users, everyone's tokens, and reads the audit trail.
    Admin,
}

impl Role {
    /// The name stored and shown (`viewer` …).
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Viewer => "viewer",
            Role::Supervisor => "supervisor",
            Role::Engineer => "engineer",
            Role::Admin => "admin",
        }
    }

    fn parse(s: &str) -> anyhow::Result<Role> {
        Ok(match s {
            "viewer" => Role::Viewer,
            "supervisor" => Role::Supervisor,
            "engineer" => Role::Engineer,
            "admin" => Role::Admin,
            other => anyhow::bail!("unknown role '{other}' in the database"),
        })
    }
}

/// A user account (never its password hash).
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct User {
    /// Id (UUIDv7).
    pub id: String,
    /// Login name.
    pub name: String,
    /// Role.
    pub role: Role,
    /// Whether the account may sign in and its tokens work.
    pub disabled: bool,
    /// When it was disabled (RFC 3339).
    pub disabled_at: Option<String>,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// The admin who created it (`null`: the first admin, made at start).
    pub created_by: Option<String>,
}

#[derive(sqlx::FromRow)]
struct UserRow {
    id: String,
    name: String,
    role: String,
    password_hash: String,
    disabled_at: Option<String>,
    created_at: String,
    created_by: Option<String>,
}

impl UserRow {
    fn user(self) -> anyhow::Result<(User, String)> {
        let user = User {
            id: self.id,
            name: self.name,
            role: Role::parse(&self.role)?,
            disabled: self.disabled_at.is_some(),
            disabled_at: self.disabled_at,
            created_at: self.created_at,
            created_by: self.created_by,
        };
        Ok((user, self.password_hash))
    }
}

const USER_COLS: &str = "id, name, role, password_hash, disabled_at, created_at, created_by";

/// How many accounts exist.
pub async fn count_users(db: &Db) -> anyhow::Result<i64> {
    Ok(sqlx::query_scalar("SELECT COUNT(*) FROM app_user")
        .fetch_one(db)
        .await?)
}

/// Creates an account; `None` when the name is taken.
pub async fn insert_user(
    db: &Db,
    name: &str,
    role: Role,
    password_hash: &str,
    created_by: Option<&str>,
) -> anyhow::Result<Option<User>> {
    let user = User {
        id: new_id(),
        name: name.to_string(),
        role,
        disabled: false,
        disabled_at: None,
        created_at: now(),
        created_by: created_by.map(String::from),
    };
    let done = sqlx::query(
        "INSERT INTO app_user (id, name, role, password_hash, created_at, created_by) \
         SELECT $1, $2, $3, $4, $5, $6 WHERE NOT EXISTS (SELECT 1 FROM app_user WHERE name = $2)",
    )
    .bind(&user.id)
    .bind(&user.name)
    .bind(role.as_str())
    .bind(password_hash)
    .bind(&user.created_at)
    .bind(&user.created_by)
    .execute(db)
    .await?;
    Ok((done.rows_affected() == 1).then_some(user))
}

/// Accounts by creation, one page, with the total.
pub async fn page_users(db: &Db, page: Page) -> anyhow::Result<(Vec<User>, i64)> {
    let rows: Vec<UserRow> = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT {USER_COLS} FROM app_user ORDER BY id LIMIT $1 OFFSET $2"
    )))
    .bind(page.sql_limit())
    .bind(page.offset)
    .fetch_all(db)
    .await?;
    let total = count_users(db).await?;
    let users = rows
        .into_iter()
        .map(|r| r.user().map(|(u, _)| u))
        .collect::<anyhow::Result<_>>()?;
    Ok((users, total))
}

/// One account by id.
pub async fn get_user(db: &Db, id: &str) -> anyhow::Result<Option<User>> {
    let row: Option<UserRow> = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT {USER_COLS} FROM app_user WHERE id = $1"
    )))
    .bind(id)
    .fetch_optional(db)
    .await?;
    Ok(row.map(UserRow::user).transpose()?.map(|(u, _)| u))
}

/// An account by login name, with its password hash (for signing in).
pub async fn user_for_login(db: &Db, name: &str) -> anyhow::Result<Option<(User, String)>> {
    let row: Option<UserRow> = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT {USER_COLS} FROM app_user WHERE name = $1"
    )))
    .bind(name)
    .fetch_optional(db)
    .await?;
    row.map(UserRow::user).transpose()
}

/// A change to an account; absent fields are kept.
#[derive(Debug, Default)]
pub struct UserUpdate {
    /// New role.
    pub role: Option<Role>,
    /// Disable (true) or enable (false).
    pub disabled: Option<bool>,
    /// New password hash.
    pub password_hash: Option<String>,
}

/// Why an account change was refused.
#[derive(Debug)]
pub enum UpdateRefused {
    /// No such account.
    Missing,
    /// It would leave no enabled admin.
    LastAdmin,
}

/// Changes an account in one transaction. Disabling it or changing its
/// password ends its sessions; a change that would leave no enabled admin
/// is refused.
pub async fn update_user(
    db: &Db,
    id: &str,
    change: UserUpdate,
) -> anyhow::Result<Result<User, UpdateRefused>> {
    let mut tx = db.begin().await?;
    if !super::lock_row(&mut tx, "app_user", id).await? {
        return Ok(Err(UpdateRefused::Missing));
    }
    let (before, _) = sqlx::query_as::<_, UserRow>(sqlx::AssertSqlSafe(format!(
        "SELECT {USER_COLS} FROM app_user WHERE id = $1"
    )))
    .bind(id)
    .fetch_one(&mut *tx)
    .await?
    .user()?;
    let role = change.role.unwrap_or(before.role);
    let disabled = change.disabled.unwrap_or(before.disabled);
    if before.role == Role::Admin && !before.disabled && (role != Role::Admin || disabled) {
        let others: i64 = sqlx::query_scalar(
            "SELECT COUNT(*) FROM app_user WHERE role = 'admin' AND disabled_at IS NULL AND id <> $1",
        )
        .bind(id)
        .fetch_one(&mut *tx)
        .await?;
        if others == 0 {
            return Ok(Err(UpdateRefused::LastAdmin));
        }
    }
    let disabled_at = match (before.disabled, disabled) {
        (false, true) => Some(now()),
        (true, true) => before.disabled_at.clone(),
        _ => None,
    };
    sqlx::query("UPDATE app_user SET role = $1, disabled_at = $2 WHERE id = $3")
        .bind(role.as_str())
        .bind(&disabled_at)
        .bind(id)
        .execute(&mut *tx)
        .await?;
    if let Some(hash) = &change.password_hash {
        sqlx::query("UPDATE app_user SET password_hash = $1 WHERE id = $2")
            .bind(hash)
            .bind(id)
            .execute(&mut *tx)
            .await?;
    }
    if disabled || change.password_hash.is_some() {
        sqlx::query("DELETE FROM session WHERE user_id = $1")
            .bind(id)
            .execute(&mut *tx)
            .await?;
    }
    tx.commit().await?;
    Ok(Ok(User {
        role,
        disabled,
        disabled_at,
        ..before
    }))
}

/// Whether an RFC 3339 time lies in the future (an unreadable one does not).
pub fn in_future(at: &str) -> bool {
    time::OffsetDateTime::parse(at, &time::format_description::well_known::Rfc3339)
        .is_ok_and(|t| t > time::OffsetDateTime::now_utc())
}

/// RFC 3339 time `secs` seconds from now.
pub fn from_now(secs: i64) -> String {
    (time::OffsetDateTime::now_utc() + time::Duration::seconds(secs))
        .format(&time::format_description::well_known::Rfc3339)
        .unwrap_or_default()
}

/// Stores a new session for `user_id` under the hash of its cookie value,
/// and drops the user's expired ones (RFC 3339 UTC strings of one format
/// order like their times, to within the second).
pub async fn insert_session(
    db: &Db,
    user_id: &str,
    token_hash: &str,
    lifetime_secs: i64,
) -> anyhow::Result<()> {
    sqlx::query("DELETE FROM session WHERE user_id = $1 AND expires_at < $2")
        .bind(user_id)
        .bind(now())
        .execute(db)
        .await?;
    sqlx::query(
        "INSERT INTO session (id, user_id, token_hash, created_at, expires_at) \
         VALUES ($1, $2, $3, $4, $5)",
    )
    .bind(new_id())
    .bind(user_id)
    .bind(token_hash)
    .bind(now())
    .bind(from_now(lifetime_secs))
    .execute(db)
    .await?;
    Ok(())
}

/// The enabled user of an unexpired session (an expired one is deleted).
pub async fn session_user(db: &Db, token_hash: &str) -> anyhow::Result<Option<User>> {
    let found: Option<(String, String)> =
        sqlx::query_as("SELECT user_id, expires_at FROM session WHERE token_hash = $1")
            .bind(token_hash)
            .fetch_optional(db)
            .await?;
    let Some((user_id, expires_at)) = found else {
        return Ok(None);
    };
    if !in_future(&expires_at) {
        delete_session(db, token_hash).await?;
        return Ok(None);
    }
    Ok(get_user(db, &user_id).await?.filter(|u| !u.disabled))
}

/// Ends a session.
pub async fn delete_session(db: &Db, token_hash: &str) -> anyhow::Result<()> {
    sqlx::query("DELETE FROM session WHERE token_hash = $1")
        .bind(token_hash)
        .execute(db)
        .await?;
    Ok(())
}

/// A personal API token (never the token itself, which is shown once).
#[derive(Debug, Clone, Serialize, sqlx::FromRow, utoipa::ToSchema)]
pub struct ApiToken {
    /// Id (UUIDv7).
    pub id: String,
    /// Its owner.
    pub user_id: String,
    /// What it is for.
    pub name: String,
    /// Its role: at most its owner's (a request gets the lower of the two).
    #[sqlx(try_from = "String")]
    pub role: Role,
    /// The token's first characters, to tell tokens apart.
    pub prefix: String,
    /// Creation time (RFC 3339).
    pub created_at: String,
    /// Expiry (RFC 3339; `null`: until revoked).
    pub expires_at: Option<String>,
    /// Last request made with it (RFC 3339).
    pub last_used_at: Option<String>,
    /// When it was revoked (RFC 3339; `null`: valid).
    pub revoked_at: Option<String>,
}

impl TryFrom<String> for Role {
    type Error = anyhow::Error;
    fn try_from(s: String) -> anyhow::Result<Role> {
        Role::parse(&s)
    }
}

const TOKEN_COLS: &str =
    "id, user_id, name, role, prefix, created_at, expires_at, last_used_at, revoked_at";

/// Stores a new token under its hash.
pub async fn insert_token(
    db: &Db,
    user_id: &str,
    name: &str,
    role: Role,
    token_hash: &str,
    prefix: &str,
    expires_at: Option<String>,
) -> anyhow::Result<ApiToken> {
    let t = ApiToken {
        id: new_id(),
        user_id: user_id.to_string(),
        name: name.to_string(),
        role,
        prefix: prefix.to_string(),
        created_at: now(),
        expires_at,
        last_used_at: None,
        revoked_at: None,
    };
    sqlx::query(
        "INSERT INTO api_token (id, user_id, name, role, token_hash, prefix, created_at, expires_at) \
         VALUES ($1, $2, $3, $4, $5, $6, $7, $8)",
    )
    .bind(&t.id)
    .bind(&t.user_id)
    .bind(&t.name)
    .bind(role.as_str())
    .bind(token_hash)
    .bind(&t.prefix)
    .bind(&t.created_at)
    .bind(&t.expires_at)
    .execute(db)
    .await?;
    Ok(t)
}

/// The valid token with this hash and its enabled owner; marks it used.
pub async fn token_user(db: &Db, token_hash: &str) -> anyhow::Result<Option<(ApiToken, User)>> {
    let token: Option<ApiToken> = sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT {TOKEN_COLS} FROM api_token WHERE token_hash = $1 AND revoked_at IS NULL"
    )))
    .bind(token_hash)
    .fetch_optional(db)
    .await?;
    let Some(token) = token else {
        return Ok(None);
    };
    if token.expires_at.as_deref().is_some_and(|e| !in_future(e)) {
        return Ok(None);
    }
    let Some(user) = get_user(db, &token.user_id).await?.filter(|u| !u.disabled) else {
        return Ok(None);
    };
    sqlx::query("UPDATE api_token SET last_used_at = $1 WHERE id = $2")
        .bind(now())
        .bind(&token.id)
        .execute(db)
        .await?;
    Ok(Some((token, user)))
}

/// Tokens of one user (`None`: everyone's), newest first.
pub async fn list_tokens(db: &Db, user_id: Option<&str>) -> anyhow::Result<Vec<ApiToken>> {
    Ok(sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT {TOKEN_COLS} FROM api_token WHERE ($1 IS NULL OR user_id = $1) ORDER BY id DESC"
    )))
    .bind(user_id)
    .fetch_all(db)
    .await?)
}

/// Revokes a token (of `owner` only, when given); `None` when there is no
/// such token. Revoking twice keeps the first time.
pub async fn revoke_token(
    db: &Db,
    id: &str,
    owner: Option<&str>,
) -> anyhow::Result<Option<ApiToken>> {
    sqlx::query(
        "UPDATE api_token SET revoked_at = COALESCE(revoked_at, $1) \
         WHERE id = $2 AND ($3 IS NULL OR user_id = $3)",
    )
    .bind(now())
    .bind(id)
    .bind(owner)
    .execute(db)
    .await?;
    Ok(sqlx::query_as(sqlx::AssertSqlSafe(format!(
        "SELECT {TOKEN_COLS} FROM api_token WHERE id = $1 AND ($2 IS NULL OR user_id = $2)"
    )))
    .bind(id)
    .bind(owner)
    .fetch_optional(db)
    .await?)
}
