//! Calibration helpers of `geartherm._native` beside `Model.calibrate`: a priors file read as
//! `geartherm calibrate --priors FILE` reads it.

use pyo3::prelude::*;

/// The priors of a priors file's text (`[[prior]]` tables; `name` names it in messages) as
/// `--prior` arguments, `KEYPATH=normal:MEAN:SD` or `KEYPATH=lognormal:MEDIAN:SD_LN`. A bad entry
/// is an `InputError` naming the file and the key path (`prior[1].sd`).
#[pyfunction]
pub fn priors_from_file(text: &str, name: &str) -> PyResult<Vec<String>> {
    geartherm::job::calibrate::prior::from_file(text, name).map_err(crate::job_error)
}

use geartherm::job::calibrate::{stack, stack_fit, trace_file, CalibrateResult, TraceFile};
use geartherm::job::{self, JobError};

/// One trace as Python gives it: its CSV text, its name (`KEY@NAME`, the files written) and the
/// label its messages name (the path of a file, as `geartherm calibrate` names it; the name for
/// a DataFrame).
pub type TraceText = (String, String, String);

/// The trace files of [`TraceText`]s, read as `calibrate` reads them.
pub fn read_traces(traces: &[TraceText], o: &job::CalibrateOptions) -> PyResult<Vec<(String, TraceFile)>> {
    traces
        .iter()
        .map(|(csv, name, label)| {
            trace_file::read(csv, label, o.missing())
                .map(|f| (name.clone(), f))
                .map_err(|e| crate::job_error(e.into()))
        })
        .collect()
}

/// One segment's residuals and Jacobian (row-major) as Python returns them.
type Part = (Vec<f64>, Vec<f64>);

/// Every segment's evaluation at θ from the Python callable `f` (θ → list of (r, J) in segment
/// order): a Python exception is a numerical failure naming it.
fn remote(f: &Py<PyAny>, theta: &[f64]) -> Result<Vec<stack::SegmentEval>, JobError> {
    Python::attach(|py| {
        let out = f
            .call1(py, (theta.to_vec(),))
            .and_then(|v| v.extract::<Vec<Part>>(py))
            .map_err(|e| JobError::numerical(format!("segment evaluation on the workers: {e}")))?;
        Ok(out
            .into_iter()
            .map(|(r, j)| stack::SegmentEval { r, j })
            .collect())
    })
}

/// Calibrate over several traces; with `evaluator` the segments are evaluated by it (on Dask
/// workers), else here in parallel.
pub fn calibrate_traces(
    m: &job::Model,
    text: &str,
    files: &[(String, TraceFile)],
    o: &job::CalibrateOptions,
    evaluator: Option<&Py<PyAny>>,
) -> Result<CalibrateResult, JobError> {
    let inputs = stack::inputs(files, o)?;
    let s = stack::prepare(m, text, &inputs, o)?;
    match evaluator {
        None => stack_fit::fit(m, &s, o, &|th| s.evaluate(th)),
        Some(f) => stack_fit::fit(m, &s, o, &|th| s.stacked(&remote(f, th)?)),
    }
}

/// The residuals and Jacobians (row-major, one column per parameter of the stack) of the
/// segments `which` (indices over every trace's segments, in order) at θ: a worker's share.
pub fn evaluate_segments(
    m: &job::Model,
    text: &str,
    files: &[(String, TraceFile)],
    o: &job::CalibrateOptions,
    theta: &[f64],
    which: &[usize],
) -> Result<Vec<Part>, JobError> {
    let inputs = stack::inputs(files, o)?;
    let s = stack::prepare(m, text, &inputs, o)?;
    if theta.len() != s.params.len() {
        return Err(JobError::invalid(format!(
            "θ has {} values for {} parameters",
            theta.len(),
            s.params.len()
        )));
    }
    which
        .iter()
        .map(|&k| {
            if k >= s.segments.len() {
                return Err(JobError::invalid(format!(
                    "segment {k}: the traces have {}",
                    s.segments.len()
                )));
            }
            s.evaluate_segment(k, theta).map(|e| (e.r, e.j))
        })
        .collect()
}
