//! `Model.uq(client=...)`: an uncertainty study whose samples Dask workers solve. The driver
//! holds the runner's session ([`UqSession`]: the same selection, lock, journal and resume as
//! the study's Dask path, `StudySession`); each task checks the same use case from the shipped
//! model text and options and runs the runner on its batch of samples ([`uq_cases`], nothing
//! written there); the estimates are made once, on the driver, from every row.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use geartherm::report::study::CaseRow;
use geartherm::study::runner::{self, Session};
use geartherm::study::uq::output::{compact, outcome};
use geartherm::study::uq::run::{Uq, UqOptions};
use geartherm::study::Selection;
use pyo3::prelude::*;

use crate::study::{check_threads, in_pool};
use crate::{job_error, json_error, py_error, to_json};

fn load_uq(text: String, file: &str, options: &str) -> PyResult<Uq> {
    let o: UqOptions = serde_json::from_str(options).map_err(|e| json_error("uq options", e))?;
    Uq::new(text, PathBuf::from(file), o).map_err(job_error)
}

fn closed() -> PyErr {
    py_error("error", "the uq session is closed".into(), Vec::new(), None)
}

/// One Dask task: the samples at `cases` (positions) of the uncertainty study of `text` with
/// `options`, solved by the runner (nothing written); their rows (with their band series) as
/// JSON.
#[pyfunction]
#[pyo3(signature = (text, file, options, cases, threads = None))]
fn uq_cases(
    py: Python<'_>,
    text: String,
    file: &str,
    options: &str,
    cases: Vec<i128>,
    threads: Option<usize>,
) -> PyResult<String> {
    check_threads(threads)?;
    let uq = load_uq(text, file, options)?;
    let sel = Selection::new(Some(cases), None).map_err(job_error)?;
    let solved = py.detach(|| {
        in_pool(threads, || {
            runner::run(&uq.study, &sel, None, &AtomicBool::new(false), &|_| {})
        })
    });
    let (_, rows) = solved
        .map_err(|e| py_error("error", e, Vec::new(), None))?
        .map_err(job_error)?;
    to_json(&rows)
}

/// The driver's side of a Dask uncertainty study: the use case checked once, the runner's
/// session opened on `out` (its lock held until [`UqSession::finish`] or [`UqSession::close`]).
#[pyclass(module = "geartherm._native", frozen)]
struct UqSession {
    uq: Uq,
    out: Option<PathBuf>,
    session: Mutex<Option<Session>>,
    recorded: AtomicUsize,
}

#[pymethods]
impl UqSession {
    /// Check the study (every check of `Model.uq`) and open the runner's session.
    #[new]
    #[pyo3(signature = (text, file, options, out = None))]
    fn new(text: String, file: &str, options: &str, out: Option<PathBuf>) -> PyResult<UqSession> {
        let uq = load_uq(text, file, options)?;
        let session = Session::open(&uq.study, &Selection::All, out.as_deref()).map_err(job_error)?;
        Ok(UqSession {
            uq,
            out,
            session: Mutex::new(Some(session)),
            recorded: AtomicUsize::new(0),
        })
    }

    /// The positions of the samples still to solve (journaled ones are not), in order.
    fn todo(&self) -> PyResult<Vec<usize>> {
        let guard = self.session.lock().unwrap_or_else(|e| e.into_inner());
        let s = guard.as_ref().ok_or_else(closed)?;
        Ok(s.todo().iter().map(|c| c.index).collect())
    }

    /// Record rows solved by a task (its JSON array), each once; the number recorded so far.
    fn record(&self, rows: &str) -> PyResult<usize> {
        let rows: Vec<CaseRow> = serde_json::from_str(rows).map_err(|e| json_error("rows", e))?;
        let guard = self.session.lock().unwrap_or_else(|e| e.into_inner());
        let s = guard.as_ref().ok_or_else(closed)?;
        for r in rows {
            if s.record(r, &Vec::new()).map_err(job_error)? {
                self.recorded.fetch_add(1, Ordering::SeqCst);
            }
        }
        Ok(self.recorded.load(Ordering::SeqCst))
    }

    /// End the session and estimate: the texts `Model.uq` returns (`uq.json`, `bands.csv`,
    /// `study.csv`), the outputs written into `out` as the local path writes them.
    fn finish(&self, py: Python<'_>) -> PyResult<(String, String, String)> {
        let session = self.session.lock().unwrap_or_else(|e| e.into_inner()).take();
        let (_, rows) = session.ok_or_else(closed)?.finish();
        let o = py
            .detach(|| match &self.out {
                Some(dir) => compact(&self.uq, dir, false),
                None => outcome(&self.uq, rows),
            })
            .map_err(job_error)?;
        crate::uq::texts(&o)
    }

    /// Release the session (and the output directory's lock) without estimating.
    fn close(&self) {
        self.session.lock().unwrap_or_else(|e| e.into_inner()).take();
    }
}

/// Add the Dask side of `Model.uq` to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(uq_cases, m)?)?;
    m.add_class::<UqSession>()?;
    Ok(())
}
