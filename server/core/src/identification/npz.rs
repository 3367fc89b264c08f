//! NumPy's `.npz` container written in memory: an uncompressed zip (the
//! `zip` crate) of `.npy` arrays in format version 1.0
//! (<https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html>),
//! little-endian `f8` numbers and fixed-width `U` (UTF-32) strings, so
//! `numpy.load(path)` reads every array without `allow_pickle`. A reader of
//! the same subset proves the round trip. No filesystem I/O.

use std::io::{Cursor, Read, Write};

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipArchive, ZipWriter};

/// The values of an array, row-major (C order).
#[derive(Debug, Clone, PartialEq)]
pub enum NpyData {
    /// `<f8`.
    F64(Vec<f64>),
    /// `<U{n}` with n the longest string in characters.
    Str(Vec<String>),
}

/// One named array of an `.npz`.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    /// Key in `numpy.load(...)` (the member is `<name>.npy`).
    pub name: String,
    /// Shape; empty for a 0-d scalar.
    pub shape: Vec<usize>,
    /// Values, as many as the shape's product.
    pub data: NpyData,
}

impl NpyArray {
    /// A 0-d float.
    pub fn scalar(name: &str, x: f64) -> Self {
        Self::f64(name, vec![], vec![x])
    }

    /// Floats of a shape.
    pub fn f64(name: &str, shape: Vec<usize>, data: Vec<f64>) -> Self {
        debug_assert_eq!(shape.iter().product::<usize>(), data.len());
        NpyArray {
            name: name.into(),
            shape,
            data: NpyData::F64(data),
        }
    }

    /// A 1-d array of strings.
    pub fn strings(name: &str, v: &[String]) -> Self {
        NpyArray {
            name: name.into(),
            shape: vec![v.len()],
            data: NpyData::Str(v.to_vec()),
        }
    }

    /// A 0-d string (e.g. JSON metadata: `str(npz["metadata"])`).
    pub fn text(name: &str, s: &str) -> Self {
        NpyArray {
            name: name.into(),
            shape: vec![],
            data: NpyData::Str(vec![s.to_string()]),
        }
    }

    /// Floats of a row-major matrix (`Err` when ragged).
    pub fn matrix(name: &str, m: &[Vec<f64>]) -> Result<Self, String> {
        Self::stack(name, std::slice::from_ref(&m.to_vec())).map(|mut a| {
            a.shape.remove(0);
            a
        })
    }

    /// Floats of equal-shaped matrices stacked on a first axis (P, r, c).
    pub fn stack(name: &str, ms: &[Vec<Vec<f64>>]) -> Result<Self, String> {
        let r = ms.first().map_or(0, Vec::len);
        let c = ms.first().and_then(|m| m.first()).map_or(0, Vec::len);
        let mut data = Vec::with_capacity(ms.len() * r * c);
        for m in ms {
            if m.len() != r || m.iter().any(|row| row.len() != c) {
                return Err(format!("{name}: matrices of different shapes"));
            }
            data.extend(m.iter().flatten());
        }
        Ok(Self::f64(name, vec![ms.len(), r, c], data))
    }

    /// Floats of equal-length vectors stacked as rows (P, n).
    pub fn rows(name: &str, vs: &[Vec<f64>]) -> Result<Self, String> {
        let n = vs.first().map_or(0, Vec::len);
        if vs.iter().any(|v| v.len() != n) {
            return Err(format!("{name}: vectors of different lengths"));
        }
        Ok(Self::f64(
            name,
            vec![vs.len(), n],
            vs.iter().flatten().copied().collect(),
        ))
    }
}

fn shape_tuple(shape: &[usize]) -> String {
    match shape {
        [] => "()".into(),
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The `.npy` bytes (format 1.0) of one array.
pub fn npy_bytes(a: &NpyArray) -> Vec<u8> {
    let width = match &a.data {
        NpyData::F64(_) => 0,
        NpyData::Str(v) => v
            .iter()
            .map(|s| s.chars().count())
            .max()
            .unwrap_or(0)
            .max(1),
    };
    let descr = match &a.data {
        NpyData::F64(_) => "<f8".to_string(),
        NpyData::Str(_) => format!("<U{width}"),
    };
    let mut header = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': {}, }}",
        shape_tuple(&a.shape)
    );
    // magic (6) + version (2) + length (2) + header + '\n', padded to 64.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    match &a.data {
        NpyData::F64(v) => v
            .iter()
            .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
        NpyData::Str(v) => {
            for s in v {
                let mut n = 0;
                for c in s.chars() {
                    out.extend_from_slice(&(c as u32).to_le_bytes());
                    n += 1;
                }
                out.extend(std::iter::repeat_n(0u8, 4 * (width - n)));
            }
        }
    }
    out
}

/// The `.npz` bytes of `arrays` (stored, not deflated; fixed timestamps, so
/// the same arrays give the same bytes).
pub fn npz_bytes(arrays: &[NpyArray]) -> Result<Vec<u8>, String> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Stored)
        .large_file(false);
    for a in arrays {
        zip.start_file(format!("{}.npy", a.name), options)
            .map_err(|e| e.to_string())?;
        zip.write_all(&npy_bytes(a)).map_err(|e| e.to_string())?;
    }
    Ok(zip.finish().map_err(|e| e.to_string())?.into_inner())
}

fn parse_npy(name: &str, b: &[u8]) -> Result<NpyArray, String> {
    let bad = |what: &str| format!("{name}: {what}");
    if b.len() < 10 || &b[..8] != b"\x93NUMPY\x01\x00" {
        return Err(bad("not a version 1.0 .npy"));
    }
    let hl = u16::from_le_bytes([b[8], b[9]]) as usize;
    let header = std::str::from_utf8(b.get(10..10 + hl).ok_or_else(|| bad("short header"))?)
        .map_err(|_| bad("header not UTF-8"))?;
    let field = |key: &str| {
        let at = header
            .find(&format!("'{key}': "))
            .ok_or_else(|| bad(&format!("no {key}")))?;
        Ok::<&str, String>(&header[at + key.len() + 4..])
    };
    let descr = field("descr")?;
    let descr = &descr[1..descr[1..].find('\'').ok_or_else(|| bad("descr"))? + 1];
    if !field("fortran_order")?.starts_with("False") {
        return Err(bad("Fortran order"));
    }
    let shape_text = field("shape")?;
    let shape_text = &shape_text[1..shape_text.find(')').ok_or_else(|| bad("shape"))?];
    let shape: Vec<usize> = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().map_err(|_| bad("shape")))
        .collect::<Result<_, _>>()?;
    let count: usize = shape.iter().product();
    let body = &b[10 + hl..];
    let data = if descr == "<f8" {
        if body.len() != 8 * count {
            return Err(bad("length"));
        }
        NpyData::F64(
            body.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
                .collect(),
        )
    } else if let Some(w) = descr.strip_prefix("<U") {
        let w: usize = w.parse().map_err(|_| bad("descr"))?;
        if body.len() != 4 * w * count {
            return Err(bad("length"));
        }
        NpyData::Str(
            body.chunks_exact(4 * w.max(1))
                .take(count)
                .map(|s| {
                    s.chunks_exact(4)
                        .map(|c| u32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
                        .take_while(|&u| u != 0)
                        .filter_map(char::from_u32)
                        .collect()
                })
                .collect(),
        )
    } else {
        return Err(bad(&format!("dtype {descr}")));
    };
    Ok(NpyArray {
        name: name.into(),
        shape,
        data,
    })
}

/// Reads back what [`npz_bytes`] writes (`f8` and `U` arrays), in order.
pub fn read_npz(bytes: &[u8]) -> Result<Vec<NpyArray>, String> {
    let mut zip = ZipArchive::new(Cursor::new(bytes)).map_err(|e| e.to_string())?;
    let mut out = Vec::with_capacity(zip.len());
    for i in 0..zip.len() {
        let mut f = zip.by_index(i).map_err(|e| e.to_string())?;
        let member = f.name().map_err(|e| e.to_string())?.to_string();
        let name = member
            .strip_suffix(".npy")
            .ok_or_else(|| format!("{member}: not an .npy member"))?
            .to_string();
        let mut b = Vec::new();
        f.read_to_end(&mut b).map_err(|e| e.to_string())?;
        out.push(parse_npy(&name, &b)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_are_padded_to_64_and_describe_the_array() {
        let b = npy_bytes(&NpyArray::f64("a", vec![2, 3], vec![0.0; 6]));
        let hl = u16::from_le_bytes([b[8], b[9]]) as usize;
        assert_eq!((10 + hl) % 64, 0);
        let header = std::str::from_utf8(&b[10..10 + hl]).unwrap();
        assert!(header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with('\n'));
        assert_eq!(b.len(), 10 + hl + 48);
        let s = npy_bytes(&NpyArray::strings("s", &["ab".into(), "ψ".into()]));
        let hl = u16::from_le_bytes([s[8], s[9]]) as usize;
        assert!(
            std::str::from_utf8(&s[10..10 + hl])
                .unwrap()
                .contains("'<U2'")
        );
        assert_eq!(&s[10 + hl + 8..10 + hl + 12], &('ψ' as u32).to_le_bytes());
        assert!(shape_tuple(&[]) == "()" && shape_tuple(&[4]) == "(4,)");
    }

    #[test]
    fn npz_round_trips_bit_for_bit() {
        let arrays = vec![
            NpyArray::stack(
                "M",
                &[
                    vec![vec![1.0, 0.1 + 0.2], vec![-0.0, 1e-300]],
                    vec![vec![5.0, 6.0], vec![7.0, f64::MAX]],
                ],
            )
            .unwrap(),
            NpyArray::scalar("h", 0.1),
            NpyArray::strings("dofs", &["surge".into(), "yaw".into()]),
            NpyArray::text("metadata", "{\"name\": \"Ærø ROV\"}"),
            NpyArray::rows("b", &[vec![1.0, 2.0], vec![3.0, 4.0]]).unwrap(),
        ];
        let bytes = npz_bytes(&arrays).unwrap();
        assert_eq!(bytes, npz_bytes(&arrays).unwrap(), "deterministic");
        let back = read_npz(&bytes).unwrap();
        assert_eq!(back, arrays);
        if let NpyData::F64(v) = &back[0].data {
            assert_eq!(v[2].to_bits(), (-0.0f64).to_bits());
        }
        assert!(NpyArray::stack("x", &[vec![vec![1.0]], vec![vec![1.0, 2.0]]]).is_err());
        assert_eq!(
            NpyArray::matrix("m", &[vec![1.0, 2.0]]).unwrap().shape,
            vec![1, 2]
        );
    }
}
