//! A model as a MAT-file (`load model.mat` in MATLAB/Octave,
//! `scipy.io.loadmat` in Python): the arrays of the `.npz` export under the
//! same names — every matrix of the document, per LPV grid speed as the
//! pages of an `r×c×p` array (`A(:,:,k)` at `grid_speeds_mps(k)`), their
//! standard deviations, the loads, g(η), the ZOH `Ad`, `Bd` at `h`, names
//! and units as cell rows of text — and `metadata`, a JSON text (name,
//! version, equations, discovered terms, notes; `format: seatrial-mat/1`).

use super::document::ModelDocument;
use super::export_npz::npz_arrays;
use super::mat::{MatValue, mat_bytes};
use super::npz::{NpyArray, NpyData};

/// The variables of the MAT-file of `doc` (see the module documentation).
pub fn mat_variables(
    doc: &ModelDocument,
    name: &str,
    version: i64,
    h: f64,
) -> Result<Vec<(String, MatValue)>, String> {
    npz_arrays(doc, name, version, h)?
        .iter()
        .map(|a| {
            let v = match (&a.name[..], &a.data) {
                ("metadata", NpyData::Str(s)) => {
                    let mut meta: serde_json::Value =
                        serde_json::from_str(&s.concat()).map_err(|e| e.to_string())?;
                    meta["format"] = "seatrial-mat/1".into();
                    MatValue::from_npy(&NpyArray::text("metadata", &meta.to_string()))?
                }
                _ => MatValue::from_npy(a)?,
            };
            Ok((a.name.clone(), v))
        })
        .collect()
}

/// The `.mat` file of `doc` (Level 5, uncompressed).
pub fn mat_export(
    doc: &ModelDocument,
    name: &str,
    version: i64,
    h: f64,
) -> Result<Vec<u8>, String> {
    let ascii: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '?'
            }
        })
        .collect();
    mat_bytes(
        &format!("seatrial model '{ascii}' v{version}"),
        &mat_variables(doc, name, version, h)?,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identification::tests::surge_pitch_doc;

    #[test]
    fn lpv_variables_keep_names_units_and_grid_speeds() {
        let doc = surge_pitch_doc();
        let vars = mat_variables(&doc, "surveyor", 2, 0.1).unwrap();
        let get = |n: &str| &vars.iter().find(|(k, _)| k == n).unwrap().1;
        let pts = &doc.lpv.as_ref().unwrap().points;
        let MatValue::Double { dims, data } = get("grid_speeds_mps") else {
            panic!("grid speeds are not doubles");
        };
        assert_eq!(dims, &[1, pts.len()]);
        assert_eq!(data, &pts.iter().map(|p| p.speed_mps).collect::<Vec<_>>());
        let MatValue::Double { dims, data } = get("A") else {
            panic!("A is not doubles");
        };
        let n = doc.dofs.len();
        assert_eq!(dims, &[n, n, pts.len()]);
        // A(i, j, k) = a[k][i][j].
        assert_eq!(data[1 + n * n], pts[1].a[1][0]);
        assert!(matches!(get("state_units"), MatValue::Strings(u) if u.len() == n));
        let MatValue::Char(meta) = get("metadata") else {
            panic!("metadata is not text");
        };
        assert!(meta.contains("seatrial-mat/1"), "{meta}");
        assert!(mat_export(&doc, "Surveyor – ψ", 2, 0.1).is_ok());
    }
}
