//! What the CLI writes to its standard streams, and its failures with their exit codes.
//!
//! Standard output is written in one piece before an output directory is committed, so that a
//! failure to write it leaves the previous result set in place: a closed pipe ends the command
//! quietly with status 141 (128 + SIGPIPE, as a shell reports a writer killed by it), any other
//! write error is I/O (exit 3). Standard error carries warnings and progress; a failure to write
//! it is ignored.

use std::io::{ErrorKind, IsTerminal, Write};

use crate::job::{ErrorKind as ErrorKindJob, JobError};

/// Exit code: I/O failure (the code of [`crate::job::ErrorKind::Io`]).
pub const EXIT_IO: i32 = crate::job::ErrorKind::Io.exit_code();
/// Exit code: standard output closed by its reader (128 + SIGPIPE).
pub const EXIT_BROKEN_PIPE: i32 = 141;

/// A failure with its exit code and message (empty: end quietly).
#[derive(Debug)]
pub struct Failure {
    /// Exit code.
    pub code: i32,
    /// Message for stderr.
    pub message: String,
}

impl From<JobError> for Failure {
    /// The exit code of the error's kind; an option named at the message's start gets its
    /// flag after it (the command line's spelling of the job layer's option names).
    fn from(e: JobError) -> Self {
        let option = match e.kind {
            ErrorKindJob::Option => e.problems.first().map(|p| p.path.as_str()),
            _ => None,
        };
        Failure {
            code: e.exit_code(),
            message: crate::job::options::spelled_for_cli(&e.message, option),
        }
    }
}

impl From<crate::report::files::OutputError> for Failure {
    fn from(e: crate::report::files::OutputError) -> Self {
        JobError::from(e).into()
    }
}

/// Invalid input described by a message (the exit code of [`crate::job::ErrorKind::Invalid`]).
pub fn invalid(message: String) -> Failure {
    JobError::invalid(message).into()
}

/// I/O failure described by a message (the exit code of [`crate::job::ErrorKind::Io`]).
pub fn io_failure(message: String) -> Failure {
    JobError::io(message, ErrorKind::Other).into()
}

/// The failure of a write to standard output.
fn stdout_failure(e: &std::io::Error) -> Failure {
    if e.kind() == ErrorKind::BrokenPipe {
        Failure {
            code: EXIT_BROKEN_PIPE,
            message: String::new(),
        }
    } else {
        io_failure(format!("cannot write to standard output: {e}"))
    }
}

/// Write `text` to standard output and flush it.
pub fn emit(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|_| out.flush())
        .map_err(|e| stdout_failure(&e))
}

/// `value` as pretty JSON plus a newline on standard output.
pub fn emit_json<T: serde::Serialize>(value: &T) -> Result<(), Failure> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| io_failure(format!("cannot serialise the report: {e}")))?;
    emit(&format!("{text}\n"))
}

/// One line on standard error (ignored when standard error cannot be written).
pub fn warn(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// Each out-of-range warning as one stderr line (the scene only collects them).
pub fn warnings(w: &[crate::job::RangeWarning]) {
    for x in w {
        warn(&x.to_string());
    }
}

/// Each model-form spread disagreement as one stderr line (`warning: item …`).
pub fn spread_warnings(s: Option<&crate::report::spread::SpreadBlock>) {
    for x in s.iter().flat_map(|b| &b.warnings) {
        warn(&format!("warning: {x}"));
    }
}

/// A progress bar on a terminal's standard error (None when quiet or not a terminal).
pub fn progress_bar(
    len: usize,
    template: &str,
    message: String,
    quiet: bool,
) -> Option<indicatif::ProgressBar> {
    (!quiet && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new(len as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
            b.set_style(style.progress_chars("=> "));
        }
        b.set_message(message);
        b
    })
}
