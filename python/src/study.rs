//! Design studies for Python: the study runner of the library (`geartherm::study::runner`:
//! case selection, journal, resume, compaction) for a local run ([`run_study`]), for one Dask
//! task ([`run_cases`]: a selection solved by the runner, nothing written) and for the Dask
//! driver ([`StudySession`]: the same runner session, whose cases remote workers solve).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use geartherm::report::study::{study_csv, CaseRow, Table};
use geartherm::study::runner::{self, Session, Tally};
use geartherm::study::spec::StudySpec;
use geartherm::study::{Selection, Study};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{in_process_pool, job_error, json_error, py_error, to_json};

fn load_study(spec: &str, text: String, file: &str) -> PyResult<Study> {
    let spec: StudySpec = serde_json::from_str(spec).map_err(|e| json_error("study", e))?;
    Study::new(spec, text, PathBuf::from(file)).map_err(job_error)
}

/// The selection of the front-end forms (`cases=`, `shard=`), checked by the study layer.
fn selection(cases: Option<Vec<i128>>, shard: Option<(i128, i128)>) -> PyResult<Selection> {
    Selection::new(cases, shard).map_err(job_error)
}

/// Read a study file: (the study as JSON, the base model's text, its file name).
#[pyfunction]
fn study_file(path: PathBuf) -> PyResult<(String, String, String)> {
    let s = Study::from_file(&path).map_err(job_error)?;
    Ok((
        to_json(&s.spec)?,
        s.model_text.clone(),
        s.model_file.display().to_string(),
    ))
}

/// Plan a study: (fingerprint, case ids in order, output columns).
#[pyfunction]
fn study_cases(spec: &str, text: String, file: &str) -> PyResult<(String, Vec<String>, Vec<String>)> {
    let s = load_study(spec, text, file)?;
    let ids = s.cases().iter().map(|c| s.case_id(c)).collect();
    Ok((s.fingerprint.clone(), ids, s.outputs.clone()))
}

/// The case indices of a selection (`cases`: positions, `shard`: (i, n)), checked as the CLI's
/// `--cases` and `--shard` are.
#[pyfunction]
#[pyo3(signature = (spec, text, file, cases = None, shard = None))]
fn study_select(
    spec: &str,
    text: String,
    file: &str,
    cases: Option<Vec<i128>>,
    shard: Option<(i128, i128)>,
) -> PyResult<Vec<usize>> {
    let s = load_study(spec, text, file)?;
    let picked = s.select(&selection(cases, shard)?).map_err(job_error)?;
    Ok(picked.iter().map(|c| c.index).collect())
}

/// `threads` held to [`geartherm::job::limits::THREADS`] before any pool is built.
pub(crate) fn check_threads(threads: Option<usize>) -> PyResult<()> {
    match threads {
        Some(n) => geartherm::job::limits::THREADS
            .check(n as f64)
            .map(|_| ())
            .map_err(job_error),
        None => Ok(()),
    }
}

pub(crate) fn in_pool<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> Result<T, String> {
    match threads {
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build()
            .map_err(|e| e.to_string())?
            .install(work)),
        None => Ok(in_process_pool(work)),
    }
}

fn csv_text(table: &Table) -> PyResult<String> {
    let csv = study_csv(table).map_err(|e| py_error("io", format!("study.csv: {e}"), Vec::new(), None))?;
    Ok(String::from_utf8_lossy(&csv).into_owned())
}

fn tally_dict(py: Python<'_>, tally: &Tally) -> PyResult<Py<PyDict>> {
    let t = PyDict::new(py);
    t.set_item("cases", tally.cases)?;
    t.set_item("already_done", tally.already_done)?;
    t.set_item("solved", tally.solved)?;
    t.set_item("wall_s", tally.wall_s)?;
    t.set_item("threads", tally.threads)?;
    t.set_item("cancelled", tally.cancelled)?;
    Ok(t.unbind())
}

/// The table a run returns: with `out`, the compacted table (`compact`: study.csv,
/// study.parquet and the figures written) or the journaled one; without, the rows solved.
fn result_table(
    py: Python<'_>,
    s: &Study,
    out: Option<&PathBuf>,
    compact: bool,
    rows: Vec<CaseRow>,
) -> PyResult<Table> {
    match (out, compact) {
        (Some(dir), true) => Ok(py.detach(|| runner::compact(s, dir)).map_err(job_error)?.table),
        (Some(dir), false) => runner::journaled(s, dir).map_err(job_error),
        (None, _) => Ok(runner::table(s, rows)),
    }
}

/// Solve a selection of cases (`cases`: positions in the study's case list) with the runner,
/// nothing written, GIL released; `threads` bounds the threads (default: all cores). Returns the
/// rows as a JSON array in case order (a Dask task's work).
#[pyfunction]
#[pyo3(signature = (spec, text, file, cases, threads = None))]
fn run_cases(
    py: Python<'_>,
    spec: &str,
    text: String,
    file: &str,
    cases: Vec<i128>,
    threads: Option<usize>,
) -> PyResult<String> {
    check_threads(threads)?;
    let s = load_study(spec, text, file)?;
    let sel = selection(Some(cases), None)?;
    let solved = py.detach(|| {
        in_pool(threads, || {
            runner::run(&s, &sel, None, &AtomicBool::new(false), &|_| {})
        })
    });
    let (_, rows) = solved
        .map_err(|e| py_error("error", e, Vec::new(), None))?
        .map_err(job_error)?;
    to_json(&runner::table(&s, rows).rows)
}

/// Run a study with the library's runner (as `geartherm study`): with `out`, resume from its
/// journals, journal every case, and (`compact`, not for a shard) write study.csv,
/// study.parquet and the figures at the end. `progress(done, total)` is called from this
/// thread about ten times a second while the cases run (GIL released in between); a signal
/// handler that raises (Ctrl-C: `KeyboardInterrupt`) stops the study cleanly: no new case
/// starts, the running ones finish and are journaled, then the exception propagates. Returns
/// (the `study.csv` text of every case done, a tally dict).
#[pyfunction]
#[pyo3(signature = (spec, text, file, out = None, shard = None, cases = None, threads = None, progress = None, compact = true))]
#[allow(clippy::too_many_arguments)]
fn run_study(
    py: Python<'_>,
    spec: &str,
    text: String,
    file: &str,
    out: Option<PathBuf>,
    shard: Option<(i128, i128)>,
    cases: Option<Vec<i128>>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    compact: bool,
) -> PyResult<(String, Py<PyDict>)> {
    check_threads(threads)?;
    let s = load_study(spec, text, file)?;
    let sel = selection(cases, shard)?;
    let total = s.select(&sel).map_err(job_error)?.len();
    let cancel = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let mut interrupt: Option<PyErr> = None;
    let result = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            in_pool(threads, || {
                runner::run(&s, &sel, out.as_deref(), &cancel, &|_| {
                    done.fetch_add(1, Ordering::SeqCst);
                })
            })
        });
        loop {
            let finished = py.detach(|| {
                for _ in 0..10 {
                    if worker.is_finished() {
                        return true;
                    }
                    std::thread::sleep(Duration::from_millis(10));
                }
                worker.is_finished()
            });
            if let Some(p) = &progress {
                if let Err(e) = p.call1(py, (done.load(Ordering::SeqCst), total)) {
                    interrupt.get_or_insert(e);
                    cancel.store(true, Ordering::SeqCst);
                }
            }
            if let Err(e) = py.check_signals() {
                interrupt.get_or_insert(e);
                cancel.store(true, Ordering::SeqCst);
            }
            if finished {
                break;
            }
        }
        worker.join()
    });
    let result = result.map_err(|_| py_error("error", "study runner panicked".into(), Vec::new(), None))?;
    let (tally, rows) = result
        .map_err(|e| py_error("error", e, Vec::new(), None))?
        .map_err(job_error)?;
    if let Some(e) = interrupt {
        return Err(e);
    }
    let table = result_table(
        py,
        &s,
        out.as_ref(),
        compact && sel.journal_shard().is_none(),
        rows,
    )?;
    Ok((csv_text(&table)?, tally_dict(py, &tally)?))
}

/// A study run whose cases are solved elsewhere (the Dask driver): the runner's session over
/// the selection and the output directory (its lock held until [`StudySession::finish`] or
/// [`StudySession::close`]). [`StudySession::todo`] gives the cases still to solve (journaled
/// ones are not), [`StudySession::record`] journals each solved row once.
#[pyclass(module = "geartherm._native", frozen)]
struct StudySession {
    study: Study,
    out: Option<PathBuf>,
    compact: bool,
    session: Mutex<Option<Session>>,
    recorded: AtomicUsize,
}

impl StudySession {
    fn with<T>(&self, f: impl FnOnce(&Session) -> PyResult<T>) -> PyResult<T> {
        let guard = self.session.lock().unwrap_or_else(|e| e.into_inner());
        match guard.as_ref() {
            Some(s) => f(s),
            None => Err(py_error(
                "error",
                "the study session is closed".into(),
                Vec::new(),
                None,
            )),
        }
    }
}

#[pymethods]
impl StudySession {
    /// Open the runner's session: select the cases (`cases` or `shard`, checked as everywhere),
    /// lock `out` and read its journals.
    #[new]
    #[pyo3(signature = (spec, text, file, out = None, cases = None, shard = None))]
    fn new(
        spec: &str,
        text: String,
        file: &str,
        out: Option<PathBuf>,
        cases: Option<Vec<i128>>,
        shard: Option<(i128, i128)>,
    ) -> PyResult<StudySession> {
        let study = load_study(spec, text, file)?;
        let sel = selection(cases, shard)?;
        let session = Session::open(&study, &sel, out.as_deref()).map_err(job_error)?;
        Ok(StudySession {
            study,
            out,
            compact: sel.journal_shard().is_none(),
            session: Mutex::new(Some(session)),
            recorded: AtomicUsize::new(0),
        })
    }

    /// The positions of the cases still to solve, in case order.
    fn todo(&self) -> PyResult<Vec<usize>> {
        self.with(|s| Ok(s.todo().iter().map(|c| c.index).collect()))
    }

    /// Record rows solved elsewhere (a task's JSON array): each journaled once (a row of a
    /// case already recorded, from a task run again after a lost worker, is dropped). Returns
    /// the number of cases recorded so far.
    fn record(&self, rows: &str) -> PyResult<usize> {
        let rows: Vec<CaseRow> = serde_json::from_str(rows).map_err(|e| json_error("rows", e))?;
        self.with(|s| {
            for r in rows {
                if s.record(r, &Vec::new()).map_err(job_error)? {
                    self.recorded.fetch_add(1, Ordering::SeqCst);
                }
            }
            Ok(self.recorded.load(Ordering::SeqCst))
        })
    }

    /// End the session: (the `study.csv` text, a tally dict) as [`run_study`] returns them
    /// (compacted into `out` unless the selection is a shard).
    fn finish(&self, py: Python<'_>) -> PyResult<(String, Py<PyDict>)> {
        let session = self.session.lock().unwrap_or_else(|e| e.into_inner()).take();
        let Some(session) = session else {
            return Err(py_error(
                "error",
                "the study session is closed".into(),
                Vec::new(),
                None,
            ));
        };
        let (tally, rows) = session.finish();
        let table = result_table(py, &self.study, self.out.as_ref(), self.compact, rows)?;
        Ok((csv_text(&table)?, tally_dict(py, &tally)?))
    }

    /// Release the output directory without compacting (after a failure).
    fn close(&self) {
        self.session.lock().unwrap_or_else(|e| e.into_inner()).take();
    }
}

/// The equivalent `geartherm` command line of every case (for job arrays without Python).
#[pyfunction]
fn study_commands(spec: &str, text: String, file: &str) -> PyResult<Vec<String>> {
    let s = load_study(spec, text, file)?;
    Ok(s.cases().iter().map(|c| s.command_line(c)).collect())
}

/// Case `index` of a study: (its overrides as `"path = toml value"` lines, its job as JSON:
/// `{"kind": "run", "options": RunOptions}` or `{"kind": "steady", "options": SteadyOptions}`).
#[pyfunction]
fn study_case(spec: &str, text: String, file: &str, index: i128) -> PyResult<(Vec<String>, String)> {
    let s = load_study(spec, text, file)?;
    let c = s
        .select(&selection(Some(vec![index]), None)?)
        .map_err(job_error)?[0];
    let (ovs, _) = s
        .overrides(c.sample)
        .map_err(|m| job_error(geartherm::job::JobError::invalid(m)))?;
    let job = match &s.case_job(&c, s.spec.outputs.per_case) {
        geartherm::study::Job::Run(o) => serde_json::json!({"kind": "run", "options": o}),
        geartherm::study::Job::Steady(o) => serde_json::json!({"kind": "steady", "options": o}),
    };
    Ok((ovs.iter().map(|o| o.to_string()).collect(), to_json(&job)?))
}

/// Add the study functions and [`StudySession`] to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<StudySession>()?;
    m.add_function(wrap_pyfunction!(study_file, m)?)?;
    m.add_function(wrap_pyfunction!(study_cases, m)?)?;
    m.add_function(wrap_pyfunction!(study_select, m)?)?;
    m.add_function(wrap_pyfunction!(run_cases, m)?)?;
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(study_commands, m)?)?;
    m.add_function(wrap_pyfunction!(study_case, m)?)?;
    Ok(())
}
