//! Errors of the drive-cycle layer: one value names the cycle, the 1-based line of the file, the
//! column, the offending value and what is allowed.

use std::fmt;

/// What kind of problem a [`CycleError`] reports (for callers and tests that branch on it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CycleErrorKind {
    /// The file could not be read (exit code 3 territory).
    Io,
    /// Not a bundled cycle name (and, for `resolve`, not a readable file either).
    UnknownName,
    /// Malformed CSV, or a missing / unknown / duplicate header column.
    Header,
    /// A row with the wrong number of fields.
    Fields,
    /// A value that is not a finite number, or out of range (negative speed...).
    Value,
    /// Time not increasing, or negative.
    Time,
    /// Fewer than two rows.
    TooShort,
    /// A gear name that is not a gear state of the model (checked at schedule time).
    UnknownGear,
    /// The cycle needs something the configuration does not give (vehicle, shift strategy).
    Config,
}

/// An error in a drive cycle, printed as one line:
/// `cycle.csv:12: column speed_kmh = "-3": must be >= 0 km/h`.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleError {
    /// What went wrong, coarsely.
    pub kind: CycleErrorKind,
    /// The cycle's source: a file path, or `bundled:<name>`.
    pub source: String,
    /// 1-based line number in the file, where one applies.
    pub line: Option<usize>,
    /// Column name (header name), where one applies.
    pub column: Option<String>,
    /// The offending value as written, where one applies.
    pub value: Option<String>,
    /// What is allowed / what went wrong.
    pub allowed: String,
}

impl CycleError {
    /// An error that is not tied to a line or column.
    pub fn new(kind: CycleErrorKind, source: &str, allowed: impl Into<String>) -> Self {
        CycleError {
            kind,
            source: source.to_string(),
            line: None,
            column: None,
            value: None,
            allowed: allowed.into(),
        }
    }

    /// Set the 1-based line number.
    pub fn at_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }

    /// Set the column name and the offending value.
    pub fn at_value(mut self, column: &str, value: impl Into<String>) -> Self {
        self.column = Some(column.to_string());
        self.value = Some(value.into());
        self
    }

    /// Set only the column name.
    pub fn at_column(mut self, column: &str) -> Self {
        self.column = Some(column.to_string());
        self
    }
}

impl fmt::Display for CycleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.source)?;
        if let Some(line) = self.line {
            write!(f, ", line {line}")?;
        }
        write!(f, ": ")?;
        match (&self.column, &self.value) {
            (Some(c), Some(v)) => write!(f, "column {c} = \"{v}\": ")?,
            (Some(c), None) => write!(f, "column {c}: ")?,
            (None, Some(v)) => write!(f, "\"{v}\": ")?,
            (None, None) => {}
        }
        write!(f, "{}", self.allowed)
    }
}

impl std::error::Error for CycleError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_is_one_line_with_all_parts() {
        let e = CycleError::new(CycleErrorKind::Value, "c.csv", "must be >= 0 km/h")
            .at_line(12)
            .at_value("speed_kmh", "-3");
        let s = e.to_string();
        assert_eq!(s, "c.csv, line 12: column speed_kmh = \"-3\": must be >= 0 km/h");
        assert!(!s.contains('\n'));
        let e = CycleError::new(CycleErrorKind::Config, "bundled:wltc", "needs a vehicle");
        assert_eq!(e.to_string(), "bundled:wltc: needs a vehicle");
    }
}
