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
