//! `geartherm._native`: the PyO3 binding of the geartherm library. It sits beside the CLI and
//! calls the same use-case layer (`geartherm::job`) and study runner (`geartherm::study`): every
//! option is checked there, once, for every front end. Results cross the boundary
//! as JSON or CSV text that the Python package (`pysrc/geartherm/`) turns into dicts and pandas
//! DataFrames. Every solve runs with the GIL released.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use geartherm::job::{
    self, ErrorKind, JobError, LossesOptions, MapOptions, RatingOptions, RunOptions, SteadyOptions,
};
use geartherm::model::Override;
use geartherm::study::spec::StudySpec;
use geartherm::study::{CaseRow, Study, StudyError};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyFileNotFoundError, PyOSError};
use pyo3::prelude::*;
use serde::{Deserialize, Serialize};

create_exception!(
    _native,
    GearthermError,
    PyException,
    "Base class of geartherm errors."
);
create_exception!(
    _native,
    ModelError,
    GearthermError,
    "An invalid model (or override): `.problems` lists (path, value, allowed); `.path` is the first key path."
);
create_exception!(
    _native,
    InputError,
    GearthermError,
    "An invalid argument: unknown cycle or gear, value out of range."
);
create_exception!(
    _native,
    SolveError,
    GearthermError,
    "A numerical failure (the message names time, node or loss item)."
);

/// A job's error as the Python exception of its kind: an invalid model or override is a
/// `ModelError` (`.problems`, `.path`), another invalid input an `InputError` (with `.path`,
/// `.value`, `.allowed` of the option), a numerical failure a `SolveError`, a missing file
/// `FileNotFoundError`, other I/O `OSError`.
fn job_error(e: JobError) -> PyErr {
    let problems: Vec<(String, String, String)> = e
        .problems
        .iter()
        .map(|p| (p.path.clone(), p.value.clone(), p.allowed.clone()))
        .collect();
    let err = match e.kind {
        ErrorKind::Io if e.io_kind == Some(std::io::ErrorKind::NotFound) => {
            return PyFileNotFoundError::new_err(e.message)
        }
        ErrorKind::Io => return PyOSError::new_err(e.message),
        ErrorKind::Numerical => return SolveError::new_err(e.message),
        ErrorKind::Model => ModelError::new_err(e.message),
        ErrorKind::Option | ErrorKind::Invalid => InputError::new_err(e.message),
    };
    let first = problems.first().cloned();
    Python::attach(|py| {
        let v = err.value(py);
        let _ = v.setattr("problems", problems);
        let _ = v.setattr("path", first.as_ref().map(|p| p.0.clone()));
        let _ = v.setattr("value", first.as_ref().map(|p| p.1.clone()));
        let _ = v.setattr("allowed", first.as_ref().map(|p| p.2.clone()));
    });
    err
}

fn study_error(e: StudyError) -> PyErr {
    match e {
        StudyError::Io { ref source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(e.to_string())
        }
        StudyError::Io { .. } => PyOSError::new_err(e.to_string()),
        StudyError::Invalid(m) => InputError::new_err(m),
        StudyError::Job(j) => job_error(j),
    }
}

fn json_error(what: &str, e: serde_json::Error) -> PyErr {
    InputError::new_err(format!("{what}: {e}"))
}

fn to_json<T: Serialize>(v: &T) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| GearthermError::new_err(e.to_string()))
}

/// What a model is made of: its text, its file name (for messages) and the overrides applied.
/// Pickled as this state (serde JSON), so a model travels to other processes without files.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct State {
    text: String,
    file: String,
    overrides: Vec<String>,
}

/// A checked gearbox model.
#[pyclass(module = "geartherm._native", frozen)]
struct Model {
    state: State,
    m: Arc<job::Model>,
}

fn build(state: State) -> PyResult<Model> {
    let file = PathBuf::from(&state.file);
    let mut ovs = Vec::with_capacity(state.overrides.len());
    for s in &state.overrides {
        let o: Override = s.parse().map_err(|msg: String| {
            let path = s.split('=').next().unwrap_or("").trim().to_string();
            job_error(JobError {
                kind: ErrorKind::Model,
                problems: vec![geartherm::model::Problem {
                    path,
                    value: s.clone(),
                    allowed: msg.clone(),
                }],
                ..JobError::invalid(msg)
            })
        })?;
        ovs.push(o);
    }
    let m = job::Model::from_text(&state.text, &file, &ovs).map_err(job_error)?;
    Ok(Model {
        state,
        m: Arc::new(m),
    })
}

/// A job's options from a Python mapping (floats pass as they are, NaN and infinities
/// included, so that the job layer checks them as it does for the CLI).
fn options<T: serde::de::DeserializeOwned>(what: &str, mapping: &Bound<'_, PyAny>) -> PyResult<T> {
    pythonize::depythonize(mapping).map_err(|e| InputError::new_err(format!("{what}: {e}")))
}

#[pymethods]
impl Model {
    /// Read and check a model file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Model> {
        let text = std::fs::read_to_string(&path).map_err(|e| {
            let msg = format!("{}: cannot read: {e}", path.display());
            match e.kind() {
                std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(msg),
                _ => PyOSError::new_err(msg),
            }
        })?;
        build(State {
            text,
            file: path.display().to_string(),
            overrides: Vec::new(),
        })
    }

    /// Check model text (`file` names it in messages).
    #[staticmethod]
    #[pyo3(signature = (text, file = "model.toml"))]
    fn from_text(text: String, file: &str) -> PyResult<Model> {
        build(State {
            text,
            file: file.to_string(),
            overrides: Vec::new(),
        })
    }

    /// A new model with more overrides (`"path = toml value"` each), checked like the file.
    fn with_overrides(&self, overrides: Vec<String>) -> PyResult<Model> {
        let mut state = self.state.clone();
        state.overrides.extend(overrides);
        build(state)
    }

    #[getter]
    fn text(&self) -> &str {
        &self.state.text
    }

    #[getter]
    fn file(&self) -> &str {
        &self.state.file
    }

    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.state.overrides.clone()
    }

    #[getter]
    fn name(&self) -> &str {
        &self.m.gearbox.name
    }

    /// Counts of the checked model (JSON).
    fn check(&self) -> PyResult<String> {
        let gb = &self.m.gearbox;
        to_json(&serde_json::json!({
            "model": gb.name,
            "gears": gb.gears.len(),
            "meshes": gb.meshes.len(),
            "gear_states": gb.gear_states.iter().map(|s| s.name.clone()).collect::<Vec<_>>(),
            "thermal_nodes": gb.thermal.as_ref().map_or(0, |t| t.nodes.len()),
            "vehicle": gb.vehicle.is_some(),
        }))
    }

    /// The `geartherm info --json` report.
    fn info(&self) -> PyResult<String> {
        to_json(&geartherm::report::info::info(&self.m.gearbox))
    }

    /// The `geartherm losses --json` report (a mapping of `job::LossesOptions` in).
    fn losses(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: LossesOptions = self::options("losses", options)?;
        let m = self.m.clone();
        let r = py.detach(|| job::losses::losses(&m, &o)).map_err(job_error)?;
        to_json(&r)
    }

    /// An equilibrium (a mapping of `job::SteadyOptions` in, `job::SteadyResult` out).
    fn steady(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: SteadyOptions = self::options("steady", options)?;
        let m = self.m.clone();
        let r = py.detach(|| job::steady::steady(&m, &o)).map_err(job_error)?;
        to_json(&r)
    }

    /// Equilibria over a speed × torque grid (a mapping of `job::MapOptions` in): `map.csv` text.
    fn map(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: MapOptions = self::options("map", options)?;
        let m = self.m.clone();
        let r = py.detach(|| job::map::map(&m, &o, &|| {})).map_err(job_error)?;
        Ok(r.csv)
    }

    /// A thermal rating (a mapping of `job::RatingOptions` in): the `rating.json` document.
    fn rating(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: RatingOptions = self::options("rating", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| job::rating::rating(&m, &o, &|| {}))
            .map_err(job_error)?;
        to_json(&r)
    }

    /// A drive-cycle run (a mapping of `job::RunOptions` in): (`summary.json` text, `timeseries.csv`
    /// text or None).
    fn run(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<(String, Option<String>)> {
        let o: RunOptions = self::options("run", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| job::run::run(&m, &o, &mut |_, _| {}))
            .map_err(job_error)?;
        Ok((to_json(&r.summary)?, r.timeseries_csv))
    }

    /// Pickle support: rebuilt from its state (text, file name, overrides) as JSON.
    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(Py<PyAny>, (String,))> {
        let restore = slf.get_type().getattr("_from_state")?.unbind();
        Ok((restore, (to_json(&slf.get().state)?,)))
    }

    #[staticmethod]
    fn _from_state(state: &str) -> PyResult<Model> {
        let s: State = serde_json::from_str(state).map_err(|e| json_error("model state", e))?;
        build(s)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({:?} from {:?}, {} override(s))",
            self.m.gearbox.name,
            self.state.file,
            self.state.overrides.len()
        )
    }
}

fn load_study(spec: &str, text: String, file: &str) -> PyResult<Study> {
    let spec: StudySpec = serde_json::from_str(spec).map_err(|e| json_error("study", e))?;
    Study::new(spec, text, PathBuf::from(file)).map_err(study_error)
}

/// Plan a study: (fingerprint, case ids in order).
#[pyfunction]
fn study_cases(spec: &str, text: String, file: &str) -> PyResult<(String, Vec<String>)> {
    let s = load_study(spec, text, file)?;
    let ids = s.cases().iter().map(|c| s.case_id(c)).collect();
    Ok((s.fingerprint.clone(), ids))
}

/// Solve the cases at `indices` (positions in the study's case list) in parallel, GIL released;
/// `threads` bounds the threads (default: all cores). Returns the rows as a JSON array, in the
/// order of `indices`.
#[pyfunction]
#[pyo3(signature = (spec, text, file, indices, threads = None))]
fn run_cases(
    py: Python<'_>,
    spec: &str,
    text: String,
    file: &str,
    indices: Vec<usize>,
    threads: Option<usize>,
) -> PyResult<String> {
    if let Some(n) = threads {
        geartherm::job::limits::THREADS
            .check(n as f64)
            .map_err(job_error)?;
    }
    let s = load_study(spec, text, file)?;
    let all = s.cases();
    let mut cases = Vec::with_capacity(indices.len());
    for &i in &indices {
        cases.push(*all.get(i).ok_or_else(|| {
            InputError::new_err(format!("case index {i}: the study has {} cases", all.len()))
        })?);
    }
    let rows = py.detach(|| -> Result<Vec<CaseRow>, String> {
        let done: Mutex<Vec<(usize, CaseRow)>> = Mutex::new(Vec::with_capacity(cases.len()));
        let position: HashMap<String, usize> =
            cases.iter().enumerate().map(|(k, c)| (s.case_id(c), k)).collect();
        let work = || {
            s.run(&cases, false, &|row, _| {
                let k = position.get(&row.case).copied().unwrap_or(usize::MAX);
                done.lock().unwrap_or_else(|e| e.into_inner()).push((k, row));
            })
        };
        match threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| e.to_string())?
                .install(work),
            None => work(),
        }
        let mut v = done.into_inner().unwrap_or_else(|e| e.into_inner());
        v.sort_by_key(|(k, _)| *k);
        Ok(v.into_iter().map(|(_, r)| r).collect())
    });
    to_json(&rows.map_err(GearthermError::new_err)?)
}

/// The equivalent `geartherm` command line of every case (for job arrays without Python).
#[pyfunction]
fn study_commands(spec: &str, text: String, file: &str) -> PyResult<Vec<String>> {
    let s = load_study(spec, text, file)?;
    Ok(s.cases().iter().map(|c| s.command_line(c)).collect())
}

/// Version of the geartherm library this binding was built with.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Model>()?;
    m.add_function(wrap_pyfunction!(study_cases, m)?)?;
    m.add_function(wrap_pyfunction!(run_cases, m)?)?;
    m.add_function(wrap_pyfunction!(study_commands, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("GearthermError", py.get_type::<GearthermError>())?;
    m.add("ModelError", py.get_type::<ModelError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    Ok(())
}
