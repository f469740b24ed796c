//! `validate`: every reference case under a directory with every applicable model choice, and
//! the checks of the comparison's numbers.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::reference::{run_all_with_warnings, summarise, CaseWarning, Row, SummaryRow};

use super::JobError;

/// Options of `geartherm validate`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValidateOptions {
    /// Directory of reference cases (each a subdirectory with `case.toml`).
    pub dir: PathBuf,
}

impl Default for ValidateOptions {
    fn default() -> Self {
        ValidateOptions {
            dir: PathBuf::from("validation"),
        }
    }
}

/// Every row and the summary per case and model.
#[derive(Debug, Clone)]
pub struct ValidateResult {
    /// One row per case, point and model choice.
    pub rows: Vec<Row>,
    /// Summary per case and model.
    pub summary: Vec<SummaryRow>,
    /// Loss models used outside their range, per case and model choice.
    pub warnings: Vec<CaseWarning>,
}

/// Evaluate every reference case under `o.dir`.
pub fn validate(o: &ValidateOptions) -> Result<ValidateResult, JobError> {
    if !o.dir.is_dir() {
        return Err(JobError::option(
            "dir",
            o.dir.display(),
            "a directory of reference cases",
            format!("validate: {}: not a directory", o.dir.display()),
        ));
    }
    let (rows, warnings) =
        run_all_with_warnings(&o.dir).map_err(|e| JobError::invalid(format!("validate: {e}")))?;
    if rows.is_empty() {
        return Err(JobError::invalid(format!(
            "validate: {}: no case.toml found",
            o.dir.display()
        )));
    }
    if let Some(r) = rows
        .iter()
        .find(|r| !(r.predicted.is_finite() && r.relative_error.is_finite()))
    {
        return Err(JobError::numerical(format!(
            "validate: case {} point {} model {}: non-finite result",
            r.case, r.point, r.model
        )));
    }
    let summary = summarise(&rows);
    Ok(ValidateResult {
        rows,
        summary,
        warnings,
    })
}
