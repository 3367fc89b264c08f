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

use self::cell::{cell_error, parse_cell, trim};
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

mod cell;
#[cfg(test)]
mod tests;
