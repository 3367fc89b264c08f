//! Downloading a model: the whole document (JSON), the parameter table
//! (CSV), the Fossen-form set, a MATLAB/Octave script, NumPy arrays (`.npz`),
//! a MAT-file (`.mat`) and plain state space (JSON or CSV). Files are named `<name>-v<version>`
//! with `filename*=` for names beyond ASCII.

use axum::extract::{Path, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use seatrial_core::identification::document::ModelKind;
use seatrial_core::identification::export::{fossen_parameter_set, parameter_csv};
use seatrial_core::identification::export_mat::mat_export;
use seatrial_core::identification::export_matlab::matlab_script;
use seatrial_core::identification::export_npz::npz_export;
use seatrial_core::identification::export_state_space::{state_space_csv, state_space_export};
use serde::{Deserialize, Serialize};

use super::models::{ModelView, view};
use super::query::ApiQuery;
use super::{AppState, found};
use crate::error::{ApiError, ApiResult, ErrorBody};
use crate::storage::{models, vessels};

/// Export format and sample time.
#[derive(Debug, Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ExportQuery {
    /// `json` (default: the whole model with provenance), `csv` (parameter
    /// table with standard deviations), `fossen` (M, D, loads, g(η),
    /// discovered terms, T, K in Fossen form for MSS /
    /// PythonVehicleSimulator), `matlab` (a `.m` script defining the struct
    /// `model`), `npz` (NumPy arrays: every matrix per grid speed with its
    /// std, loads, g(η), names and units, and the ZOH A_d, B_d at `h`),
    /// `mat` (the same arrays as a MAT-file for MATLAB `load` and
    /// `scipy.io.loadmat`; a stack over the grid speeds is `r×c×p`),
    /// `ss_json` or `ss_csv` (A, B, C, D with named states, inputs and
    /// outputs, units, offsets u0/y0 and sample time; continuous unless `h`
    /// is given).
    #[param(value_type = Option<ExportFormat>)]
    pub format: Option<String>,
    /// Sample time h (s). `npz`, `mat`: the h of A_d, B_d (default: the vessel's
    /// log interval; an N4SID model's own h). `ss_json`/`ss_csv`: the
    /// ZOH-discretized model at h instead of the continuous one (an N4SID
    /// model is discrete at its own h and refuses another). Others ignore it.
    pub h: Option<f64>,
}

/// The export formats (documentation of `format`; an unknown one is a 400 naming it).
#[derive(utoipa::ToSchema)]
#[schema(rename_all = "snake_case")]
#[allow(dead_code)]
pub enum ExportFormat {
    /// The whole model with provenance.
    Json,
    /// The parameter table with standard deviations.
    Csv,
    /// M, D, loads, g(η), discovered terms, T, K in Fossen form.
    Fossen,
    /// A MATLAB/Octave script defining the struct `model`.
    Matlab,
    /// NumPy `.npz` (uncompressed zip of `.npy` arrays).
    Npz,
    /// MAT-file (Level 5): the `.npz` arrays for MATLAB/Octave `load` and `scipy.io.loadmat`.
    Mat,
    /// State space A, B, C, D with names, units, offsets, sample time (JSON).
    SsJson,
    /// The same as a long CSV, one matrix entry per row.
    SsCsv,
}

/// What a JSON export holds. Documentation only.
#[derive(Serialize, utoipa::ToSchema)]
#[allow(dead_code)]
#[serde(untagged)]
pub enum JsonExport {
    /// `format=json`.
    Model(Box<ModelView>),
    /// `format=fossen`.
    Fossen(Box<seatrial_core::identification::export::FossenParameterSet>),
    /// `format=ss_json`.
    StateSpace(Box<seatrial_core::identification::export_state_space::StateSpaceExport>),
}

/// A binary download. Documentation only.
#[derive(utoipa::ToSchema)]
#[schema(value_type = String, format = Binary)]
#[allow(dead_code)]
pub struct BinaryFile(Vec<u8>);

fn attachment(body: impl IntoResponse, content_type: &str, filename: String) -> Response {
    (
        [
            (header::CONTENT_TYPE, content_type.to_string()),
            (
                header::CONTENT_DISPOSITION,
                super::exposure::attachment(&filename),
            ),
        ],
        body,
    )
        .into_response()
}

fn pretty<T: Serialize>(v: &T) -> ApiResult<String> {
    Ok(serde_json::to_string_pretty(v).map_err(anyhow::Error::from)?)
}

/// Download a model.
#[utoipa::path(get, path = "/api/models/{id}/export", tag = "models",
    params(("id" = String, Path, description = "Model id"), ExportQuery),
    responses(
        (status = 200, description = "The export, a file to save: NumPy arrays (`npz`), a MAT-file (`mat`), JSON (`json`, `fossen`, `ss_json`), CSV (`csv`, `ss_csv`) or a MATLAB script (`matlab`). The binary content comes first so that generated clients hand every format over as a file", content(
            (BinaryFile = "application/octet-stream"),
            (JsonExport = "application/json"),
            (String = "text/csv"),
            (String = "text/x-matlab"))),
        (status = 400, description = "Unknown format, or `h` not a number", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 422, description = "No Fossen form for a black-box model; `h` unusable (not positive, or not an N4SID model's own)", body = ErrorBody)))]
pub async fn export_model(
    State(s): State<AppState>,
    Path(id): Path<String>,
    ApiQuery(q): ApiQuery<ExportQuery>,
) -> ApiResult<Response> {
    let m = found(models::get(&s.db, &id).await?, "model", &id)?;
    let stem = format!(
        "{}-v{}",
        m.summary.name.replace([' ', '/', '"', '\\'], "_"),
        m.summary.version
    );
    let v = view(m)?;
    let (doc, name, version) = (&v.document, v.model.name.as_str(), v.model.version);
    let h_error = |msg: String| ApiError::invalid("h", msg);
    match q.format.as_deref().unwrap_or("json") {
        "json" => Ok(attachment(
            pretty(&v)?,
            "application/json",
            format!("{stem}.json"),
        )),
        "csv" => Ok(attachment(
            parameter_csv(doc),
            "text/csv",
            format!("{stem}.csv"),
        )),
        "fossen" => {
            let set = fossen_parameter_set(doc).map_err(|msg| ApiError::invalid("format", msg))?;
            Ok(attachment(
                pretty(&set)?,
                "application/json",
                format!("{stem}-fossen.json"),
            ))
        }
        "matlab" => Ok(attachment(
            matlab_script(doc, name, version),
            "text/x-matlab; charset=utf-8",
            format!(
                "{}.m",
                stem.replace(|c: char| !c.is_ascii_alphanumeric(), "_")
            ),
        )),
        fmt @ ("npz" | "mat") => {
            let h = match (q.h, doc.state_space.as_ref()) {
                (Some(h), _) => h,
                (None, Some(ss)) if doc.kind == ModelKind::StateSpace => ss.h,
                (None, _) => {
                    let vessel =
                        vessels::get(&s.db, &v.model.vessel_id)
                            .await?
                            .ok_or_else(|| {
                                h_error(
                                    "the model's vessel is gone: give the sample time as ?h="
                                        .into(),
                                )
                            })?;
                    1.0 / vessel.profile.logger_rate_hz
                }
            };
            let bytes = if fmt == "mat" {
                mat_export(doc, name, version, h)
            } else {
                npz_export(doc, name, version, h)
            }
            .map_err(h_error)?;
            Ok(attachment(
                bytes,
                "application/octet-stream",
                format!("{stem}.{fmt}"),
            ))
        }
        "ss_json" => {
            let e = state_space_export(doc, name, version, q.h).map_err(h_error)?;
            Ok(attachment(
                pretty(&e)?,
                "application/json",
                format!("{stem}-ss.json"),
            ))
        }
        "ss_csv" => {
            let e = state_space_export(doc, name, version, q.h).map_err(h_error)?;
            Ok(attachment(
                state_space_csv(&e),
                "text/csv",
                format!("{stem}-ss.csv"),
            ))
        }
        other => Err(ApiError::bad_field(
            "format",
            format!(
                "unknown export format '{other}'; use json, csv, fossen, matlab, mat, npz, ss_json or ss_csv"
            ),
        )),
    }
}
