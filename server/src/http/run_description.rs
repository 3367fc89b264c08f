//! What a run is, as the supervisor says it: role, grid speed, excited DOFs,
//! signal and notes, given with the upload (`meta`) or later
//! (`PATCH /api/runs/{id}`). Checked against the vessel; every refusal is a
//! 422 naming the field. A user value wins over the planned experiment's,
//! which wins over the inferred one; `null` clears a user value.

use axum::Json;
use axum::extract::{Path, State};
use seatrial_core::identification::{RunRole, RunSignal, UserDescription};
use seatrial_core::planning::vessel::VesselKind;
use seatrial_core::planning::{Dof, KNOT, PlanError, VesselProfile};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer};
use serde_json::Value;

use super::json::ApiJson;
use super::{AppState, campaign_and_vessel, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::processing::RunMeta;
use crate::storage::runs::{self, DescriptionField, Run};

/// Longest notes (characters).
pub const MAX_NOTES_CHARS: usize = 2000;

/// Present (even as `null`) → `Some(value)`; absent → `None` (with `default`).
fn present<'de, T: Deserialize<'de>, D: Deserializer<'de>>(d: D) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// A change to what the supervisor says a run is. Each field absent: kept;
/// `null`: the user value is cleared (the planned, else the inferred value
/// applies again); a value: set.
#[derive(Debug, Default, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct DescriptionChange {
    /// Role: `static`, `dynamic`, `recursive` or `validation` (a DP vessel: `dynamic` or `validation`).
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<RunRole>, nullable)]
    pub role: Option<Option<RunRole>>,
    /// Grid speed it was flown at (m/s), 0 … the vessel's maximum forward speed.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<f64>, nullable)]
    pub grid_speed_mps: Option<Option<f64>>,
    /// The same in knots (stored in m/s); give one of the two.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<f64>, nullable)]
    pub grid_speed_kn: Option<Option<f64>>,
    /// DOFs it excites, each modelled by the vessel (`[]`: none, a static run).
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<Vec<Dof>>, nullable)]
    pub excited_dofs: Option<Option<Vec<Dof>>>,
    /// Excitation signal.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<RunSignal>, nullable)]
    pub signal: Option<Option<RunSignal>>,
    /// Free notes, at most 2000 characters.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = Option<String>, nullable)]
    pub notes: Option<Option<String>>,
}

impl DescriptionChange {
    /// The description given in upload metadata (a `null` there is "not said").
    pub fn of_meta(m: &RunMeta) -> DescriptionChange {
        DescriptionChange {
            role: m.role.map(Some),
            grid_speed_mps: m.grid_speed_mps.map(Some),
            grid_speed_kn: m.grid_speed_kn.map(Some),
            excited_dofs: m.excited_dofs.clone().map(Some),
            signal: m.signal.map(Some),
            notes: m.notes.clone().map(Some),
        }
    }

    /// Applies the change to `user`, checked against `vessel`; errors name
    /// the field with `prefix` (`meta.` for an upload). Returns the fields
    /// it touched.
    pub fn apply(
        &self,
        user: &mut UserDescription,
        vessel: &VesselProfile,
        prefix: &str,
    ) -> Result<Vec<DescriptionField>, ApiError> {
        let field = |f: &str| format!("{prefix}{f}");
        let mut touched = Vec::new();
        if let Some(role) = self.role {
            if let Some(r) = role
                && !RunRole::allowed_for(vessel.kind).contains(&r)
            {
                return Err(ApiError::invalid(
                    field("role"),
                    match vessel.kind {
                        VesselKind::Dp3 => format!(
                            "a DP vessel's runs are dynamic (the SI1–SI3 manoeuvres) or validation, not {}",
                            r.name()
                        ),
                        VesselKind::Rov6 => format!("'{}' is not a role", r.name()),
                    },
                ));
            }
            user.role = role;
            touched.push(DescriptionField::Role);
        }
        let speed = match (self.grid_speed_mps, self.grid_speed_kn) {
            (Some(Some(_)), Some(Some(_))) => {
                return Err(ApiError::invalid(
                    field("grid_speed_kn"),
                    "give the grid speed once: grid_speed_mps or grid_speed_kn",
                ));
            }
            (Some(Some(v)), _) => Some(Some((v, "grid_speed_mps", v, "m/s"))),
            (_, Some(Some(v))) => Some(Some((v * KNOT, "grid_speed_kn", v, "kn"))),
            (Some(None), _) | (_, Some(None)) => Some(None),
            (None, None) => None,
        };
        if let Some(speed) = speed {
            if let Some((si, name, given, unit)) = speed {
                let max = vessel.max_forward_speed();
                if !(given.is_finite() && given >= 0.0) {
                    return Err(ApiError::invalid(
                        field(name),
                        format!("a grid speed is a finite forward speed ≥ 0 {unit}, got {given}"),
                    ));
                }
                if si > max + 1e-12 {
                    let limit = if unit == "kn" { max / KNOT } else { max };
                    return Err(ApiError::Unprocessable(PlanError::over_limit(
                        field(name),
                        format!(
                            "{given} {unit} is above {}'s maximum forward speed of {limit:.3} {unit}",
                            vessel.name
                        ),
                        limit,
                    )));
                }
            }
            user.grid_speed_mps = speed.map(|s| s.0);
            touched.push(DescriptionField::GridSpeed);
        }
        if let Some(dofs) = &self.excited_dofs {
            if let Some(list) = dofs {
                for (i, d) in list.iter().enumerate() {
                    if !vessel.dofs.contains(d) {
                        return Err(ApiError::invalid(
                            field(&format!("excited_dofs[{i}]")),
                            format!(
                                "{} is not modelled by {} (its DOFs: {})",
                                d.name(),
                                vessel.name,
                                vessel
                                    .dofs
                                    .iter()
                                    .map(|d| d.name())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        ));
                    }
                    if list[..i].contains(d) {
                        return Err(ApiError::invalid(
                            field(&format!("excited_dofs[{i}]")),
                            format!("{} is listed twice", d.name()),
                        ));
                    }
                }
            }
            user.excited_dofs = dofs.as_ref().map(|l| {
                let mut l = l.clone();
                l.sort();
                l
            });
            touched.push(DescriptionField::ExcitedDofs);
        }
        if let Some(signal) = self.signal {
            user.signal = signal;
            touched.push(DescriptionField::Signal);
        }
        if let Some(notes) = &self.notes {
            let notes = notes.as_deref().map(str::trim).filter(|n| !n.is_empty());
            if let Some(n) = notes {
                let chars = n.chars().count();
                if chars > MAX_NOTES_CHARS {
                    return Err(ApiError::Unprocessable(PlanError::over_limit(
                        field("notes"),
                        format!("notes are limited to {MAX_NOTES_CHARS} characters, got {chars}"),
                        MAX_NOTES_CHARS as f64,
                    )));
                }
            }
            user.notes = notes.map(str::to_string);
            touched.push(DescriptionField::Notes);
        }
        Ok(touched)
    }
}

/// Reads a JSON value as `T`: a value the type does not accept (an unknown
/// field, an unknown role, a string for a number) is a 422 naming the field
/// with `prefix`; the message names it too.
pub fn from_value<T: DeserializeOwned>(v: Value, prefix: &str) -> Result<T, ApiError> {
    serde_path_to_error::deserialize(v).map_err(|e| {
        let path = e.path().to_string();
        let msg = e.inner().to_string();
        let mut field = (path != ".").then_some(path);
        // An unknown field may be reported at its parent; name the field itself.
        if let Some(rest) = msg.strip_prefix("unknown field `")
            && let Some(name) = rest.split('`').next()
        {
            field = Some(match field {
                Some(p) if p == name || p.ends_with(&format!(".{name}")) => p,
                Some(p) => format!("{p}.{name}"),
                None => name.to_string(),
            });
        }
        let field = match field {
            Some(f) => format!("{prefix}{f}"),
            None => prefix.trim_end_matches('.').to_string(),
        };
        let field = if field.is_empty() {
            "body".into()
        } else {
            field
        };
        ApiError::invalid(field.clone(), format!("{field}: {msg}"))
    })
}

/// A change to a run's name and to its use in identification.
#[derive(Debug, Default, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RunManage {
    /// New name, 1–200 characters (trimmed).
    #[schema(min_length = 1, max_length = 200, pattern = r"\S")]
    pub name: Option<String>,
    /// `true`: leave the run out of identification unless a job names it
    /// (give `excluded_reason`); `false`: use it again.
    pub excluded: Option<bool>,
    /// Why it is excluded: required with `excluded: true`, at most 2000 characters.
    #[schema(min_length = 1, max_length = 2000)]
    pub excluded_reason: Option<String>,
}

/// The keys of [`RunManage`] in a PATCH body; the others describe the run.
const MANAGE_KEYS: [&str; 3] = ["name", "excluded", "excluded_reason"];

impl RunManage {
    /// The checked update; refusals are 422s naming the field.
    fn update(self) -> Result<runs::RunUpdate, ApiError> {
        let name = self
            .name
            .as_deref()
            .map(|n| check_name("name", n))
            .transpose()?;
        let exclusion = match (self.excluded, self.excluded_reason) {
            (Some(true), reason) => {
                let reason = reason.as_deref().map(str::trim).unwrap_or("");
                if reason.is_empty() {
                    return Err(ApiError::invalid(
                        "excluded_reason",
                        "say why the run is excluded (excluded_reason), so that whoever identifies next knows",
                    ));
                }
                let chars = reason.chars().count();
                if chars > MAX_NOTES_CHARS {
                    return Err(ApiError::Unprocessable(PlanError::over_limit(
                        "excluded_reason",
                        format!(
                            "the reason is limited to {MAX_NOTES_CHARS} characters, got {chars}"
                        ),
                        MAX_NOTES_CHARS as f64,
                    )));
                }
                Some(Some(reason.to_string()))
            }
            (Some(false), _) => Some(None),
            (None, Some(_)) => {
                return Err(ApiError::invalid(
                    "excluded_reason",
                    "a reason goes with excluded: true",
                ));
            }
            (None, None) => None,
        };
        Ok(runs::RunUpdate { name, exclusion })
    }
}

/// A name checked against the documented limits (1–200 characters once
/// trimmed); a 422 naming `field` otherwise.
pub fn check_name(field: &str, name: &str) -> Result<String, ApiError> {
    let name = name.trim();
    if name.is_empty() {
        return Err(ApiError::invalid(field, "a name must not be empty"));
    }
    let chars = name.chars().count();
    if chars > MAX_NAME_CHARS {
        return Err(ApiError::Unprocessable(PlanError::over_limit(
            field,
            format!("names are limited to {MAX_NAME_CHARS} characters, got {chars}"),
            MAX_NAME_CHARS as f64,
        )));
    }
    Ok(name.to_string())
}

/// Longest name (characters).
pub const MAX_NAME_CHARS: usize = 200;

/// The body of `PATCH /api/runs/{id}`: name and exclusion, and what the run
/// is (documentation; the handler reads the two parts apart).
#[derive(Deserialize, utoipa::ToSchema)]
#[allow(dead_code)]
pub struct RunChange {
    #[serde(flatten)]
    manage: RunManage,
    #[serde(flatten)]
    description: DescriptionChange,
}

/// Change a run: rename it, exclude it from identification (with a reason)
/// or include it again, and say what it is — role, grid speed
/// (`grid_speed_mps` or `grid_speed_kn`), excited DOFs, signal, notes.
/// Absent fields are kept, `null` clears a user description value (the
/// planned experiment's, else the inferred value applies again). One
/// transaction. Answers the run with its description, each field with its
/// source (`user`, `plan`, `inferred`).
#[utoipa::path(patch, path = "/api/runs/{id}", tag = "runs",
    params(("id" = String, Path, description = "Run id")),
    request_body = RunChange,
    responses(
        (status = 200, description = "The run with its description", body = Run),
        (status = 400, description = "Not JSON", body = ErrorBody),
        (status = 404, description = "No such run", body = ErrorBody),
        (status = 415, description = "Not application/json", body = ErrorBody),
        (status = 422, description = "A field the vessel or the service does not accept (unknown field or role, negative speed, a DOF not modelled, notes over 2000 characters, an empty or too long name, exclusion without a reason): `field` names it", body = ErrorBody)))]
pub async fn describe_run(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiJson(body): ApiJson<Value>,
) -> ApiResult<Json<Run>> {
    let run = found(runs::get(&s.db, &id).await?, "run", &id)?;
    let Value::Object(mut rest) = body else {
        return Err(ApiError::invalid("body", "a JSON object is expected"));
    };
    let mut manage = serde_json::Map::new();
    for k in MANAGE_KEYS {
        if let Some(v) = rest.remove(k) {
            manage.insert(k.to_string(), v);
        }
    }
    let update = from_value::<RunManage>(Value::Object(manage), "")?.update()?;
    let change: DescriptionChange = from_value(Value::Object(rest), "")?;
    let (_, vessel) = campaign_and_vessel(&s.db, &run).await?;
    let mut user = UserDescription::default();
    let touched = change.apply(&mut user, &vessel.profile, "")?;
    if !runs::update(&s.db, &id, &user, &touched, &update).await? {
        return Err(ApiError::NotFound(format!("no run with id '{id}'")));
    }
    Ok(Json(found(runs::get(&s.db, &id).await?, "run", &id)?))
}
