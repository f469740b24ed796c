//! `geartherm validate [DIR] [--out DIR] [--json]`: every reference case under DIR (default
//! `validation/`) with every applicable model choice; writes validation.csv,
//! validation_summary.csv, validation.md and the parity / error-vs-speed PNGs (docs/validation.md).

use std::path::PathBuf;

use geartherm::job::validate::{validate as run_validate, ValidateOptions};
use geartherm::report::files::OutputDir;
use geartherm::report::validation::{rows_csv, summary_csv, summary_markdown, ValidationReport};

use super::output::{emit, emit_json, io_failure};
use super::Failure;

/// Arguments of `validate`.
#[derive(clap::Args, Debug)]
pub struct ValidateArgs {
    /// Directory of reference cases (each a subdirectory with case.toml).
    #[arg(default_value = "validation")]
    pub dir: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "validation_out")]
    pub out: PathBuf,
    /// Print rows and summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

impl ValidateArgs {
    /// The job's options.
    pub fn options(&self) -> ValidateOptions {
        ValidateOptions {
            dir: self.dir.clone(),
        }
    }
}

/// Run `validate`.
pub fn validate(a: &ValidateArgs) -> Result<(), Failure> {
    // Lock the output directory before the work (a second writer is refused now) and write the
    // result set as one transaction: the previous set stays whole until the commit.
    let out = OutputDir::begin(&a.out)?;
    let r = run_validate(&a.options())?;
    let texts = [
        ("validation.csv", rows_csv(&r.rows)),
        ("validation_summary.csv", summary_csv(&r.summary)),
        ("validation.md", summary_markdown(&r.summary)),
    ];
    geartherm::report::plots::render_validation(out.path(), &r.rows, &texts)
        .map_err(|e| io_failure(format!("validate: {e}")))?;
    if a.json {
        emit_json(&ValidationReport {
            rows: &r.rows,
            summary: &r.summary,
        })?;
    } else {
        emit(&format!(
            "{}\n{} rows written to {}\n",
            summary_markdown(&r.summary),
            r.rows.len(),
            out.target().display()
        ))?;
    }
    out.commit()?;
    Ok(())
}
