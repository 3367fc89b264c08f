//! What a job is: its kind and request, its state, its error, and the
//! stored record the API returns.

use serde::{Deserialize, Serialize};

/// State of a job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum JobState {
    /// Waiting for a worker.
    Queued,
    /// Claimed by a worker and computing.
    Running,
    /// Done; `result` holds what the handler stored.
    Succeeded,
    /// The handler failed; `error` says why.
    Failed,
    /// Cancelled on request.
    Cancelled,
    /// The server stopped mid-run more often than `max_attempts` allows.
    Interrupted,
}

impl JobState {
    /// Every state, in lifecycle order.
    pub const ALL: [JobState; 6] = [
        JobState::Queued,
        JobState::Running,
        JobState::Succeeded,
        JobState::Failed,
        JobState::Cancelled,
        JobState::Interrupted,
    ];

    /// The stored spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            JobState::Queued => "queued",
            JobState::Running => "running",
            JobState::Succeeded => "succeeded",
            JobState::Failed => "failed",
            JobState::Cancelled => "cancelled",
            JobState::Interrupted => "interrupted",
        }
    }

    /// Parses the stored spelling.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.as_str() == s)
    }

    /// No further transition happens by itself.
    pub fn is_terminal(self) -> bool {
        !matches!(self, JobState::Queued | JobState::Running)
    }
}

/// What to compute: the body of `POST /api/jobs`, stored with the job.
#[derive(Debug, Clone, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JobRequest {
    /// The job's kind: one of the registered handlers (`identify`,
    /// `discover`, `precision`, `design`, `next_dive`).
    #[schema(value_type = JobKind)]
    pub kind: String,
    /// The campaign the runs belong to.
    #[serde(default)]
    pub campaign_id: Option<String>,
    /// Runs to use; they must belong to `campaign_id` and have been accepted at upload.
    #[serde(default)]
    pub run_ids: Vec<String>,
    /// The method, as the kind defines it. `identify`: `lambda_kf` (default
    /// for ROVs; for DP vessels only those logging forces τ), `parallel_ekf`
    /// (default for DP vessels; DP only) or `n4sid`; the other kinds take
    /// none.
    #[serde(default)]
    #[schema(value_type = Option<IdentifyMethod>)]
    pub method: Option<String>,
    /// Settings of the method (a JSON object; its fields are the kind's).
    #[serde(default = "empty_object")]
    #[schema(value_type = Object)]
    pub settings: serde_json::Value,
    /// A model to start from (discovery), or the prior a plan is flown
    /// with (precision, design, next_dive: `settings.prior = model`).
    #[serde(default)]
    pub model_id: Option<String>,
}

/// The kinds of job the service registers (documentation only: a request
/// naming another kind is a 422 listing the registered ones).
#[derive(utoipa::ToSchema)]
#[schema(rename_all = "snake_case", example = "identify")]
#[allow(dead_code)]
pub enum JobKind {
    /// Identification of a campaign's runs (`method`).
    Identify,
    /// Missing-physics discovery on a stored model (`model_id`).
    Discover,
    /// Predicted precision of the campaign's current plan (settings:
    /// `PrecisionSettings`; a prior model in `model_id`); the result is a
    /// `PrecisionResult`.
    Precision,
    /// The campaign designed for precision per ship-hour (settings:
    /// `DesignSettings`; a prior model in `model_id`; ROVs); the result is
    /// a `DesignResult`.
    Design,
    /// The next dive's runs from what was flown (settings:
    /// `NextDiveSettings`; a prior model in `model_id`; ROVs); the result
    /// is a `NextDiveResult`.
    NextDive,
}

/// The methods of an `identify` job (documentation only; an unknown one is a 422).
#[derive(utoipa::ToSchema)]
#[schema(rename_all = "snake_case", example = "lambda_kf")]
#[allow(dead_code)]
pub enum IdentifyMethod {
    /// λ-filter Kalman LPV model on forward speed.
    LambdaKf,
    /// DP ship by the parallel EKF (DP vessels only).
    ParallelEkf,
    /// Black-box subspace state-space model.
    N4sid,
}

pub(super) fn empty_object() -> serde_json::Value {
    serde_json::Value::Object(Default::default())
}

/// Why a job failed or was interrupted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, utoipa::ToSchema)]
pub struct JobError {
    /// What went wrong, in plain words.
    pub message: String,
    /// The offending request field, when one is to blame (e.g. `settings.order`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
}

impl JobError {
    /// An error not tied to a field.
    pub fn new(message: impl Into<String>) -> Self {
        JobError {
            message: message.into(),
            field: None,
        }
    }
}

/// The request of a stored job, as submitted: a `JobRequest` whose `kind`
/// and `method` are those the server registers. Documentation only (its own
/// name keeps generated clients from deriving a second `JobRequest` model).
#[derive(utoipa::ToSchema)]
#[schema(value_type = Object)]
#[allow(dead_code)]
pub struct SubmittedRequest(serde_json::Value);

/// A stored job.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct Job {
    /// Id (UUIDv7).
    pub id: String,
    /// The handler that computes it.
    pub kind: String,
    /// Campaign, if the job has one.
    pub campaign_id: Option<String>,
    /// The request as submitted: a `JobRequest` (its `kind` and `method`
    /// are those the server registers, which the `JobRequest` schema lists
    /// for this service).
    #[schema(value_type = SubmittedRequest)]
    pub request: JobRequest,
    /// Lifecycle state.
    pub state: JobState,
    /// Fraction done of the current attempt, 0–1.
    pub progress: f64,
    /// What the job is doing (or why it is queued again).
    pub stage: String,
    /// The handler's result (e.g. `{"model_id": …}`) once succeeded.
    #[schema(value_type = Option<Object>)]
    pub result: Option<serde_json::Value>,
    /// Why it failed or was interrupted.
    pub error: Option<JobError>,
    /// Attempts so far (1 for a job that ran once; a restart after a crash adds one).
    pub attempts: i64,
    /// Attempts allowed before a job orphaned by a crash is `interrupted`.
    pub max_attempts: i64,
    /// A cancel was requested while it ran; it stops at the next progress report.
    pub cancel_requested: bool,
    /// Worker that holds it while running.
    pub worker: Option<String>,
    /// The running job belongs to its worker until then (RFC 3339).
    pub lease_until: Option<String>,
    /// Submission time (RFC 3339).
    pub created_at: String,
    /// Start of the current attempt.
    pub started_at: Option<String>,
    /// End time, once in a terminal state.
    pub finished_at: Option<String>,
    /// Last change (progress is written about once a second).
    pub updated_at: String,
}
