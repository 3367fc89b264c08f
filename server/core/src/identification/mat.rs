//! A MAT-file (Level 5) writer, enough for `load` in MATLAB/Octave and
//! `scipy.io.loadmat`: real double arrays of any rank, character rows and
//! cell rows of character rows, uncompressed, little-endian. The format is
//! MathWorks' "MAT-File Format" (version 7 and earlier): a 128-byte header,
//! then one `miMATRIX` element per variable; text is `miUTF8`.

use super::npz::{NpyArray, NpyData};

const MI_INT8: u32 = 1;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_DOUBLE: u32 = 9;
const MI_MATRIX: u32 = 14;
const MI_UTF8: u32 = 16;

const MX_CELL: u32 = 1;
const MX_CHAR: u32 = 4;
const MX_DOUBLE: u32 = 6;

/// One variable of a MAT-file.
#[derive(Debug, Clone, PartialEq)]
pub enum MatValue {
    /// Real doubles with MATLAB's dimensions, data in column-major order.
    Double {
        /// Dimensions (at least two).
        dims: Vec<usize>,
        /// Values, column-major.
        data: Vec<f64>,
    },
    /// A character row (`1×n`).
    Char(String),
    /// A `1×n` cell array of character rows.
    Strings(Vec<String>),
}

impl MatValue {
    /// A row-major NumPy-style array as MATLAB sees it: a scalar is `1×1`,
    /// a vector `1×n`, a matrix `r×c`, and a stack `[p, r, c]` of matrices
    /// becomes `r×c×p` (page `k` is `X(:,:,k)`).
    pub fn from_npy(a: &NpyArray) -> Result<MatValue, String> {
        match &a.data {
            NpyData::Str(v) if a.shape.is_empty() => Ok(MatValue::Char(v.concat())),
            NpyData::Str(v) => Ok(MatValue::Strings(v.clone())),
            NpyData::F64(v) => {
                let (dims, data) = match a.shape[..] {
                    [] => (vec![1, 1], v.clone()),
                    [n] => (vec![1, n], v.clone()),
                    [r, c] => (vec![r, c], column_major(v, 1, r, c)),
                    [p, r, c] => (vec![r, c, p], column_major(v, p, r, c)),
                    _ => return Err(format!("{}: rank {} is not written", a.name, a.shape.len())),
                };
                Ok(MatValue::Double { dims, data })
            }
        }
    }
}

/// `p` row-major `r×c` matrices, one after another, to MATLAB's column-major `r×c×p`.
fn column_major(v: &[f64], p: usize, r: usize, c: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(v.len());
    for k in 0..p {
        for j in 0..c {
            for i in 0..r {
                out.push(v[k * r * c + i * c + j]);
            }
        }
    }
    out
}

/// A MATLAB variable name: a letter, then letters, digits or `_`, at most 63.
fn check_name(name: &str) -> Result<(), String> {
    let ok = name.len() <= 63
        && name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(format!("'{name}' is not a MATLAB variable name"))
    }
}

/// A data element: tag (type, byte count), data, padding to 8 bytes.
fn element(out: &mut Vec<u8>, ty: u32, data: &[u8]) {
    out.extend_from_slice(&ty.to_le_bytes());
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.extend(std::iter::repeat_n(0u8, (8 - data.len() % 8) % 8));
}

/// The body of a `miMATRIX` element: flags, dimensions, name, data.
fn matrix(name: &str, v: &MatValue) -> Vec<u8> {
    let mut out = Vec::new();
    let (class, dims): (u32, Vec<usize>) = match v {
        MatValue::Double { dims, .. } => (MX_DOUBLE, dims.clone()),
        MatValue::Char(s) => (MX_CHAR, vec![1, s.chars().count()]),
        MatValue::Strings(v) => (MX_CELL, vec![1, v.len()]),
    };
    let mut flags = Vec::with_capacity(8);
    flags.extend_from_slice(&class.to_le_bytes());
    flags.extend_from_slice(&0u32.to_le_bytes());
    element(&mut out, MI_UINT32, &flags);
    let dims: Vec<u8> = dims
        .iter()
        .flat_map(|&d| (d as i32).to_le_bytes())
        .collect();
    element(&mut out, MI_INT32, &dims);
    element(&mut out, MI_INT8, name.as_bytes());
    match v {
        MatValue::Double { data, .. } => {
            let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
            element(&mut out, MI_DOUBLE, &bytes);
        }
        // UTF-8 text, as scipy.io.savemat writes it (MATLAB and Octave read it).
        MatValue::Char(s) => element(&mut out, MI_UTF8, s.as_bytes()),
        MatValue::Strings(v) => {
            for s in v {
                element(&mut out, MI_MATRIX, &matrix("", &MatValue::Char(s.clone())));
            }
        }
    }
    out
}

/// The MAT-file of `vars` (name, value), with `description` in the header's
/// text (at most 116 bytes kept).
pub fn mat_bytes(description: &str, vars: &[(String, MatValue)]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut text: Vec<u8> = format!("MATLAB 5.0 MAT-file, {description}").into_bytes();
    text.truncate(116);
    text.resize(116, b' ');
    out.extend_from_slice(&text);
    out.extend_from_slice(&[0u8; 8]); // no subsystem data
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    for (name, v) in vars {
        check_name(name)?;
        if let MatValue::Double { dims, data } = v
            && dims.iter().product::<usize>() != data.len()
        {
            return Err(format!(
                "{name}: {} values for dimensions {dims:?}",
                data.len()
            ));
        }
        element(&mut out, MI_MATRIX, &matrix(name, v));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stacks_become_pages_in_column_major_order() {
        // Two 2×3 matrices, row-major, page after page.
        let a = NpyArray::f64(
            "A",
            vec![2, 2, 3],
            (0..12).map(f64::from).collect::<Vec<_>>(),
        );
        let MatValue::Double { dims, data } = MatValue::from_npy(&a).unwrap() else {
            panic!("not a double array");
        };
        assert_eq!(dims, [2, 3, 2]);
        // A(:,:,1) = [0 1 2; 3 4 5] column by column, then page 2.
        assert_eq!(
            data,
            [0.0, 3.0, 1.0, 4.0, 2.0, 5.0, 6.0, 9.0, 7.0, 10.0, 8.0, 11.0]
        );
    }

    #[test]
    fn the_file_is_a_header_and_aligned_elements() {
        let vars = vec![
            (
                "h".to_string(),
                MatValue::Double {
                    dims: vec![1, 1],
                    data: vec![0.1],
                },
            ),
            ("unit".to_string(), MatValue::Char("N·m".into())),
            (
                "names".to_string(),
                MatValue::Strings(vec!["u".into(), "ψ".into()]),
            ),
        ];
        let b = mat_bytes("test", &vars).unwrap();
        assert!(b.starts_with(b"MATLAB 5.0 MAT-file, test"));
        assert_eq!(&b[124..128], &[0x00, 0x01, b'I', b'M']);
        // Each top-level element: tag, then its byte count, padded to 8.
        let mut at = 128;
        let mut n = 0;
        while at < b.len() {
            assert_eq!(
                u32::from_le_bytes(b[at..at + 4].try_into().unwrap()),
                MI_MATRIX
            );
            let len = u32::from_le_bytes(b[at + 4..at + 8].try_into().unwrap()) as usize;
            assert_eq!(len % 8, 0);
            at += 8 + len;
            n += 1;
        }
        assert_eq!((at, n), (b.len(), 3));
        assert!(mat_bytes("x", &[("2bad".into(), MatValue::Char(String::new()))]).is_err());
    }
}
