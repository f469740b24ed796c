//! The typed error of every job: what went wrong (invalid input, numerical failure, I/O), one
//! message that every front end shows unchanged, and the problems with their key paths.

use std::fmt;

use crate::model::{ModelError, Problem};

/// What kind of failure a job reports; each maps to one exit code of the CLI.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// An invalid model file or override; the problems carry key paths (exit code 1).
    Model,
    /// An option outside its allowed values; the problem names the option (exit code 1).
    Option,
    /// Other invalid input: a cycle, a trace, a study (exit code 1).
    Invalid,
    /// The solver failed, or a result left the range where its models hold (exit code 2).
    Numerical,
    /// A file could not be read or written (exit code 3).
    Io,
}

impl ErrorKind {
    /// The CLI's exit code of this kind.
    pub const fn exit_code(self) -> i32 {
        match self {
            ErrorKind::Model | ErrorKind::Option | ErrorKind::Invalid => 1,
            ErrorKind::Numerical => 2,
            ErrorKind::Io => 3,
        }
    }
}

/// A failed job: its kind, its message (shown as is by the CLI, a study row and Python), and
/// the problems behind it, each with its key path or option name, value and allowed range.
#[derive(Debug, Clone, PartialEq)]
pub struct JobError {
    /// Kind (exit code).
    pub kind: ErrorKind,
    /// The message, naming the file, key path or option, value and allowed range.
    pub message: String,
    /// Every problem found (empty for numerical failures and I/O).
    pub problems: Vec<Problem>,
    /// The I/O error's kind, when `kind` is [`ErrorKind::Io`] (e.g. not found).
    pub io_kind: Option<std::io::ErrorKind>,
    /// The file the error is about, where one is (a file that cannot be read, an invalid
    /// model file).
    pub file: Option<std::path::PathBuf>,
}

impl fmt::Display for JobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for JobError {}

impl JobError {
    /// Invalid input described by a message alone.
    pub fn invalid(message: impl Into<String>) -> JobError {
        JobError {
            kind: ErrorKind::Invalid,
            message: message.into(),
            problems: Vec::new(),
            io_kind: None,
            file: None,
        }
    }

    /// An option outside its allowed values: `option` is its name (`speed_rpm`), `value` as
    /// given, `allowed` what it may be; the message is `message`.
    pub fn option(
        option: &str,
        value: impl fmt::Display,
        allowed: impl Into<String>,
        message: String,
    ) -> JobError {
        JobError {
            kind: ErrorKind::Option,
            message,
            problems: vec![Problem {
                path: option.to_string(),
                value: value.to_string(),
                allowed: allowed.into(),
            }],
            io_kind: None,
            file: None,
        }
    }

    /// A numerical failure (the message names time, node and loss item where known).
    pub fn numerical(message: impl Into<String>) -> JobError {
        JobError {
            kind: ErrorKind::Numerical,
            message: message.into(),
            problems: Vec::new(),
            io_kind: None,
            file: None,
        }
    }

    /// An I/O failure.
    pub fn io(message: impl Into<String>, io_kind: std::io::ErrorKind) -> JobError {
        JobError {
            kind: ErrorKind::Io,
            message: message.into(),
            problems: Vec::new(),
            io_kind: Some(io_kind),
            file: None,
        }
    }

    /// The CLI's exit code.
    pub fn exit_code(&self) -> i32 {
        self.kind.exit_code()
    }

    /// True for invalid input of any kind (model, option, other).
    pub fn is_invalid(&self) -> bool {
        self.exit_code() == 1
    }

    /// The same error about `file`.
    pub fn in_file(mut self, file: impl Into<std::path::PathBuf>) -> JobError {
        self.file = Some(file.into());
        self
    }

    /// The same error with `prefix: ` in front of its message (e.g. the model file).
    pub fn prefixed(mut self, prefix: &str) -> JobError {
        self.message = format!("{prefix}: {}", self.message);
        self
    }
}

impl From<ModelError> for JobError {
    /// A model file that cannot be read (missing, no permission, a directory) is I/O; one that
    /// is read but is not UTF-8 text, or that is invalid, is invalid input.
    fn from(e: ModelError) -> JobError {
        let message = e.report().trim_end().to_string();
        match e {
            ModelError::Io { source, file } if source.kind() != std::io::ErrorKind::InvalidData => {
                JobError::io(message, source.kind()).in_file(file)
            }
            ModelError::Io { file, .. } => JobError::invalid(message).in_file(file),
            ModelError::Invalid { problems, file } => JobError {
                kind: ErrorKind::Model,
                message,
                problems,
                io_kind: None,
                file: Some(file),
            },
        }
    }
}

impl From<crate::cycle::CycleError> for JobError {
    /// A cycle file that exists but cannot be read is I/O; every other cycle problem is input.
    fn from(e: crate::cycle::CycleError) -> JobError {
        let message = format!("cycle: {e}");
        if e.kind == crate::cycle::CycleErrorKind::Io {
            return JobError::io(message, std::io::ErrorKind::Other);
        }
        // The problem: the column and its cell, or the cycle option and the name given.
        let (path, value) = match (&e.column, &e.value) {
            (Some(c), v) => (c.clone(), v.clone().unwrap_or_default()),
            (None, v) => ("cycle".to_string(), v.clone().unwrap_or_else(|| e.source.clone())),
        };
        JobError {
            problems: vec![Problem {
                path,
                value,
                allowed: e.allowed.clone(),
            }],
            ..JobError::invalid(message)
        }
    }
}

impl From<crate::report::files::OutputError> for JobError {
    /// An output that cannot be written is I/O.
    fn from(e: crate::report::files::OutputError) -> JobError {
        JobError::io(format!("cannot write outputs: {e}"), std::io::ErrorKind::Other)
    }
}

impl From<crate::report::study::JournalError> for JobError {
    /// A journal of another study in the output directory is a usage error (invalid input); a
    /// journal that cannot be read is I/O.
    fn from(e: crate::report::study::JournalError) -> JobError {
        use crate::report::study::JournalError;
        let message = e.to_string();
        match e {
            JournalError::Foreign(_) => JobError::invalid(message),
            JournalError::Io { source, .. } => JobError::io(message, source.kind()),
        }
    }
}

/// A text input file (study, model, cycle, trace): one that cannot be read (missing, no
/// permission, a directory) is I/O; one that is read but is not UTF-8 text is invalid input,
/// as for a model file. The message is `FILE: cannot read: CAUSE`.
pub fn read_text(path: &std::path::Path) -> Result<String, JobError> {
    std::fs::read_to_string(path).map_err(|e| {
        let message = format!("{}: cannot read: {e}", path.display());
        match e.kind() {
            std::io::ErrorKind::InvalidData => JobError::invalid(message),
            kind => JobError::io(message, kind),
        }
        .in_file(path)
    })
}

impl From<crate::report::plots::PlotError> for JobError {
    /// A figure's input that cannot be parsed or lacks what the figure needs (or is not UTF-8
    /// text) is invalid input; a file that cannot be read or written, or a drawing that fails,
    /// is I/O.
    fn from(e: crate::report::plots::PlotError) -> JobError {
        use crate::report::plots::PlotError;
        let message = format!("report: {e}");
        match &e {
            PlotError::Csv { .. } | PlotError::Json { .. } | PlotError::Data { .. } => {
                JobError::invalid(message)
            }
            PlotError::Io { source, .. } if source.kind() == std::io::ErrorKind::InvalidData => {
                JobError::invalid(message)
            }
            PlotError::Io { source, .. } => JobError::io(message, source.kind()),
            _ => JobError::io(message, std::io::ErrorKind::Other),
        }
    }
}

impl From<super::calibrate::trace::TraceError> for JobError {
    /// A trace that does not parse is invalid input (the message names file, line and column).
    fn from(e: super::calibrate::trace::TraceError) -> JobError {
        JobError::invalid(e.0)
    }
}
