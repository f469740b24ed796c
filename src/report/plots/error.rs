//! The error of reading outputs back and drawing them ([`PlotError`]).

use std::path::PathBuf;

use crate::report::files::user_path;

/// Errors of the plot reports. Every variant names the file concerned, as the user knows it
/// (a file in a transaction's temporary directory by its place in the target:
/// [`user_path`]).
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A file could not be read or written.
    #[error("{}: {source}", user_path(path).display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A CSV file is malformed (field count, a value that is not a finite number).
    #[error("{}: malformed CSV: {msg}", user_path(path).display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// What is wrong, with line and column where known.
        msg: String,
    },
    /// A JSON file does not parse.
    #[error("{}: malformed JSON: {source}", user_path(path).display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The parser's error.
        #[source]
        source: serde_json::Error,
    },
    /// A file parses but lacks what the figure needs (a required column, any data rows).
    #[error("{}: {what}", user_path(path).display())]
    Data {
        /// The file.
        path: PathBuf,
        /// What is missing.
        what: String,
    },
    /// Rendering a figure failed.
    #[error("{}: drawing failed: {msg}", user_path(path).display())]
    Draw {
        /// The figure's file.
        path: PathBuf,
        /// The drawing backend's error.
        msg: String,
    },
    /// The embedded font could not be registered.
    #[error("the embedded DejaVu Sans font could not be loaded")]
    Font,
}
