//! `geartherm validate [DIR] [--out DIR] [--json]`: every reference case under DIR (default
//! `validation/`) with every applicable model choice; writes validation.csv,
//! validation_summary.csv, validation.md and the parity / error-vs-speed PNGs (docs/validation.md).

use std::path::PathBuf;

use geartherm::reference::{run_all, summarise};
use geartherm::report::files::OutputDir;
use geartherm::report::validation::{rows_csv, summary_csv, summary_markdown, ValidationReport};

use super::{invalid, print_json, Failure, EXIT_IO};

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

/// Run `validate`.
pub fn validate(a: &ValidateArgs) -> Result<(), Failure> {
    if !a.dir.is_dir() {
        return Err(invalid(format!("validate: {}: not a directory", a.dir.display())));
    }
    // Lock the output directory before the work (a second writer is refused now) and write the
    // result set as one transaction: the previous set stays whole until the commit.
    let out = OutputDir::begin(&a.out)?;
    let rows = run_all(&a.dir).map_err(|e| invalid(format!("validate: {e}")))?;
    if rows.is_empty() {
        return Err(invalid(format!(
            "validate: {}: no case.toml found",
            a.dir.display()
        )));
    }
    if let Some(r) = rows
        .iter()
        .find(|r| !(r.predicted.is_finite() && r.relative_error.is_finite()))
    {
        return Err(Failure {
            code: super::EXIT_NUMERICAL,
            message: format!(
                "validate: case {} point {} model {}: non-finite result",
                r.case, r.point, r.model
            ),
        });
    }
    let sum = summarise(&rows);
    let texts = [
        ("validation.csv", rows_csv(&rows)),
        ("validation_summary.csv", summary_csv(&sum)),
        ("validation.md", summary_markdown(&sum)),
    ];
    geartherm::report::plots::render_validation(out.path(), &rows, &texts).map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("validate: {e}"),
    })?;
    let target = out.commit()?;
    if a.json {
        print_json(&ValidationReport {
            rows: &rows,
            summary: &sum,
        })
    } else {
        print!("{}", summary_markdown(&sum));
        println!("\n{} rows written to {}", rows.len(), target.display());
        Ok(())
    }
}
