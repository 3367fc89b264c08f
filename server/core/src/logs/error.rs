//! The one error of log reading: what is wrong, where (file, physical line,
//! column) and in words a trial supervisor understands. The service maps it
//! to 422 and shows [`LogError`]'s `Display`, e.g.
//! `control, line 1833, column tau_K: 'abc' is not a number`.

use std::fmt;

use serde::Serialize;

/// What kind of defect a log has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum LogErrorKind {
    /// No header: the file is empty or holds only blank lines.
    Empty,
    /// The header is separated by `;`, tab or `|` instead of commas.
    WrongDelimiter,
    /// Columns the vessel profile needs are not in the header.
    MissingColumns,
    /// A column name appears twice in the header.
    DuplicateColumn,
    /// A row has more or fewer fields than the header.
    RaggedRow,
    /// A cell of a needed column is empty or not a number.
    NotNumeric,
    /// A cell is NaN or ±infinity (or overflows an `f64`).
    NonFinite,
    /// A time stamp is earlier than the previous one.
    NonMonotonicTime,
    /// A time stamp repeats the previous one.
    DuplicateTime,
    /// Fewer than two data rows.
    TooFewRows,
    /// More rows (or resampled values) than the configured limit.
    TooLarge,
    /// The reader failed (an I/O error of the caller's stream).
    Io,
    /// A requested resampling rate is not a finite positive number.
    InvalidRate,
}

/// A log that cannot be used, with the place of the first defect.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
pub struct LogError {
    /// Which file: `"file"` (a single log), `"control"` or `"nav"`.
    pub file: String,
    /// 1-based physical line of the defect (the header is line 1 unless blank
    /// lines precede it); `None` for defects of the file as a whole.
    pub line: Option<u64>,
    /// Name of the offending column, when one is at fault.
    pub column: Option<String>,
    /// Kind of defect, for programs.
    pub kind: LogErrorKind,
    /// What is wrong, for people (without the file/line/column prefix that
    /// `Display` adds).
    pub message: String,
}

impl LogError {
    /// An error of a whole file (no line, no column).
    pub fn new(file: impl Into<String>, kind: LogErrorKind, message: impl Into<String>) -> Self {
        LogError {
            file: file.into(),
            line: None,
            column: None,
            kind,
            message: message.into(),
        }
    }

    /// The same error, located at a physical line.
    pub fn at_line(mut self, line: u64) -> Self {
        self.line = Some(line);
        self
    }

    /// The same error, located in a column.
    pub fn in_column(mut self, column: impl Into<String>) -> Self {
        self.column = Some(column.into());
        self
    }
}

impl fmt::Display for LogError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(line) = self.line {
            write!(f, ", line {line}")?;
        }
        if let Some(column) = &self.column {
            write!(f, ", column {column}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for LogError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_prefixes_file_line_and_column() {
        let e = LogError::new("control", LogErrorKind::NotNumeric, "'abc' is not a number")
            .at_line(1833)
            .in_column("tau_K");
        assert_eq!(
            e.to_string(),
            "control, line 1833, column tau_K: 'abc' is not a number"
        );
        let e = LogError::new("file", LogErrorKind::TooFewRows, "only 1 data row");
        assert_eq!(e.to_string(), "file: only 1 data row");
        let json = serde_json::to_value(&e).unwrap();
        assert_eq!(json["kind"], "too_few_rows");
        assert_eq!(json["line"], serde_json::Value::Null);
    }
}
