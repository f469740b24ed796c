//! `fmu`: export a model as an FMI 2.0 co-simulation FMU, and the model an FMU's runtime builds
//! from what the exporter embedded.
//!
//! The runtime library (the `geartherm-fmu` cdylib, `fmu/`) carries a fixed-size byte slot
//! ([`slot`]); the exporter writes the model into it as a [`Payload`] (the model text, its
//! overrides and the exported parameters' key paths), so the FMU reads no file at run time.
//! The runtime checks the payload again with the same functions ([`FmuModel::build`]) and
//! integrates with [`crate::solve::cosim::Stepper`] ([`instance`]).

pub mod description;
pub mod instance;
pub mod outputs;
pub mod slot;
pub mod variables;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::model::overrides;
use crate::model::{KeyPath, Override};
use crate::report::zip::stored_zip;
use crate::scene::{Needs, Scene};

use super::{JobError, Model};
pub use variables::{Causality, Role, Variable};

/// The FMI platform directory of the runtime library.
pub const PLATFORM: &str = "linux64";

/// The environment variable naming the runtime library (else the front ends look beside the
/// `geartherm` executable).
pub const RUNTIME_ENV: &str = "GEARTHERM_FMU_RUNTIME";

/// The runtime library's file name as cargo builds it.
pub const RUNTIME_FILE: &str = "libgeartherm_fmu.so";

/// What the exporter embeds in the runtime library.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Payload {
    /// The model file as named in messages.
    pub file: String,
    /// The model text.
    pub text: String,
    /// Overrides applied to it (`PATH = VALUE`, as `--set`).
    pub overrides: Vec<String>,
    /// Key paths exported as parameters (`--param`).
    pub params: Vec<String>,
}

/// An exported parameter: its key path and its value in the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// The key path.
    pub path: KeyPath,
    /// Its text as given.
    pub text: String,
    /// The model's value.
    pub value: f64,
    /// The model file holds an integer there.
    pub integer: bool,
}

/// The model of an FMU: checked, compiled for every gear state, with its variables.
pub struct FmuModel {
    /// What it was built from.
    pub payload: Payload,
    /// The checked model.
    pub model: Model,
    /// The compiled scene.
    pub scene: Scene,
    /// Exported parameters.
    pub params: Vec<Param>,
    /// Every variable.
    pub vars: Vec<Variable>,
}

/// The scene of an FMU: every gear state (the gear is an input), loss energy per item (as a run).
fn needs() -> Needs {
    Needs {
        states: None,
        evaluate_all: false,
        energy_per_source_only: false,
        ..Needs::default()
    }
}

fn parse_overrides(list: &[String]) -> Result<Vec<Override>, JobError> {
    list.iter()
        .map(|s| s.parse::<Override>().map_err(JobError::invalid))
        .collect()
}

impl FmuModel {
    /// Check the payload's model with its overrides, check every parameter key path (it must
    /// exist and hold a number), compile the scene.
    pub fn build(payload: Payload) -> Result<FmuModel, JobError> {
        let file = Path::new(&payload.file);
        let ovs = parse_overrides(&payload.overrides)?;
        let model = Model::from_text(&payload.text, file, &ovs)?;
        let params = check_params(&payload, &ovs)?;
        let scene = model.compile(&needs())?;
        let values: Vec<(String, f64)> = params.iter().map(|p| (p.text.clone(), p.value)).collect();
        let vars = variables::variables(&model.gearbox, &scene, &values);
        Ok(FmuModel {
            payload,
            model,
            scene,
            params,
            vars,
        })
    }

    /// The model and scene with the parameters set to `values` (checked as the model file is;
    /// an error names the key path).
    pub fn with_params(&self, values: &[f64]) -> Result<(Model, Scene), JobError> {
        let mut ovs = parse_overrides(&self.payload.overrides)?;
        for (p, v) in self.params.iter().zip(values) {
            let value = if p.integer {
                if v.fract() != 0.0 || !v.is_finite() {
                    return Err(JobError::invalid(format!(
                        "param.{} = {v}: the model file holds an integer there",
                        p.text
                    )));
                }
                toml::Value::Integer(*v as i64)
            } else {
                toml::Value::Float(*v)
            };
            ovs.push(Override {
                path: p.path.clone(),
                value,
            });
        }
        let model = Model::from_text(&self.payload.text, Path::new(&self.payload.file), &ovs)?;
        let scene = model.compile(&needs())?;
        if scene.n_states() != self.scene.n_states() || scene.thermal().names != self.scene.thermal().names {
            return Err(JobError::invalid(
                "the parameters change the model's structure (its nodes or loss items): not allowed in an FMU",
            ));
        }
        Ok((model, scene))
    }
}

/// Every parameter key path: parsed, present in the model (with its overrides) and a number.
fn check_params(payload: &Payload, ovs: &[Override]) -> Result<Vec<Param>, JobError> {
    let mut problems = Vec::new();
    let mut doc: toml::Table = payload
        .text
        .parse()
        .map_err(|e: toml::de::Error| JobError::invalid(format!("{}: {}", payload.file, e.message())))?;
    for ov in ovs {
        overrides::apply(&mut doc, ov).map_err(JobError::invalid)?;
    }
    let mut out = Vec::new();
    for text in &payload.params {
        let path: KeyPath = match text.parse() {
            Ok(p) => p,
            Err(e) => {
                problems.push(format!("parameter {text}: bad key path: {e}"));
                continue;
            }
        };
        match overrides::get(&doc, &path) {
            Ok(toml::Value::Float(v)) => out.push(Param {
                path,
                text: text.clone(),
                value: v,
                integer: false,
            }),
            Ok(toml::Value::Integer(v)) => out.push(Param {
                path,
                text: text.clone(),
                value: v as f64,
                integer: true,
            }),
            Ok(other) => problems.push(format!(
                "parameter {text}: holds {other}, not a number (only numbers can be FMU parameters)"
            )),
            Err(e) => problems.push(format!("parameter {text}: {e}")),
        }
    }
    if !problems.is_empty() {
        return Err(JobError::invalid(format!(
            "{}: {}",
            payload.file,
            problems.join("; ")
        )));
    }
    Ok(out)
}

/// Options of an export.
#[derive(Debug, Clone, PartialEq)]
pub struct FmuOptions {
    /// Key paths exported as parameters.
    pub params: Vec<String>,
    /// The FMU's model identifier (a C identifier: the runtime library's file name).
    pub model_identifier: String,
}

/// A C identifier from a file stem (`at6-lepelletier` → `at6_lepelletier`).
pub fn model_identifier(stem: &str) -> String {
    let mut id: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if id.is_empty() || id.starts_with(|c: char| c.is_ascii_digit()) {
        id.insert(0, '_');
    }
    id
}

/// A checked export: the model built and initialised once with its start values.
pub struct Export {
    fm: FmuModel,
    payload: Vec<u8>,
    id: String,
}

/// Check an export: the model `text` named `file` with `overrides` (`PATH = VALUE`) and the
/// options. Every failure is invalid input (exit 1): the model, a parameter key path, a model
/// larger than the slot, a model the FMU cannot integrate.
pub fn prepare(text: &str, file: &str, overrides: &[String], o: &FmuOptions) -> Result<Export, JobError> {
    if model_identifier(&o.model_identifier) != o.model_identifier {
        return Err(JobError::invalid(format!(
            "model identifier `{}`: not a C identifier",
            o.model_identifier
        )));
    }
    let payload = Payload {
        file: file.to_string(),
        text: text.to_string(),
        overrides: overrides.to_vec(),
        params: o.params.clone(),
    };
    let fm = FmuModel::build(payload.clone())?;
    instance::check_exportable(&fm)?;
    let bytes = serde_json::to_vec(&payload)
        .map_err(|e| JobError::invalid(format!("cannot serialise the model: {e}")))?;
    slot::check_fits(&bytes)?;
    Ok(Export {
        fm,
        payload: bytes,
        id: o.model_identifier.clone(),
    })
}

impl Export {
    /// The FMU's bytes (a zip: modelDescription.xml and the runtime library `runtime` with the
    /// model in its slot). A runtime library without a slot is an I/O error (exit 3).
    pub fn package(&self, runtime: &[u8]) -> Result<Vec<u8>, JobError> {
        let lib = slot::patch(runtime, &self.payload)?;
        let guid = slot::guid(&self.payload);
        let xml = description::model_description(&self.fm, &self.id, &guid);
        let lib_name = format!("binaries/{PLATFORM}/{}.so", self.id);
        Ok(stored_zip(&[
            ("modelDescription.xml", xml.as_bytes()),
            (&lib_name, &lib),
        ]))
    }

    /// Number of variables.
    pub fn variables(&self) -> usize {
        self.fm.vars.len()
    }
}
