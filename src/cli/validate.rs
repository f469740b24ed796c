//! `geartherm validate [DIR] [--out DIR] [--json]`: every reference case under DIR (default
//! `validation/`) with every applicable model choice; writes validation.csv,
//! validation_summary.csv, validation.md and the parity / error-vs-speed PNGs (docs/validation.md).

use std::path::PathBuf;

use crate::job::validate::{validate as run_validate, ValidateOptions};
use crate::report::files::{write_all_atomic, OutputDir};
use crate::report::validation::{
    doc_block, rows_csv, splice_doc, summary_csv, summary_markdown, ValidationReport,
};

use super::output::{emit, emit_json, invalid, io_failure};
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
    /// Also write the summary tables into this Markdown file, between its
    /// `<!-- geartherm validate: begin -->` and `<!-- geartherm validate: end -->` markers
    /// (docs/validation.md).
    #[arg(long)]
    pub doc: Option<PathBuf>,
}

/// The Markdown file `path` with its generated block replaced, written in place atomically.
fn write_doc(path: &std::path::Path, block: &str) -> Result<(), Failure> {
    let text =
        std::fs::read_to_string(path).map_err(|e| io_failure(format!("--doc {}: {e}", path.display())))?;
    let new = splice_doc(&text, block).map_err(|e| invalid(format!("--doc {}: {e}", path.display())))?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    write_all_atomic(dir, &[(&name, new.as_bytes())])
        .map_err(|e| io_failure(format!("--doc {}: {e}", path.display())))?;
    Ok(())
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
    for w in &r.warnings {
        eprintln!(
            "warning: case {} [{}]: {}: {} ({})",
            w.case, w.model, w.warning.item, w.warning.range, w.warning.seen
        );
    }
    let texts = [
        ("validation.csv", rows_csv(&r.rows)),
        ("validation_summary.csv", summary_csv(&r.summary)),
        ("validation.md", summary_markdown(&r.summary)),
    ];
    crate::report::plots::render_validation(out.path(), &r.rows, &texts)
        .map_err(|e| io_failure(format!("validate: {e}")))?;
    if let Some(doc) = &a.doc {
        write_doc(doc, &doc_block(&r.rows, &r.summary))?;
    }
    if a.json {
        emit_json(&ValidationReport {
            rows: &r.rows,
            summary: &r.summary,
            warnings: &r.warnings,
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
