//! `Model.to_fmu`: the FMU export of `geartherm fmu` (`geartherm::job::fmu`) for Python. The
//! runtime library is the `runtime` argument (the Python side passes the one the wheel carries,
//! `geartherm/_bin/libgeartherm_fmu.so`, unless the caller names another), else
//! `$GEARTHERM_FMU_RUNTIME`.

use std::path::{Path, PathBuf};

use geartherm::job::fmu::{self as job_fmu, FmuOptions};
use geartherm::job::JobError;
use geartherm::report::files::write_file_atomic;
use pyo3::prelude::*;

use super::{job_error, Model};

fn io(message: String, kind: std::io::ErrorKind) -> PyErr {
    job_error(JobError::io(message, kind))
}

/// Export `model` as an FMI 2.0 co-simulation FMU at `out` (`NAME.fmu`) with the key paths
/// `params` as parameters; returns the path written. Nothing is written on error.
#[pyfunction]
#[pyo3(signature = (model, out, params, runtime = None))]
pub fn export_fmu(
    py: Python<'_>,
    model: PyRef<'_, Model>,
    out: PathBuf,
    params: Vec<String>,
    runtime: Option<PathBuf>,
) -> PyResult<String> {
    let stem = out.file_stem().map(|s| s.to_string_lossy().into_owned());
    let Some(stem) = stem.filter(|_| out.extension().is_some_and(|e| e == "fmu")) else {
        return Err(job_error(JobError::invalid(format!(
            "{}: the FMU's file name must end in .fmu",
            out.display()
        ))));
    };
    let o = FmuOptions {
        params,
        model_identifier: job_fmu::model_identifier(&stem),
    };
    let state = model.state.clone();
    let export = py
        .detach(|| job_fmu::prepare(&state.text, &state.file, &state.overrides, &o))
        .map_err(job_error)?;
    let rt = runtime
        .or_else(|| std::env::var_os(job_fmu::RUNTIME_ENV).map(PathBuf::from))
        .ok_or_else(|| {
            io(
                format!(
                    "no FMU runtime library: pass runtime= or set {} to a {} (`cargo build --release` builds one in target/release/)",
                    job_fmu::RUNTIME_ENV,
                    job_fmu::RUNTIME_FILE
                ),
                std::io::ErrorKind::NotFound,
            )
        })?;
    let lib = std::fs::read(&rt).map_err(|e| {
        io(
            format!("{}: cannot read the FMU runtime library: {e}", rt.display()),
            e.kind(),
        )
    })?;
    let bytes = export.package(&lib).map_err(job_error)?;
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        let m = format!("{}: no such directory", dir.display());
        return Err(io(m, std::io::ErrorKind::NotFound));
    }
    write_file_atomic(&out, &bytes)
        .map_err(|e| io(format!("{}: cannot write: {e}", out.display()), e.kind()))?;
    Ok(out.display().to_string())
}
