//! The model file: serde schema, parsing with key paths, validation into a checked [`Gearbox`].
//!
//! `load` is the only place that reads a model file; everything below works on the checked
//! [`Gearbox`].
//!
//! Layout:
//! - [`sections`]: one file per model-file section (`[model]`, `[oil]`, `[[members]]`,
//!   `[[gears]]`, `[[meshes]]`, `[[planetary_sets]]`, `[[shift_elements]]`, `[[gear_states]]`,
//!   `[train]`, `[lubrication]`, `[losses]`, `[thermal]` (a folder, one file per sub-table:
//!   nodes, boundaries, links, coolers, heat, wall_mesh), `[vehicle]`, `[[clutch_packs]]`,
//!   `[pump]`, `[launch]`, `[[bearings]]`, `[[seals]]`, `[uncertainty]` (a folder: the
//!   uncertain inputs, their distributions and checks)), each holding the section's serde
//!   struct(s), its checks with their key paths, and the checked type it becomes;
//! - [`file`]: the whole file, one field per section; [`parse`]: TOML text → [`file::ModelFile`],
//!   every section's type errors with their full key paths; [`base`]: a base document read once
//!   and reused by variants that override a few key paths; [`validate`]: the order in which the
//!   sections are checked, → [`Gearbox`]; [`gearbox`]: the checked gearbox;
//! - [`choice`]: model choices (`churning = "changenet"`), enums read by name once with their
//!   section; [`problems`] (what a check reports), [`overrides`] (key-path overrides), [`source`]
//!   (the loss sources), [`catalogue`] and [`bearing_catalogue`] (the oils and bearings compiled
//!   in).
//!
//! The paths `model::thermal`, `model::wall_mesh`, `model::bearings`, `model::pump`,
//! `model::uncertainty` name the section modules, and `model::gearbox` every checked part type.

pub mod alternative;
pub mod base;
pub mod bearing_catalogue;
pub mod catalogue;
pub mod choice;
pub mod file;
pub mod gearbox;
pub mod overrides;
pub mod parse;
pub mod problems;
pub mod sections;
pub mod source;
pub mod validate;

pub use sections::thermal::wall_mesh;
pub use sections::{bearings, pump, thermal, uncertainty};

use std::path::{Path, PathBuf};

pub use base::{from_base_with, BaseDocument};
pub use gearbox::Gearbox;
pub use overrides::{KeyPath, Override};
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

/// Parse model text, apply `overrides` (key path = value) to the document, then deserialize and
/// validate it as if the values had been written in the file. A problem at (or inside, or above)
/// an overridden path names the override; a model made invalid by overrides lists them.
pub fn from_str_with(text: &str, file: &Path, overrides: &[Override]) -> Result<Gearbox, ModelError> {
    if overrides.is_empty() {
        return from_str(text, file);
    }
    let mut problems = Problems::default();
    let Some(doc) = parse::parse_document(text, &mut problems) else {
        return Err(ModelError::Invalid {
            file: file.to_path_buf(),
            problems: problems.into_vec(),
        });
    };
    from_document_with(doc, file, overrides)
}

/// As [`from_str_with`] on an already parsed document (a study parses its base model once and
/// gives each case a copy).
pub fn from_document_with(
    mut doc: toml::Table,
    file: &Path,
    overrides: &[Override],
) -> Result<Gearbox, ModelError> {
    let mut problems = Problems::default();
    let invalid = |problems: Problems| ModelError::Invalid {
        file: file.to_path_buf(),
        problems: problems.into_vec(),
    };
    let mut applied = Vec::with_capacity(overrides.len());
    for ov in overrides {
        match overrides::apply(&mut doc, ov) {
            Ok(canon) => applied.push((canon, ov.to_string())),
            Err(msg) => problems.push(ov.path.to_string(), &ov.value, msg),
        }
    }
    if !problems.is_empty() {
        return Err(invalid(problems));
    }
    let parsed = parse::parse_table(doc, &mut problems);
    let gearbox = parsed.and_then(|f| validate::validate(&f, &mut problems));
    match gearbox {
        Some(g) if problems.is_empty() => Ok(g),
        _ => Err(invalid(annotate(problems, &applied))),
    }
}

/// Whether the model schema takes `ov` on `doc`: the override finds its place (every table
/// and named entry on its path exists) and the document still has the schema's shape (no
/// unknown key, every value of its type). Values are not validated: a value out of its range
/// fits the schema. The problems when it does not.
pub fn schema_takes(mut doc: toml::Table, ov: &Override) -> Result<(), Vec<Problem>> {
    let mut problems = Problems::default();
    if let Err(msg) = overrides::apply(&mut doc, ov) {
        problems.push(ov.path.to_string(), &ov.value, msg);
        return Err(problems.into_vec());
    }
    match parse::parse_table(doc, &mut problems) {
        Some(_) if problems.is_empty() => Ok(()),
        _ => Err(problems.into_vec()),
    }
}

/// The `[uncertainty]` of a model document checked against the model ([`uncertainty::check`]:
/// key paths, log-normals on positive values, the values each distribution reaches); Ok when
/// the document has none. Its type errors are the model's own (reported by every parse).
pub fn check_uncertainty(doc: &toml::Table, file: &Path) -> Result<(), ModelError> {
    let Some(Ok(spec)) = doc
        .get("uncertainty")
        .map(|v| v.clone().try_into::<uncertainty::UncertaintySpec>())
    else {
        return Ok(());
    };
    uncertainty::check(&spec, doc, file)
        .map(|_| ())
        .map_err(|problems| ModelError::Invalid {
            file: file.to_path_buf(),
            problems,
        })
}

/// Name the override behind each problem it concerns; when none does, list every override.
fn annotate(problems: Problems, applied: &[(String, String)]) -> Problems {
    let mut list = problems.into_vec();
    let mut any = false;
    for p in &mut list {
        let by: Vec<&str> = applied
            .iter()
            .filter(|(canon, _)| overrides::concerns(&p.path, canon))
            .map(|(_, text)| text.as_str())
            .collect();
        if !by.is_empty() {
            any = true;
            p.allowed
                .push_str(&format!(" (set by override `{}`)", by.join("`, `")));
        }
    }
    if !any {
        let all: Vec<&str> = applied.iter().map(|(_, t)| t.as_str()).collect();
        for p in &mut list {
            p.allowed
                .push_str(&format!(" (with overrides `{}`)", all.join("`, `")));
        }
    }
    let mut out = Problems::default();
    for p in list {
        out.push(p.path, p.value, p.allowed);
    }
    out
}

/// Read a model file and apply overrides (see [`from_str_with`]).
pub fn load_with(path: &Path, overrides: &[Override]) -> Result<Gearbox, ModelError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    from_str_with(&text, path, overrides)
}

/// Read, parse and validate a model file.
pub fn load(path: &Path) -> Result<Gearbox, ModelError> {
    let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    from_str(&text, path)
}
