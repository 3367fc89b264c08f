//! Reading one CSV log into a [`LogTable`], with the first defect reported at
//! its exact line and column.
//!
//! Accepted: a UTF-8 BOM, `\n`, `\r\n` or bare `\r` (old Mac) line ends, blank lines (also
//! trailing), spaces around names and numbers, quoted fields, columns in any
//! order. The header is the first non-blank line. Every column named in
//! [`ParseOptions::required`] (and `t`) must be present and hold a finite
//! number in every row. Other columns are kept in the table when every cell
//! is a finite number, and otherwise listed in
//! [`ParsedLog::ignored_columns`] with a warning. `t` must strictly increase.
//!
//! Line numbers are physical (1-based, counting blank lines); a quoted field
//! spanning lines is reported at the line where its row ends.

use std::io::{self, Read};

use csv::{ByteRecord, ReaderBuilder, Terminator};

use super::checks::{LogWarning, plausibility_warnings};
use super::error::{LogError, LogErrorKind};
use super::gaps::{Gap, find_gaps};
use super::measurements::{check_groups, heading_from_degrees};
use super::schema::{LogRole, TIME_COLUMN, describe_vessel, measurement_groups, strict_columns};
use crate::numbers::{echoed, escape_controls};
use crate::planning::vessel::{HeadingUnit, VesselProfile};
use crate::timeseries::LogTable;

/// Default limit on data rows (a 10 Hz log of almost 58 days).
pub const DEFAULT_MAX_ROWS: usize = 50_000_000;

/// Default limit on header columns; a wider header is [`LogErrorKind::TooLarge`].
pub const DEFAULT_MAX_COLUMNS: usize = 10_000;

/// Ignored columns warned about one by one; the rest in one warning.
pub const MAX_COLUMN_WARNINGS: usize = 20;

/// How to read one log.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseOptions {
    /// Name of the file in errors: `"file"`, `"control"` or `"nav"`.
    pub file: String,
    /// Columns that must be present and fully numeric (`t` is always
    /// required, listed or not).
    pub required: Vec<String>,
    /// More data rows than this is [`LogErrorKind::TooLarge`].
    pub max_rows: usize,
    /// More header columns than this is [`LogErrorKind::TooLarge`].
    pub max_columns: usize,
    /// Who needs the required columns, for the missing-columns message, e.g.
    /// `the 6-DOF ROV 'Surveyor ROV'`.
    pub needed_by: Option<String>,
    /// Groups of columns of which at least one must be complete (a DP
    /// vessel's velocities or pose); empty: no such condition.
    pub one_of: Vec<Vec<String>>,
    /// Unit of `psi` in the file; degrees are converted to radians.
    pub heading_unit: HeadingUnit,
}

impl ParseOptions {
    /// Options with the default row limit.
    pub fn new(file: impl Into<String>, required: Vec<String>) -> Self {
        ParseOptions {
            file: file.into(),
            required,
            max_rows: DEFAULT_MAX_ROWS,
            max_columns: DEFAULT_MAX_COLUMNS,
            needed_by: None,
            one_of: Vec::new(),
            heading_unit: HeadingUnit::Rad,
        }
    }

    /// Options for a file of `role` of `vessel` (see
    /// [`required_columns`](super::schema::required_columns);
    /// a DP vessel's pose or velocities suffice), named after the role,
    /// with the profile's heading unit.
    pub fn for_vessel(vessel: &VesselProfile, role: LogRole, shared: Option<&str>) -> Self {
        ParseOptions {
            needed_by: Some(describe_vessel(vessel)),
            one_of: measurement_groups(vessel, role),
            heading_unit: vessel.heading_unit.unwrap_or_default(),
            ..ParseOptions::new(role.label(), strict_columns(vessel, role, shared))
        }
    }
}

impl Default for ParseOptions {
    fn default() -> Self {
        ParseOptions::new("file", vec![TIME_COLUMN.to_string()])
    }
}

/// A log that passed every check, with what was noticed on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedLog {
    /// Time and every numeric column, in file order.
    pub table: LogTable,
    /// Columns dropped because they are unnamed or not fully numeric.
    pub ignored_columns: Vec<String>,
    /// Doubts: ignored columns, units that look wrong, constant channels.
    pub warnings: Vec<LogWarning>,
    /// Gaps in the time stamps (see [`super::gaps`]).
    pub gaps: Vec<Gap>,
    /// Number of data rows.
    pub rows: usize,
}

/// Reads a CSV log from `reader` (the caller opens the file).
///
/// Errors, each at the first defect: [`LogErrorKind::Empty`] (no header),
/// `WrongDelimiter`, `DuplicateColumn`, `MissingColumns` (all listed),
/// `RaggedRow`, `NotNumeric` (text or an empty cell in a required column),
/// `NonFinite`, `NonMonotonicTime`, `DuplicateTime`, `TooFewRows` (fewer
/// than 2 data rows), `TooLarge` (more than `max_rows` rows or
/// `max_columns` columns), `Io`. Header checks cost time linear in the
/// number of columns.
pub fn parse_log<R: Read>(reader: R, opts: &ParseOptions) -> Result<ParsedLog, LogError> {
    let file = opts.file.as_str();
    let mut rdr = ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .terminator(Terminator::Any(b'\n'))
        .buffer_capacity(1 << 16)
        .from_reader(Tracked::new(reader));
    let mut rec = ByteRecord::new();

    let header_line = loop {
        if !next_record(&mut rdr, &mut rec, file)? {
            return Err(LogError::new(
                file,
                LogErrorKind::Empty,
                "the file is empty: expected a header line with column names",
            ));
        }
        if !is_blank(&rec) {
            break record_line(&rdr);
        }
    };
    if rec.len() > opts.max_columns {
        return Err(LogError::new(
            file,
            LogErrorKind::TooLarge,
            format!(
                "the header has {} columns, more than the limit of {}",
                rec.len(),
                opts.max_columns
            ),
        )
        .at_line(header_line));
    }
    // Names are shown in messages and summaries: control characters escaped.
    let names: Vec<String> = rec
        .iter()
        .map(|b| escape_controls(&String::from_utf8_lossy(trim(b))))
        .collect();
    check_header(&names, &rec, header_line, opts)?;

    let Some(t_index) = names.iter().position(|n| n == TIME_COLUMN) else {
        // check_header guarantees `t`; stay total anyway.
        return Err(
            LogError::new(file, LogErrorKind::MissingColumns, "column t is missing")
                .at_line(header_line),
        );
    };
    let required: std::collections::HashSet<&str> =
        opts.required.iter().map(String::as_str).collect();
    let mut cols: Vec<Column> = names
        .iter()
        .enumerate()
        .map(|(i, n)| Column {
            required: i == t_index || required.contains(n.as_str()),
            alive: !n.is_empty(),
            data: Vec::new(),
            dropped: if n.is_empty() {
                Some("it has no name in the header".to_string())
            } else {
                None
            },
        })
        .collect();

    let mut rows = 0usize;
    let mut prev_t = f64::NAN;
    while next_record(&mut rdr, &mut rec, file)? {
        if is_blank(&rec) {
            continue;
        }
        let line = record_line(&rdr);
        if rec.len() != names.len() {
            let mut e = LogError::new(
                file,
                LogErrorKind::RaggedRow,
                format!(
                    "the row has {} fields, the header has {} columns",
                    rec.len(),
                    names.len()
                ),
            )
            .at_line(line);
            if let Some(first_missing) = names.get(rec.len()) {
                e = e.in_column(first_missing.as_str());
            }
            return Err(e);
        }
        if rows >= opts.max_rows {
            return Err(LogError::new(
                file,
                LogErrorKind::TooLarge,
                format!(
                    "the log has more than {} data rows, the limit; split it into shorter runs",
                    opts.max_rows
                ),
            )
            .at_line(line));
        }
        for (ci, (col, cell)) in cols.iter_mut().zip(rec.iter()).enumerate() {
            if !col.alive {
                continue;
            }
            match parse_cell(cell) {
                Ok(v) => col.data.push(v),
                Err(bad) if col.required => {
                    return Err(cell_error(file, line, &names[ci], cell, bad));
                }
                Err(bad) => {
                    col.alive = false;
                    col.data = Vec::new();
                    col.dropped = Some(format!("line {line}: {}", bad.describe(cell)));
                }
            }
        }
        // The time column is required: a row that got here pushed its t.
        let t = cols[t_index].data.last().copied().unwrap_or(f64::NAN);
        if rows > 0 && t <= prev_t {
            let (kind, msg) = if t == prev_t {
                (
                    LogErrorKind::DuplicateTime,
                    format!(
                        "t = {} repeats the previous time stamp (time must strictly increase)",
                        echoed(t)
                    ),
                )
            } else {
                (
                    LogErrorKind::NonMonotonicTime,
                    format!(
                        "t = {} is not after the previous {} (time must strictly increase)",
                        echoed(t),
                        echoed(prev_t)
                    ),
                )
            };
            return Err(LogError::new(file, kind, msg)
                .at_line(line)
                .in_column(TIME_COLUMN));
        }
        prev_t = t;
        rows += 1;
    }
    if rows < 2 {
        return Err(LogError::new(
            file,
            LogErrorKind::TooFewRows,
            format!(
                "the log has {rows} data row{}; at least 2 are needed",
                if rows == 1 { "" } else { "s" }
            ),
        ));
    }

    let mut table = LogTable {
        t: Vec::new(),
        names: Vec::new(),
        data: Vec::new(),
    };
    let mut ignored_columns = Vec::new();
    let mut warnings = Vec::new();
    for (i, (name, col)) in names.into_iter().zip(cols).enumerate() {
        if i == t_index {
            table.t = col.data;
        } else if col.alive {
            table.names.push(name);
            table.data.push(col.data);
        } else {
            let shown = if name.is_empty() {
                format!("(column {}, unnamed)", i + 1)
            } else {
                name
            };
            if ignored_columns.len() < MAX_COLUMN_WARNINGS {
                let why = col.dropped.unwrap_or_default();
                warnings.push(LogWarning::column(
                    shown.as_str(),
                    format!("{shown} is ignored: {why}"),
                ));
            }
            ignored_columns.push(shown);
        }
    }
    if ignored_columns.len() > MAX_COLUMN_WARNINGS {
        warnings.push(LogWarning {
            column: None,
            message: format!(
                "… and {} more columns are ignored (unnamed or not fully numeric; all are listed \
                 in the ignored columns)",
                ignored_columns.len() - MAX_COLUMN_WARNINGS
            ),
            units: false,
        });
    }
    if opts.heading_unit == HeadingUnit::Deg {
        warnings.extend(heading_from_degrees(&mut table));
    }
    warnings.extend(plausibility_warnings(&table));
    let gaps = table
        .median_dt()
        .map(|dt| find_gaps(&table.t, dt))
        .unwrap_or_default();
    Ok(ParsedLog {
        table,
        ignored_columns,
        warnings,
        gaps,
        rows,
    })
}

/// One column while reading.
struct Column {
    /// Required columns reject bad cells; others are dropped.
    required: bool,
    /// Still being read.
    alive: bool,
    data: Vec<f64>,
    /// Why an optional column was dropped.
    dropped: Option<String>,
}

/// Header checks in order: delimiter, duplicates, missing columns.
fn check_header(
    names: &[String],
    raw: &ByteRecord,
    line: u64,
    opts: &ParseOptions,
) -> Result<(), LogError> {
    let file = opts.file.as_str();
    if names.len() == 1 {
        let bytes = raw.get(0).unwrap_or_default();
        let found = [(b';', "';'"), (b'\t', "tabs"), (b'|', "'|'")]
            .into_iter()
            .find(|(d, _)| bytes.contains(d));
        if let Some((_, what)) = found {
            return Err(LogError::new(
                file,
                LogErrorKind::WrongDelimiter,
                format!("the header uses {what} — the format is comma-separated"),
            )
            .at_line(line));
        }
    }
    let mut first_at: std::collections::HashMap<&str, usize> =
        std::collections::HashMap::with_capacity(names.len());
    for (k, n) in names.iter().enumerate() {
        if n.is_empty() {
            continue;
        }
        if let Some(i) = first_at.insert(n.as_str(), k) {
            return Err(LogError::new(
                file,
                LogErrorKind::DuplicateColumn,
                format!(
                    "column {n} appears twice in the header (columns {} and {})",
                    i + 1,
                    k + 1
                ),
            )
            .at_line(line)
            .in_column(n.as_str()));
        }
    }
    let mut wanted: Vec<&str> = vec![TIME_COLUMN];
    for r in &opts.required {
        if !wanted.contains(&r.as_str()) {
            wanted.push(r);
        }
    }
    let missing: Vec<&str> = wanted
        .iter()
        .copied()
        .filter(|w| !first_at.contains_key(w))
        .collect();
    if missing.is_empty() {
        return check_groups(&first_at, line, opts);
    }
    let mut msg = if let [one] = missing.as_slice() {
        format!("column {one} is missing")
    } else {
        format!("columns {} are missing", missing.join(", "))
    };
    let near: Vec<String> = missing
        .iter()
        .filter_map(|m| {
            names
                .iter()
                .find(|n| n.eq_ignore_ascii_case(m))
                .map(|n| format!("'{n}' for {m}"))
        })
        .collect();
    if !near.is_empty() {
        msg.push_str(&format!(
            "; the header has {} (names are case-sensitive)",
            near.join(", ")
        ));
    }
    let who = opts.needed_by.as_deref().unwrap_or("this log");
    msg.push_str(&format!(" ({who} needs {})", wanted.join(", ")));
    Err(LogError::new(file, LogErrorKind::MissingColumns, msg).at_line(line))
}

/// Why a cell is not a usable number.
#[derive(Debug, Clone, Copy, PartialEq)]
enum BadCell {
    Empty,
    NotNumber,
    NonFinite,
}

impl BadCell {
    /// The defect in words, quoting the cell.
    fn describe(self, cell: &[u8]) -> String {
        let shown = quote(cell);
        match self {
            BadCell::Empty => "the cell is empty; every row needs a value".to_string(),
            BadCell::NotNumber => format!("{shown} is not a number"),
            BadCell::NonFinite => {
                format!("{shown} is not a finite number (NaN and infinity are not allowed)")
            }
        }
    }
}

/// Parses a trimmed decimal number; NaN, infinities and overflow are
/// `NonFinite`.
#[inline]
fn parse_cell(cell: &[u8]) -> Result<f64, BadCell> {
    let s = trim(cell);
    if s.is_empty() {
        return Err(BadCell::Empty);
    }
    let v: f64 = match fast_decimal(s) {
        Some(v) => v,
        None => std::str::from_utf8(s)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or(BadCell::NotNumber)?,
    };
    if v.is_finite() {
        Ok(v)
    } else {
        Err(BadCell::NonFinite)
    }
}

/// Fast path for plain decimals `[+-]digits[.digits]` (no exponent) whose
/// digits form an integer `m ≤ 2^53` with at most 22 decimals: so `m / 10^k` divides two exactly representable numbers and the
/// one IEEE rounding gives the same `f64` as `str::parse` (Clinger's fast
/// path). Anything else returns `None` and goes to `str::parse`.
#[inline]
fn fast_decimal(s: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (negative, body) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, s),
    };
    let mut m: u64 = 0;
    let mut digits = 0usize;
    let mut dot_at: Option<usize> = None;
    for &b in body {
        match b {
            b'0'..=b'9' => {
                digits += 1;
                if digits > 18 {
                    return None;
                }
                m = m * 10 + u64::from(b - b'0');
            }
            b'.' if dot_at.is_none() => dot_at = Some(digits),
            _ => return None,
        }
    }
    let k = digits - dot_at.unwrap_or(digits);
    if digits == 0 || m > (1u64 << 53) || k >= POW10.len() {
        return None;
    }
    let v = m as f64 / POW10[k];
    Some(if negative { -v } else { v })
}

/// The error of a bad cell in a required column.
fn cell_error(file: &str, line: u64, column: &str, cell: &[u8], bad: BadCell) -> LogError {
    let kind = match bad {
        BadCell::Empty | BadCell::NotNumber => LogErrorKind::NotNumeric,
        BadCell::NonFinite => LogErrorKind::NonFinite,
    };
    LogError::new(file, kind, bad.describe(cell))
        .at_line(line)
        .in_column(column)
}

/// A cell in quotes for messages, shortened to 40 characters.
fn quote(cell: &[u8]) -> String {
    let s = String::from_utf8_lossy(trim(cell));
    let mut out: String = escape_controls(&s.chars().take(40).collect::<String>());
    if s.chars().count() > 40 {
        out.push('…');
    }
    format!("'{out}'")
}

/// ASCII whitespace (including a `\r` left by `\r\n`) trimmed off both ends.
#[inline]
fn trim(b: &[u8]) -> &[u8] {
    b.trim_ascii()
}

/// A line holding nothing but whitespace (csv skips truly empty lines).
fn is_blank(rec: &ByteRecord) -> bool {
    rec.len() == 1 && rec.get(0).is_some_and(|f| trim(f).is_empty())
}

/// Reads the next record, mapping reader failures to [`LogErrorKind::Io`].
fn next_record<R: Read>(
    rdr: &mut csv::Reader<Tracked<R>>,
    rec: &mut ByteRecord,
    file: &str,
) -> Result<bool, LogError> {
    rdr.read_byte_record(rec).map_err(|e| {
        LogError::new(
            file,
            LogErrorKind::Io,
            format!("the log could not be read: {e}"),
        )
    })
}

/// Physical line of the record just read. csv counts `\n` consumed so far;
/// with `\n` as the only terminator a record ends by consuming its `\n`,
/// except the last one when the file does not end in a newline.
fn record_line<R: Read>(rdr: &csv::Reader<Tracked<R>>) -> u64 {
    let pos = rdr.position();
    let src = rdr.get_ref();
    let unterminated = src.eof && pos.byte() == src.total && src.last != Some(b'\n');
    if unterminated {
        pos.line()
    } else {
        pos.line().saturating_sub(1).max(1)
    }
}

/// A reader that remembers how many bytes it gave, the last one, and whether
/// it reached the end: enough to tell an unterminated last line. It also
/// turns a bare `\r` (old Mac line end) into `\n`, so such a file reads as
/// lines, not as one header of every value; `\r\n` passes unchanged (the
/// `\r` is trimmed with the last field).
struct Tracked<R> {
    inner: R,
    total: u64,
    last: Option<u8>,
    eof: bool,
    /// The previous chunk ended in a `\r`, given as `\n`: a `\n` opening
    /// the next chunk belongs to it and is dropped.
    cr_pending: bool,
}

impl<R> Tracked<R> {
    fn new(inner: R) -> Self {
        Tracked {
            inner,
            total: 0,
            last: None,
            eof: false,
            cr_pending: false,
        }
    }
}

impl<R: Read> Read for Tracked<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        loop {
            let mut n = self.inner.read(buf)?;
            if n == 0 {
                self.eof |= !buf.is_empty();
                return Ok(0);
            }
            if std::mem::take(&mut self.cr_pending) && buf[0] == b'\n' {
                buf.copy_within(1..n, 0);
                n -= 1;
                if n == 0 {
                    continue;
                }
            }
            for i in 0..n {
                if buf[i] == b'\r' {
                    match buf[..n].get(i + 1) {
                        Some(b'\n') => {}
                        Some(_) => buf[i] = b'\n',
                        None => {
                            buf[i] = b'\n';
                            self.cr_pending = true;
                        }
                    }
                }
            }
            self.total += n as u64;
            self.last = Some(buf[n - 1]);
            return Ok(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::examples::{supply_vessel, surveyor_rov};

    fn opts(required: &[&str]) -> ParseOptions {
        ParseOptions::new("file", required.iter().map(|s| s.to_string()).collect())
    }

    fn parse(csv: &str, required: &[&str]) -> Result<ParsedLog, LogError> {
        parse_log(csv.as_bytes(), &opts(required))
    }

    fn err(csv: &str, required: &[&str]) -> LogError {
        match parse(csv, required) {
            Ok(p) => panic!("expected an error, parsed {} rows", p.rows),
            Err(e) => e,
        }
    }

    /// (kind, line, column) of an error.
    fn at(e: &LogError) -> (LogErrorKind, Option<u64>, Option<&str>) {
        (e.kind, e.line, e.column.as_deref())
    }

    #[test]
    fn parses_columns_in_any_order_and_keeps_numeric_unknowns() {
        let csv = "u, t ,psi,depth_raw,mode\n0.5,0.0,0.1,12,AUTO\n0.6,0.1,0.2,13,AUTO\n0.7,0.2,0.3,14,MAN\n";
        let p = parse(csv, &["t", "u", "psi"]).unwrap();
        assert_eq!(p.rows, 3);
        assert_eq!(p.table.t, [0.0, 0.1, 0.2]);
        assert_eq!(p.table.names, ["u", "psi", "depth_raw"]);
        assert_eq!(p.table.column("depth_raw"), Some(&[12.0, 13.0, 14.0][..]));
        assert_eq!(p.ignored_columns, ["mode"]);
        assert_eq!(p.warnings.len(), 1);
        assert_eq!(p.warnings[0].column.as_deref(), Some("mode"));
        assert_eq!(
            p.warnings[0].message,
            "mode is ignored: line 2: 'AUTO' is not a number"
        );
        assert!(p.gaps.is_empty());
    }

    #[test]
    fn unknown_columns_with_gaps_nan_or_no_name_are_ignored() {
        let csv = "t,u,aux,flag,\n0,1,,nan,\n1,2,3,1,\n2,3,4,0,\n";
        let p = parse(csv, &["u"]).unwrap();
        assert_eq!(p.table.names, ["u"]);
        assert_eq!(p.ignored_columns, ["aux", "flag", "(column 5, unnamed)"]);
        assert_eq!(
            p.warnings[1].message,
            "flag is ignored: line 2: 'nan' is not a finite number (NaN and infinity are not allowed)"
        );
    }

    #[test]
    fn bom_crlf_quotes_spaces_and_blank_lines_are_accepted() {
        let csv = "\u{feff}t,u\r\n0.0, 1.5 \r\n\r\n\"0.1\",2\r\n  \r\n0.2,3e0\r\n\r\n\n";
        let p = parse(csv, &["t", "u"]).unwrap();
        assert_eq!(p.rows, 3);
        assert_eq!(p.table.names, ["u"]);
        assert_eq!(p.table.t, [0.0, 0.1, 0.2]);
        assert_eq!(p.table.data[0], [1.5, 2.0, 3.0]);
    }

    #[test]
    fn line_numbers_count_blank_lines_crlf_and_a_missing_final_newline() {
        // Header after two blank lines; data with blank lines between.
        let e = err("\n\nt,u\n0,1\n\n\n1,x\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(7), Some("u")));
        let e = err("t,u\r\n0,1\r\n\r\n1,2\r\n2,x\r\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(5), Some("u")));
        let e = err("t,u\n0,1\n1,2\n\n2,x", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(5), Some("u")));
        let e = err("t,u\r\n0,1\r\n1,x", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("u")));
        let e = err("\u{feff}t;u\n", &["u"]);
        assert_eq!(e.line, Some(1));
    }

    #[test]
    fn empty_file_and_too_few_rows() {
        for csv in ["", "\n\n", " \r\n\r\n"] {
            let e = err(csv, &["u"]);
            assert_eq!(at(&e), (LogErrorKind::Empty, None, None), "{csv:?}");
        }
        let e = err("t,u\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::TooFewRows, None, None));
        assert_eq!(
            e.to_string(),
            "file: the log has 0 data rows; at least 2 are needed"
        );
        let e = err("t,u\n0,1\n\n", &["u"]);
        assert_eq!(e.kind, LogErrorKind::TooFewRows);
        assert_eq!(e.message, "the log has 1 data row; at least 2 are needed");
    }

    #[test]
    fn wrong_delimiter_is_named() {
        let e = err("t;u;psi\n0;1;2\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::WrongDelimiter, Some(1), None));
        assert_eq!(
            e.to_string(),
            "file, line 1: the header uses ';' — the format is comma-separated"
        );
        assert!(err("t\tu\n0\t1\n", &["u"]).message.contains("uses tabs"));
        assert!(err("t|u\n0|1\n", &["u"]).message.contains("uses '|'"));
        // A lone column without separators is a missing-columns error.
        assert_eq!(err("t\n0\n1\n", &["u"]).kind, LogErrorKind::MissingColumns);
    }

    /// A reader giving `chunk` bytes at a time (chunk boundaries anywhere).
    struct Chunked<'a>(&'a [u8], usize);

    impl Read for Chunked<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.1.min(buf.len()).min(self.0.len());
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    #[test]
    fn bare_cr_line_ends_read_like_lf_at_any_chunk_boundary() {
        let lf = parse("t,u\n0,1\n0.1,2\n0.2,3\n", &["u"]).unwrap();
        for csv in [
            "t,u\r0,1\r0.1,2\r0.2,3\r",
            "t,u\r\n0,1\r\n0.1,2\r\n0.2,3\r\n",
            "t,u\r0,1\r\n0.1,2\n0.2,3",
        ] {
            for chunk in [1, 2, 3, 7, 1 << 16] {
                let p = parse_log(Chunked(csv.as_bytes(), chunk), &opts(&["u"]))
                    .unwrap_or_else(|e| panic!("{csv:?} by {chunk}: {e}"));
                assert_eq!(p.table, lf.table, "{csv:?} by {chunk}");
            }
        }
        // Line numbers count CR line ends.
        let e = err("t,u\r0,1\r0.1,x\r0.2,3\r", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("u")));
        // The old report: the whole file as one header of numbers.
        let old_mac = "t,u,v\r-35496.16,1,2\r-35496.06,1,2\r-35495.96,1,2\r";
        let p = parse(old_mac, &["u"]).unwrap();
        assert_eq!(p.rows, 3);
    }

    #[test]
    fn a_wide_header_is_refused_naming_the_limit_and_read_in_linear_time() {
        let n = 100_000;
        let header: Vec<String> = (0..n)
            .map(|i| if i == 0 { "t".into() } else { format!("c{i}") })
            .collect();
        let row = vec!["1"; n].join(",");
        let csv = format!("{}\n{row}\n{}\n", header.join(","), vec!["2"; n].join(","));
        let e = err(&csv, &[]);
        assert_eq!(e.kind, LogErrorKind::TooLarge);
        assert_eq!(
            e.message,
            "the header has 100000 columns, more than the limit of 10000"
        );
        // Allowed that wide, it reads in well under a second (quadratic
        // duplicate detection took 8 s).
        let wide = ParseOptions {
            max_columns: 200_000,
            ..opts(&[])
        };
        let started = std::time::Instant::now();
        let p = parse_log(csv.as_bytes(), &wide).unwrap();
        assert_eq!(p.table.names.len(), n - 1);
        assert!(
            started.elapsed().as_secs_f64() < 3.0,
            "{:?}",
            started.elapsed()
        );
        // A duplicate at the far end is still found.
        let dup = format!("{},c1\n", header.join(","));
        let started = std::time::Instant::now();
        let e = parse_log(dup.as_bytes(), &wide).unwrap_err();
        assert!(started.elapsed().as_secs_f64() < 3.0);
        assert_eq!(
            e.message,
            "column c1 appears twice in the header (columns 2 and 100001)"
        );
    }

    #[test]
    fn ignored_column_warnings_are_bounded() {
        let names: Vec<String> = (0..50).map(|i| format!("note{i}")).collect();
        let cells = vec!["x"; 50].join(",");
        let csv = format!("t,u,{}\n0,1,{cells}\n0.1,2,{cells}\n", names.join(","));
        let p = parse(&csv, &["u"]).unwrap();
        assert_eq!(p.ignored_columns.len(), 50);
        let ignored: Vec<&LogWarning> = p
            .warnings
            .iter()
            .filter(|w| w.message.contains("ignored"))
            .collect();
        assert_eq!(ignored.len(), MAX_COLUMN_WARNINGS + 1);
        assert_eq!(
            ignored[MAX_COLUMN_WARNINGS].message,
            "… and 30 more columns are ignored (unnamed or not fully numeric; all are listed in the ignored columns)"
        );
    }

    #[test]
    fn control_characters_and_long_numbers_are_not_echoed_raw() {
        let e = err("t,u\n0,1\n0.1,\u{1b}[31mred\n", &["u"]);
        assert_eq!(e.message, "'\\u{1b}[31mred' is not a number");
        let e = err("t,u\n1e300,1\n1e299,2\n", &["u"]);
        assert_eq!(
            e.message,
            "t = 1e299 is not after the previous 1e300 (time must strictly increase)"
        );
        let p = parse("t,u,a\u{7}b\n0,1,x\n0.1,2,y\n", &["u"]).unwrap();
        assert_eq!(p.ignored_columns, ["a\\u{7}b"]);
    }

    #[test]
    fn duplicate_column_names_line_and_column() {
        let e = err("t,u,v, u\n0,1,2,3\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::DuplicateColumn, Some(1), Some("u")));
        assert_eq!(
            e.message,
            "column u appears twice in the header (columns 2 and 4)"
        );
    }

    #[test]
    fn missing_columns_are_all_listed_with_who_needs_them() {
        let v = surveyor_rov();
        let header = "t,tau_X,tau_Y,tau_Z,tau_K,tau_M,tau_N,v,w,p,q,R,x,y,z,phi,theta\n";
        let e = parse_log(
            format!("{header}0{}\n", ",0".repeat(16)).as_bytes(),
            &ParseOptions::for_vessel(&v, LogRole::Single, None),
        )
        .unwrap_err();
        assert_eq!(at(&e), (LogErrorKind::MissingColumns, Some(1), None));
        assert_eq!(
            e.to_string(),
            "file, line 1: columns u, r, psi are missing; the header has 'R' for r (names are \
             case-sensitive) (the 6-DOF ROV 'Surveyor ROV' needs t, tau_X, tau_Y, tau_Z, tau_K, \
             tau_M, tau_N, u, v, w, p, q, r, x, y, z, phi, theta, psi)"
        );
        let e = parse_log(
            "t,thr_1,u\n0,0,0\n".as_bytes(),
            &ParseOptions::for_vessel(&supply_vessel(), LogRole::Control, None),
        )
        .unwrap_err();
        assert_eq!(e.file, "control");
        assert!(
            e.message
                .starts_with("columns thr_2, thr_3, thr_4, thr_5, thr_6 are missing")
        );
        // t is required even when not listed.
        let e = err("u,v\n1,2\n", &["u"]);
        assert!(
            e.message
                .starts_with("column t is missing (this log needs t, u)"),
            "{e}"
        );
    }

    #[test]
    fn ragged_rows_name_line_and_first_missing_column() {
        let e = err("t,u,psi\n0,1,2\n1,2\n", &["u", "psi"]);
        assert_eq!(at(&e), (LogErrorKind::RaggedRow, Some(3), Some("psi")));
        assert_eq!(e.message, "the row has 2 fields, the header has 3 columns");
        let e = err("t,u\n0,1\n1,2\n2,3,4\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::RaggedRow, Some(4), None));
    }

    #[test]
    fn text_and_empty_cells_in_required_columns() {
        let mut csv = String::from("t,tau_X,tau_K\n");
        for k in 0..1831 {
            csv.push_str(&format!("{k},1,2\n"));
        }
        csv.push_str("1831,1,abc\n");
        let e = parse_log(
            csv.as_bytes(),
            &ParseOptions::new("control", vec!["tau_K".into()]),
        )
        .unwrap_err();
        assert_eq!(
            at(&e),
            (LogErrorKind::NotNumeric, Some(1833), Some("tau_K"))
        );
        assert_eq!(
            e.to_string(),
            "control, line 1833, column tau_K: 'abc' is not a number"
        );

        let e = err("t,u,v\n0,1,2\n1, ,2\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("u")));
        assert_eq!(e.message, "the cell is empty; every row needs a value");
        let e = err("t,u\n0,1\n,2\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NotNumeric, Some(3), Some("t")));
        let e = err("t,u\n0,1\n1,1.2.3\n", &["u"]);
        assert_eq!(e.message, "'1.2.3' is not a number");
    }

    #[test]
    fn nan_infinity_and_overflow_are_non_finite() {
        for (cell, shown) in [
            ("NaN", "'NaN'"),
            ("nan", "'nan'"),
            ("inf", "'inf'"),
            ("-Infinity", "'-Infinity'"),
            ("1e400", "'1e400'"),
        ] {
            let e = err(&format!("t,u\n0,1\n1,2\n2,{cell}\n"), &["u"]);
            assert_eq!(
                at(&e),
                (LogErrorKind::NonFinite, Some(4), Some("u")),
                "{cell}"
            );
            assert!(
                e.message
                    .starts_with(&format!("{shown} is not a finite number"))
            );
        }
        let e = err("t,u\n0,1\nNAN,2\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::NonFinite, Some(3), Some("t")));
    }

    #[test]
    fn time_must_strictly_increase() {
        let mut csv = String::from("t,u\n");
        for k in 0..9 {
            csv.push_str(&format!("{:.1},0\n", 2.4 + 0.1 * k as f64));
        }
        assert_eq!(parse(&csv, &["u"]).unwrap().rows, 9);
        let e = err(&format!("{csv}3.1,0\n"), &["u"]);
        assert_eq!(
            at(&e),
            (LogErrorKind::NonMonotonicTime, Some(11), Some("t"))
        );
        let e = err("t,u\n0,1\n0.5,1\n0.5,2\n", &["u"]);
        assert_eq!(at(&e), (LogErrorKind::DuplicateTime, Some(4), Some("t")));
        assert_eq!(
            e.message,
            "t = 0.5 repeats the previous time stamp (time must strictly increase)"
        );
        let e = err("t,u\n0,1\n3.3,1\n3.2,2\n", &["u"]);
        assert_eq!(
            e.to_string(),
            "file, line 4, column t: t = 3.2 is not after the previous 3.3 (time must strictly increase)"
        );
    }

    #[test]
    fn fast_decimal_path_agrees_with_str_parse() {
        let mut cases: Vec<String> = [
            "0",
            "-0",
            "+1",
            "1.",
            ".5",
            "-.5",
            "0.1",
            "0.3",
            "123456.789",
            "-0.000001",
            "9007199254740992",
            "9007199254740993",
            "0.12345678901234567",
            "1.0000000000000000000001",
            "12345678901234567890",
            "1e5",
            ".",
            "-",
            "",
            "1.2.3",
            "--1",
            "0x10",
            "1_0",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        // Deterministic pseudo-random decimals of every length.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..20_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let digits = format!("{}", state % 10u64.pow((state % 17) as u32 + 1));
            let cut = (state >> 40) as usize % (digits.len() + 1);
            let sign = if state & 1 == 1 { "-" } else { "" };
            cases.push(format!("{sign}{}.{}", &digits[..cut], &digits[cut..]));
        }
        for c in &cases {
            let fast = fast_decimal(c.as_bytes());
            let slow: Option<f64> = c.parse().ok();
            if let Some(f) = fast {
                assert_eq!(Some(f.to_bits()), slow.map(f64::to_bits), "{c}");
            }
        }
        assert!(fast_decimal(b"0.1").is_some() && fast_decimal(b"1e5").is_none());
    }

    #[test]
    fn too_many_rows() {
        let o = ParseOptions {
            max_rows: 3,
            ..opts(&["u"])
        };
        assert_eq!(
            parse_log("t,u\n0,1\n1,1\n2,1\n".as_bytes(), &o)
                .unwrap()
                .rows,
            3
        );
        let e = parse_log("t,u\n0,1\n1,1\n2,1\n\n3,1\n".as_bytes(), &o).unwrap_err();
        assert_eq!(at(&e), (LogErrorKind::TooLarge, Some(6), None));
    }

    #[test]
    fn reader_failure_is_io() {
        struct Failing(usize);
        impl Read for Failing {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                if self.0 == 0 {
                    return Err(io::Error::other("disk gone"));
                }
                self.0 = 0;
                let s = b"t,u\n0,1\n";
                buf[..s.len()].copy_from_slice(s);
                Ok(s.len())
            }
        }
        let e = parse_log(Failing(1), &opts(&["u"])).unwrap_err();
        assert_eq!(e.kind, LogErrorKind::Io);
        assert!(e.message.contains("disk gone"));
    }

    #[test]
    fn heading_in_degrees_warns_and_radians_do_not() {
        let mut deg = String::from("t,u,psi\n");
        let mut rad = deg.clone();
        for k in 0..200 {
            let heading = (350.0 + 0.3 * k as f64) % 360.0;
            deg.push_str(&format!(
                "{},{},{heading}\n",
                0.1 * k as f64,
                1.0 + 0.01 * k as f64
            ));
            rad.push_str(&format!(
                "{},{},{}\n",
                0.1 * k as f64,
                1.0 + 0.01 * k as f64,
                heading.to_radians()
            ));
        }
        let p = parse(&deg, &["u", "psi"]).unwrap();
        assert_eq!(p.warnings.len(), 1, "{:?}", p.warnings);
        assert_eq!(p.warnings[0].column.as_deref(), Some("psi"));
        assert!(
            p.warnings[0]
                .message
                .starts_with("psi looks like degrees (max 359.9")
        );
        let p = parse(&rad, &["u", "psi"]).unwrap();
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
    }

    #[test]
    fn gaps_are_reported_with_missing_counts() {
        // 10 Hz; after t = 1.0 three samples are missing, after 3.0 twenty.
        let mut t: Vec<f64> = (0..=10).map(|k| k as f64 * 0.1).collect();
        t.extend((14..=30).map(|k| k as f64 * 0.1));
        t.extend((51..=60).map(|k| k as f64 * 0.1));
        let mut csv = String::from("t,u\n");
        for (k, v) in t.iter().enumerate() {
            csv.push_str(&format!("{v},{}\n", k % 7));
        }
        let p = parse(&csv, &["u"]).unwrap();
        let got: Vec<(usize, bool)> = p
            .gaps
            .iter()
            .map(|g| (g.missing_samples, g.bridged))
            .collect();
        assert_eq!(got, [(3, true), (20, false)]);
        assert_eq!(
            (p.gaps[0].start_t, p.gaps[0].end_t),
            (1.0, 1.4000000000000001)
        );
        assert_eq!(p.gaps[1].start_t, 3.0);
    }
}
