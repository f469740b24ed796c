//! Uncertainty studies for Python (`Model.uq`): the options as JSON into the use case
//! (`geartherm::study::uq::run::Uq`, every check there), its cases solved by the study runner
//! (journal and resume with `out`), the estimates returned as `uq.json` text and `bands.csv` text.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use geartherm::report::uq::write_bands_csv;
use geartherm::study::runner;
use geartherm::study::uq::output::{compact, outcome};
use geartherm::study::uq::run::{Uq, UqOptions};
use geartherm::study::Selection;
use pyo3::prelude::*;

use crate::{in_process_pool, job_error, json_error, py_error};

/// Run an uncertainty study of the model `text` (file name `file` for messages) with `options`
/// (JSON of `UqOptions`); with `out`, journaled there (resume) and the outputs written. Returns
/// (`uq.json` text, `bands.csv` text or "", `study.csv` text).
#[pyfunction]
#[pyo3(signature = (text, file, options, out = None, threads = None))]
fn run_uq(
    py: Python<'_>,
    text: String,
    file: &str,
    options: &str,
    out: Option<PathBuf>,
    threads: Option<usize>,
) -> PyResult<(String, String, String)> {
    let o: UqOptions = serde_json::from_str(options).map_err(|e| json_error("uq options", e))?;
    if let Some(n) = threads {
        geartherm::job::limits::THREADS
            .check(n as f64)
            .map_err(job_error)?;
    }
    let uq = Uq::new(text, PathBuf::from(file), o).map_err(job_error)?;
    let cancel = AtomicBool::new(false);
    let work = || -> Result<_, geartherm::job::JobError> {
        let (_, rows) = runner::run(&uq.study, &Selection::All, out.as_deref(), &cancel, &|_| {})?;
        match &out {
            Some(dir) => compact(&uq, dir, false),
            None => outcome(&uq, rows),
        }
    };
    let result = py.detach(|| match threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build()
            .map_err(|e| e.to_string())
            .map(|p| p.install(work)),
        None => Ok(in_process_pool(work)),
    });
    let o = result
        .map_err(|e| py_error("io", e, Vec::new(), None))?
        .map_err(job_error)?;
    texts(&o)
}

/// The texts `Model.uq` reads: (`uq.json`, `bands.csv` or "", `study.csv`).
pub(crate) fn texts(o: &geartherm::study::uq::output::UqOutcome) -> PyResult<(String, String, String)> {
    let summary = o
        .summary
        .to_json()
        .map_err(|e| py_error("numerical", e, Vec::new(), None))?;
    let bands = match &o.bands {
        Some(b) => write_bands_csv(b).map_err(|e| py_error("numerical", e, Vec::new(), None))?,
        None => String::new(),
    };
    let csv = geartherm::report::study::study_csv(&o.table)
        .map_err(|e| py_error("io", format!("study.csv: {e}"), Vec::new(), None))?;
    Ok((summary, bands, String::from_utf8_lossy(&csv).into_owned()))
}

/// Add the uq function to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_uq, m)?)?;
    Ok(())
}
