//! `geartherm._native`: the PyO3 binding of the geartherm library. It sits beside the CLI and
//! calls the same use-case layer (`geartherm::job`) and study runner (`geartherm::study`): every
//! option is checked there, once, for every front end. Results cross the boundary
//! as JSON or CSV text that the Python package (`pysrc/geartherm/`) turns into dicts and pandas
//! DataFrames. Every solve runs with the GIL released.

mod calibrate;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use geartherm::job::{
    self, ErrorKind, JobError, LossesOptions, MapOptions, RatingOptions, RunOptions, SteadyOptions,
};
use geartherm::model::Override;
use pyo3::prelude::*;
use serde::{Deserialize, Serialize};

mod study;
mod uq;
mod uq_dask;

/// The Python exception of a failure, built by `geartherm.errors._from_native` (the classes are
/// plain Python classes there, so they import from `geartherm` and pickle with their fields).
/// `kind`: `model`, `input`, `solve`, `io`, `not_found` or `error`; `problems`: (path, value,
/// allowed) triples.
pub(crate) fn py_error(
    kind: &str,
    message: String,
    problems: Vec<(String, String, String)>,
    file: Option<String>,
) -> PyErr {
    Python::attach(|py| {
        let build = || -> PyResult<PyErr> {
            let f = py.import("geartherm.errors")?.getattr("_from_native")?;
            let e = f.call1((kind, message.clone(), problems.clone(), file.clone()))?;
            Ok(PyErr::from_value(e))
        };
        build().unwrap_or_else(|e| e)
    })
}

/// A job's error as the Python exception of its kind: an invalid model or override is a
/// `ModelError`, another invalid input an `InputError` (both `ValueError`s, with `.path`,
/// `.value`, `.allowed` and `.problems`), a numerical failure a `SolveError`, a missing file
/// `FileNotFoundError`, other I/O `OSError`.
/// The exception class is chosen by the error's kind alone (one table, here); a file that
/// cannot be read and an invalid model name their file (`.filename`, `.file`).
pub(crate) fn job_error(e: JobError) -> PyErr {
    let problems: Vec<(String, String, String)> = e
        .problems
        .iter()
        .map(|p| (p.path.clone(), p.value.clone(), p.allowed.clone()))
        .collect();
    let kind = match e.kind {
        ErrorKind::Io if e.io_kind == Some(std::io::ErrorKind::NotFound) => "not_found",
        ErrorKind::Io => "io",
        ErrorKind::Numerical => "solve",
        ErrorKind::Model => "model",
        ErrorKind::Option | ErrorKind::Invalid => "input",
    };
    let file = match kind {
        "input" | "solve" => None,
        _ => e.file.map(|f| f.display().to_string()),
    };
    py_error(kind, e.message, problems, file)
}

fn input_error(message: String) -> PyErr {
    py_error("input", message, Vec::new(), None)
}

/// A trace's problem: an `InputError` whose fields come from its message (`FILE, line N: column
/// C = "V": what`).
fn trace_error(message: &str) -> PyErr {
    py_error("input", message.to_string(), Vec::new(), None)
}

pub(crate) fn json_error(what: &str, e: serde_json::Error) -> PyErr {
    input_error(format!("{what}: {e}"))
}

pub(crate) fn to_json<T: Serialize>(v: &T) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| py_error("error", e.to_string(), Vec::new(), None))
}

/// What a model is made of: its text, its file name (for messages) and the overrides applied.
/// Pickled as this state (serde JSON), so a model travels to other processes without files.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct State {
    text: String,
    file: String,
    overrides: Vec<String>,
}

/// A calibration for Python: (`calibration.json`, `fit.csv`, `calibrated.toml`, `cycle.csv`
/// texts, the CLI's files as (name, bytes)).
type Calibration = (String, String, String, String, Vec<(String, Vec<u8>)>);

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
    pythonize::depythonize(mapping).map_err(|e| input_error(format!("{what}: {e}")))
}

#[pymethods]
impl Model {
    /// Read and check a model file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Model> {
        let text = job::read_text(&path).map_err(job_error)?;
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

    /// The model's text with every override written in at its key path (comments and layout
    /// kept), which `Model.from_text` checks into an equal model.
    fn to_toml(&self) -> PyResult<String> {
        geartherm::job::calibrate::model_file::calibrated_text(&self.state.text, &self.m.overrides, &[])
            .map_err(|e| py_error("model", format!("{}: {e}", self.state.file), Vec::new(), None))
    }

    /// Two models are equal when their checked gearboxes are (every value, bit for bit),
    /// whatever text, file name and overrides made them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        match other.cast::<Model>() {
            Ok(o) => format!("{:?}", self.m.gearbox) == format!("{:?}", o.get().m.gearbox),
            Err(_) => false,
        }
    }

    /// Counts of the checked model (JSON), after the checks `geartherm check` makes (the
    /// model's `[uncertainty]` against the model).
    fn check(&self) -> PyResult<String> {
        job::Model::check_text(&self.state.text, &self.m.file, &self.m.overrides).map_err(job_error)?;
        to_json(&self.m.check_report())
    }

    /// The `geartherm info --json` report.
    fn info(&self) -> PyResult<String> {
        to_json(&geartherm::report::info::info(&self.m.gearbox))
    }

    /// The `geartherm losses --json` report (a mapping of `job::LossesOptions` in).
    fn losses(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: LossesOptions = self::options("losses", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| in_process_pool(|| job::losses::losses(&m, &o)))
            .map_err(job_error)?;
        to_json(&r)
    }

    /// An equilibrium (a mapping of `job::SteadyOptions` in, `job::SteadyResult` out).
    fn steady(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: SteadyOptions = self::options("steady", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| in_process_pool(|| job::steady::steady(&m, &o)))
            .map_err(job_error)?;
        to_json(&r)
    }

    /// Equilibria over a speed × torque grid (a mapping of `job::MapOptions` in): `map.csv` text.
    fn map(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: MapOptions = self::options("map", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| in_process_pool(|| job::map::map(&m, &o, &|| {})))
            .map_err(job_error)?;
        Ok(r.csv())
    }

    /// A thermal rating (a mapping of `job::RatingOptions` in): the `rating.json` document.
    fn rating(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<String> {
        let o: RatingOptions = self::options("rating", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| in_process_pool(|| job::rating::rating(&m, &o, &|| {})))
            .map_err(job_error)?;
        to_json(&r)
    }

    /// A drive-cycle run (a mapping of `job::RunOptions` in): (`summary.json` text, `timeseries.csv`
    /// text or None).
    fn run(&self, py: Python<'_>, options: &Bound<'_, PyAny>) -> PyResult<(String, Option<String>)> {
        let o: RunOptions = self::options("run", options)?;
        let m = self.m.clone();
        let r = py
            .detach(|| in_process_pool(|| job::run::run(&m, &o, &mut |_, _| {})))
            .map_err(job_error)?;
        Ok((to_json(&r.summary)?, r.timeseries_csv))
    }

    // --- calibrate -----------------------------------------------------------------------
    /// Calibrate against a trace given as CSV text (`trace_name` names it in messages; a
    /// mapping of `job::CalibrateOptions` in): a [`Calibration`].
    fn calibrate(
        &self,
        py: Python<'_>,
        trace_csv: &str,
        trace_name: &str,
        options: &Bound<'_, PyAny>,
    ) -> PyResult<Calibration> {
        let mut o: job::CalibrateOptions = self::options("calibrate", options)?;
        o.trace = trace_name.to_string();
        let file = job::calibrate::trace_file::read(trace_csv, trace_name, o.missing())
            .map_err(|e| trace_error(&e.to_string()))?;
        let trace = file.select(o.segment).map_err(|e| trace_error(&e.to_string()))?;
        let (m, text) = (self.m.clone(), self.state.text.clone());
        let r = py
            .detach(|| in_process_pool(|| job::calibrate::calibrate(&m, &text, trace, &o)))
            .map_err(job_error)?;
        let files = r.files().map_err(job_error)?;
        Ok((
            to_json(&r.summary)?,
            r.fit_csv,
            r.calibrated_model,
            r.cycle_csv,
            files,
        ))
    }
    /// Calibrate over several traces ((CSV text, name, file label) triples; a mapping of
    /// `job::CalibrateOptions`): a [`Calibration`]. With `evaluator` (θ → every segment's
    /// (residuals, Jacobian) in order) the segments are evaluated by it, on Dask workers.
    #[pyo3(signature = (traces, options, evaluator=None))]
    fn calibrate_traces(
        &self,
        py: Python<'_>,
        traces: Vec<calibrate::TraceText>,
        options: &Bound<'_, PyAny>,
        evaluator: Option<Py<PyAny>>,
    ) -> PyResult<Calibration> {
        let o: job::CalibrateOptions = self::options("calibrate", options)?;
        let files = calibrate::read_traces(&traces, &o)?;
        let (m, text) = (self.m.clone(), self.state.text.clone());
        let r = py
            .detach(|| {
                in_process_pool(|| calibrate::calibrate_traces(&m, &text, &files, &o, evaluator.as_ref()))
            })
            .map_err(job_error)?;
        let files = r.files().map_err(job_error)?;
        Ok((
            to_json(&r.summary)?,
            r.fit_csv,
            r.calibrated_model,
            r.cycle_csv,
            files,
        ))
    }

    /// The residuals and Jacobians of the segments `which` at θ (a Dask worker's share of
    /// [`Self::calibrate_traces`]): a list of (residuals, Jacobian row-major).
    fn evaluate_segments(
        &self,
        py: Python<'_>,
        traces: Vec<calibrate::TraceText>,
        options: &Bound<'_, PyAny>,
        theta: Vec<f64>,
        which: Vec<usize>,
    ) -> PyResult<Vec<(Vec<f64>, Vec<f64>)>> {
        let o: job::CalibrateOptions = self::options("calibrate", options)?;
        let files = calibrate::read_traces(&traces, &o)?;
        let (m, text) = (self.m.clone(), self.state.text.clone());
        py.detach(|| in_process_pool(|| calibrate::evaluate_segments(&m, &text, &files, &o, &theta, &which)))
            .map_err(job_error)
    }
    /// The number of segments a calibration over `traces` fits (the indices of
    /// [`Self::evaluate_segments`] run over 0 … this).
    fn segment_count(
        &self,
        traces: Vec<calibrate::TraceText>,
        options: &Bound<'_, PyAny>,
    ) -> PyResult<usize> {
        let o: job::CalibrateOptions = self::options("calibrate", options)?;
        let files = calibrate::read_traces(&traces, &o)?;
        let inputs = job::calibrate::stack::inputs(&files, &o).map_err(job_error)?;
        Ok(inputs.iter().map(|t| t.segments.len()).sum())
    }
    // --- end calibrate -------------------------------------------------------------------

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

/// This process's rayon pool. rayon's global pool does not survive a fork: a child forked (a
/// `multiprocessing` pool's default on Linux) from a process whose global pool had started
/// inherits a registry whose threads do not exist, and its first parallel call waits forever.
/// Every parallel call of the binding runs in this pool instead, built again in a forked child
/// (the parent's copy is leaked there: dropping it would signal threads that do not exist).
fn process_pool() -> Option<Arc<rayon::ThreadPool>> {
    static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);
    let pid = std::process::id();
    {
        let mut slot = POOL.lock().unwrap_or_else(|e| e.into_inner());
        match slot.take() {
            Some((p, pool)) if p == pid => {
                *slot = Some((p, pool.clone()));
                return Some(pool);
            }
            Some(inherited) => std::mem::forget(inherited),
            None => {}
        }
    }
    // Built without the lock held: a fork while its threads start must not leave the child a
    // locked mutex.
    let pool = Arc::new(rayon::ThreadPoolBuilder::new().build().ok()?);
    let mut slot = POOL.lock().unwrap_or_else(|e| e.into_inner());
    match &*slot {
        Some((p, other)) if *p == pid => Some(other.clone()),
        _ => {
            *slot = Some((pid, pool.clone()));
            Some(pool)
        }
    }
}

/// `work` in [`process_pool`] (on the calling thread when no pool can be built).
pub(crate) fn in_process_pool<T: Send>(work: impl FnOnce() -> T + Send) -> T {
    match process_pool() {
        Some(pool) => pool.install(work),
        None => work(),
    }
}

/// The oil catalogue as JSON (key, name, viscosities, density, base stock, sources).
#[pyfunction]
fn oils() -> PyResult<String> {
    let v: Vec<serde_json::Value> = geartherm::model::catalogue::oils()
        .into_iter()
        .map(|o| {
            serde_json::json!({
                "key": o.key,
                "name": o.name,
                "nu40_cst": o.nu40_cst,
                "nu100_cst": o.nu100_cst,
                "rho15_kg_m3": o.rho15_kg_m3,
                "thermal_expansion_per_k": o.thermal_expansion_per_k,
                "density_assumed": o.density_assumed,
                "base": o.base.map(|b| b.as_str()),
                "lubricant_factor": o.lubricant_factor,
                "source": o.source,
            })
        })
        .collect();
    to_json(&v)
}

/// The bundled drive cycles as JSON (name, duration, distance, top speed).
#[pyfunction]
fn cycles() -> PyResult<String> {
    let mut v = Vec::new();
    for name in geartherm::cycle::bundled_names() {
        let c = geartherm::cycle::DriveCycle::bundled(name).map_err(|e| job_error(e.into()))?;
        v.push(serde_json::json!({
            "name": name,
            "duration_s": c.duration(),
            "distance_km": c.distance() / 1e3,
            "max_speed_kmh": c.max_vehicle_speed() * 3.6,
            "segments": c.len(),
        }));
    }
    to_json(&v)
}

/// The loss sources in output order (the order of every per-source column and key).
#[pyfunction]
fn sources() -> Vec<&'static str> {
    geartherm::model::source::Source::ALL
        .iter()
        .map(|s| s.as_str())
        .collect()
}

/// Read trace text as `geartherm trace` does (`refuse`: empty cells are errors): (the summary
/// JSON, each segment's (offset s, CSV text)).
#[pyfunction]
fn read_trace(text: &str, name: &str, refuse: bool) -> PyResult<(String, Vec<(f64, String)>)> {
    let missing = if refuse {
        job::calibrate::Missing::Refuse
    } else {
        job::calibrate::Missing::Drop
    };
    let f = job::calibrate::trace_file::read(text, name, missing).map_err(|e| trace_error(&e.to_string()))?;
    let segs = f.segments.iter().map(|s| (s.offset_s, s.csv.clone())).collect();
    Ok((to_json(&f.summary())?, segs))
}

/// A run directory read with the writer's types (`summary.json` as `report::run::Summary`,
/// `timeseries.csv` as `report::timeseries::Timeseries`, keys and columns of earlier versions
/// under their present names): (the summary JSON, the time series' CSV text or None when the
/// directory has none).
#[pyfunction]
fn read_run(py: Python<'_>, dir: PathBuf) -> PyResult<(String, Option<String>)> {
    use geartherm::report::{plots::data::read_json, run::Summary, timeseries::Timeseries};
    py.detach(|| -> Result<(String, Option<String>), JobError> {
        let summary: Summary = read_json(&dir.join("summary.json"))?;
        let ts = dir.join("timeseries.csv");
        let csv = if ts.exists() {
            Some(Timeseries::read(&ts)?.to_csv())
        } else {
            None
        };
        let json = serde_json::to_string(&summary)
            .map_err(|e| JobError::numerical(format!("cannot serialise the summary: {e}")))?;
        Ok((json, csv))
    })
    .map_err(job_error)
}

/// Draw `calibration.png` into a directory holding a calibration's `fit.csv` (as the CLI does).
#[pyfunction]
fn render_calibration(py: Python<'_>, dir: PathBuf) -> PyResult<()> {
    py.detach(|| geartherm::report::plots::calibration::render_calibration(&dir))
        .map(|_| ())
        .map_err(|e| py_error("io", format!("calibration.png: {e}"), Vec::new(), None))
}

/// Version of the geartherm library this binding was built with.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

mod fmu;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_function(wrap_pyfunction!(fmu::export_fmu, m)?)?;
    study::register(m)?;
    uq::register(m)?;
    uq_dask::register(m)?;
    m.add_function(wrap_pyfunction!(oils, m)?)?;
    m.add_function(wrap_pyfunction!(cycles, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(read_trace, m)?)?;
    m.add_function(wrap_pyfunction!(read_run, m)?)?;
    m.add_function(wrap_pyfunction!(render_calibration, m)?)?;
    m.add_function(wrap_pyfunction!(sources, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::priors_from_file, m)?)?;
    Ok(())
}
