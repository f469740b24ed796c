//! The model file: serde schema, parsing with key paths, validation into a checked [`Gearbox`].
//!
//! `load` is the only place that reads a model file; everything below works on the checked
//! [`Gearbox`].

pub mod automatic;
pub mod catalogue;
pub mod gearbox;
pub mod losses;
pub mod parse;
pub mod problems;
pub mod schema;
pub mod source;
pub mod thermal;
pub mod validate;

use std::path::{Path, PathBuf};

pub use gearbox::Gearbox;
pub use problems::{Problem, Problems};

/// A model file that could not be read or did not validate.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// File path.
        file: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// Parse or validation problems (all of them).
    #[error("{file}: {n} problem(s)", n = problems.len())]
    Invalid {
        /// File path.
        file: PathBuf,
        /// Every problem found.
        problems: Vec<Problem>,
    },
}

impl ModelError {
    /// Human-readable list: one line per problem, prefixed by the file.
    pub fn report(&self) -> String {
        match self {
            ModelError::Io { .. } => self.to_string(),
            ModelError::Invalid { file, problems } => {
                let mut s = format!("{}: {} problem(s):\n", file.display(), problems.len());
                for p in problems {
                    s.push_str(&format!("  {}: {p}\n", file.display()));
                }
                s
            }
        }
    }
}

/// Parse and validate model text; `file` names it in messages.
pub fn from_str(text: &str, file: &Path) -> Result<Gearbox, ModelError> {
    let mut problems = Problems::default();
    let parsed = parse::parse_model(text, &mut problems);
    let gearbox = parsed.and_then(|f| validate::validate(&f, &mut problems));
    match gearbox {
        Some(g) if problems.is_empty() => Ok(g),
        _ => Err(ModelError::Invalid {
            file: file.to_path_buf(),
            problems: problems.into_vec(),
        }),
    }
}

/// Read, parse and validate a model file.
pub fn load(path: &Path) -> Result<Gearbox, ModelError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    from_str(&text, path)
}
