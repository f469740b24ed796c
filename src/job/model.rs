//! The first steps of every job: read the model file, apply the overrides, check it. A
//! [`Model`] is a checked gearbox with the file it came from and the overrides it carries, so
//! that messages name the file and a case's stand-alone command line can be rendered.

use std::path::{Path, PathBuf};

use crate::model::{self, Gearbox, Override};
use crate::physics::units::c_to_k;
use crate::scene::{Needs, Scene};

use super::JobError;

/// What `check` reports of a checked model (the CLI prints it as one line, Python returns it
/// as a dict).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CheckReport {
    /// The model's name.
    pub model: String,
    /// Number of gears.
    pub gears: usize,
    /// Number of meshes.
    pub meshes: usize,
    /// The gear states' names.
    pub gear_states: Vec<String>,
    /// Number of thermal nodes.
    pub thermal_nodes: usize,
    /// Whether the model has a vehicle.
    pub vehicle: bool,
}

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

    /// What `check` runs: [`Model::load`], then the file's `[uncertainty]` (with the
    /// overrides applied) checked against the model: every key path exists, every distribution
    /// reaches only values the model accepts (the checks `uq` makes before any case runs).
    /// When the model without its `[uncertainty]` is valid, every problem of the section is
    /// reported at once (those that need no model and those that do).
    pub fn check_file(path: &Path, overrides: &[Override]) -> Result<Model, JobError> {
        let loaded = Model::load(path, overrides);
        if matches!(&loaded, Err(e) if e.kind != super::ErrorKind::Model) {
            return loaded;
        }
        let Ok(text) = super::read_text(path) else {
            return loaded;
        };
        with_uncertainty_checked(&text, path, overrides, loaded)
    }

    /// [`Model::check_file`] for model text (`file` names it in messages): what Python's
    /// `Model.check()` runs.
    pub fn check_text(text: &str, file: &Path, overrides: &[Override]) -> Result<Model, JobError> {
        let loaded = Model::from_text(text, file, overrides);
        if matches!(&loaded, Err(e) if e.kind != super::ErrorKind::Model) {
            return loaded;
        }
        with_uncertainty_checked(text, file, overrides, loaded)
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

    /// Check a variant of a base document read once (`file` names it in messages) with
    /// `overrides`: the same as [`Model::from_document`] on a copy of the base's document.
    pub fn from_base(
        base: &model::BaseDocument,
        file: &Path,
        overrides: &[Override],
    ) -> Result<Model, JobError> {
        let gearbox = model::from_base_with(base, file, overrides)?;
        Ok(Model {
            gearbox,
            file: file.to_path_buf(),
            overrides: overrides.to_vec(),
        })
    }

    /// What `check` reports: the counts of the checked model.
    pub fn check_report(&self) -> CheckReport {
        let gb = &self.gearbox;
        CheckReport {
            model: gb.name.clone(),
            gears: gb.gears.len(),
            meshes: gb.meshes.len(),
            gear_states: gb.gear_states.iter().map(|s| s.name.clone()).collect(),
            thermal_nodes: gb.thermal.as_ref().map_or(0, |t| t.nodes.len()),
            vehicle: gb.vehicle.is_some(),
        }
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
                    "gear = {gear}: unknown gear state; {} has: {}",
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

    /// The scenario's ambient in K for [`Needs::ambient_k`] (`ambient_c`, °C, already
    /// range-checked); a model whose network has no ambient boundary is refused.
    pub fn ambient_k(&self, ambient_c: Option<f64>) -> Result<Option<f64>, JobError> {
        let Some(a) = ambient_c else {
            return Ok(None);
        };
        // A model without a network: the compile names that.
        let Some(net) = &self.gearbox.thermal else {
            return Ok(Some(c_to_k(a)));
        };
        net.ambient().map(|_| Some(c_to_k(a))).ok_or_else(|| {
            JobError::option(
                "ambient_c",
                a,
                "no value: the model has no ambient boundary",
                format!(
                    "ambient_c = {a}: {} has no ambient boundary (name one `ambient` or set ambient = true)",
                    self.label()
                ),
            )
        })
    }
}

/// `loaded` (the model checked without its `[uncertainty]` against the model), then the file's
/// `[uncertainty]` with the overrides applied checked against the model; every problem of the
/// section at once when the model without it is valid.
fn with_uncertainty_checked(
    text: &str,
    path: &Path,
    overrides: &[Override],
    loaded: Result<Model, JobError>,
) -> Result<Model, JobError> {
    let mut problems = model::Problems::default();
    let Some(mut doc) = model::parse::parse_document(text, &mut problems) else {
        return loaded;
    };
    if overrides
        .iter()
        .any(|ov| model::overrides::apply(&mut doc, ov).is_err())
    {
        return loaded;
    }
    let mut without = doc.clone();
    if without.remove("uncertainty").is_none() {
        return loaded;
    }
    // The probes need the model itself valid.
    if loaded.is_err() && model::from_document_with(without, path, &[]).is_err() {
        return loaded;
    }
    model::check_uncertainty(&doc, path)?;
    loaded
}
