//! The first steps of every job: read the model file, apply the overrides, check it. A
//! [`Model`] is a checked gearbox with the file it came from and the overrides it carries, so
//! that messages name the file and a case's stand-alone command line can be rendered.

use std::path::{Path, PathBuf};

use crate::model::{self, Gearbox, Override};
use crate::scene::{Needs, Scene};

use super::JobError;

/// A checked model: the gearbox, its file (as named in messages) and its overrides.
#[derive(Debug, Clone)]
pub struct Model {
    /// The checked gearbox.
    pub gearbox: Gearbox,
    /// The model file (or the name given to model text).
    pub file: PathBuf,
    /// The overrides applied, in order.
    pub overrides: Vec<Override>,
}

impl Model {
    /// Read `path`, apply `overrides` and check the result (every problem with its key path).
    pub fn load(path: &Path, overrides: &[Override]) -> Result<Model, JobError> {
        let gearbox = model::load_with(path, overrides)?;
        Ok(Model {
            gearbox,
            file: path.to_path_buf(),
            overrides: overrides.to_vec(),
        })
    }

    /// Check model text (`file` names it in messages) with `overrides`.
    pub fn from_text(text: &str, file: &Path, overrides: &[Override]) -> Result<Model, JobError> {
        let gearbox = model::from_str_with(text, file, overrides)?;
        Ok(Model {
            gearbox,
            file: file.to_path_buf(),
            overrides: overrides.to_vec(),
        })
    }

    /// Check an already parsed model document (`file` names it in messages) with `overrides`.
    pub fn from_document(doc: toml::Table, file: &Path, overrides: &[Override]) -> Result<Model, JobError> {
        let gearbox = model::from_document_with(doc, file, overrides)?;
        Ok(Model {
            gearbox,
            file: file.to_path_buf(),
            overrides: overrides.to_vec(),
        })
    }

    /// The file as shown in messages.
    pub fn label(&self) -> String {
        self.file.display().to_string()
    }

    /// The file's stem (default output directory names).
    pub fn stem(&self) -> String {
        self.file
            .file_stem()
            .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned())
    }

    /// Index of gear state `gear`, or an error listing the states the model has.
    pub fn state(&self, gear: &str) -> Result<usize, JobError> {
        self.gearbox.state_index(gear).ok_or_else(|| {
            let names: Vec<&str> = self.gearbox.gear_states.iter().map(|s| s.name.as_str()).collect();
            JobError::option(
                "gear",
                gear,
                names.join(", "),
                format!(
                    "gear (--gear) = {gear}: unknown gear state; {} has: {}",
                    self.label(),
                    names.join(", ")
                ),
            )
        })
    }

    /// Compile the scene for `needs`; a model the scene cannot use is invalid input.
    pub fn compile(&self, needs: &Needs) -> Result<Scene, JobError> {
        Scene::compile_for(&self.gearbox, needs)
            .map_err(|e| JobError::invalid(format!("{}: {e}", self.label())))
    }

    /// Set the ambient boundary to `ambient_c` (°C, already range-checked) when given.
    pub fn set_ambient(&self, scene: &mut Scene, ambient_c: Option<f64>) -> Result<(), JobError> {
        let Some(a) = ambient_c else {
            return Ok(());
        };
        let idx = scene.thermal.ambient.ok_or_else(|| {
            JobError::option(
                "ambient_c",
                a,
                "no value: the model has no ambient boundary",
                format!(
                    "ambient_c (--ambient-c) = {a}: {} has no ambient boundary (name one `ambient` or set ambient = true)",
                    self.label()
                ),
            )
        })?;
        scene
            .thermal
            .set_boundary_fixed(idx, a + crate::physics::oil::KELVIN_OFFSET);
        Ok(())
    }
}
