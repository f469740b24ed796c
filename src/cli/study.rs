//! `geartherm study STUDY.toml --out DIR [--shard I/N | --cases LIST] [--list]`: parses, runs the study with
//! the library's runner (`crate::study::runner`: journal, resume, compaction) under a
//! progress bar, stops cleanly on Ctrl-C (exit 130, resumable), prints the tally.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::report::study::CaseRow;
use crate::study::runner;
use crate::study::{Case, Selection, Study};

use super::output::{emit, progress_bar, warn, Failure, EXIT_IO};

/// Arguments of `study`.
#[derive(clap::Args, Debug)]
pub struct StudyArgs {
    /// Study file (TOML): base model, job, parameters, sampling plan.
    pub study: PathBuf,
    /// Output directory (journal, study.csv, study.parquet, figures; cases/<id>/ when asked).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run only shard I of N (cases I, I+N, I+2N, …; I from 0), e.g. from a Slurm job array;
    /// a later run without --shard merges the shards' journals into study.csv.
    #[arg(long, value_name = "I/N", allow_hyphen_values = true)]
    pub shard: Option<String>,
    /// Run only these cases (positions in the case list, from 0, comma-separated), each once.
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub cases: Option<String>,
    /// Print each case's id and the equivalent stand-alone `geartherm run`/`steady` command
    /// line, then exit.
    #[arg(long)]
    pub list: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Each case's id and stand-alone command line, one per line, written as they are rendered (a
/// closed pipe ends the listing quietly).
fn list(study: &Study, cases: &[Case]) -> Result<(), Failure> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for c in cases {
        writeln!(out, "{}\t{}", study.case_id(c), study.command_line(c)).map_err(|e| stdout_error(&e))?;
    }
    out.flush().map_err(|e| stdout_error(&e))
}

fn stdout_error(e: &std::io::Error) -> Failure {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        Failure {
            code: super::output::EXIT_BROKEN_PIPE,
            message: String::new(),
        }
    } else {
        Failure {
            code: EXIT_IO,
            message: format!("cannot write to standard output: {e}"),
        }
    }
}

/// Set by SIGINT: no new case starts; the running ones finish and are journaled.
pub(super) static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Exit status of a command ended by SIGINT (128 + 2).
pub(super) const EXIT_INTERRUPTED: i32 = 130;

#[cfg(unix)]
extern "C" fn on_sigint(_: libc::c_int) {
    INTERRUPTED.store(true, Ordering::SeqCst);
    // A second Ctrl-C ends the process at once (async-signal-safe: signal(2)).
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_DFL);
    }
}

/// Ctrl-C stops the study cleanly (the default again once the study is over).
pub(super) fn catch_sigint() {
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGINT, on_sigint as *const () as libc::sighandler_t);
    }
}

/// Ctrl-C at its default again (after the cases: a Ctrl-C during the compaction ends the
/// process, the journals already hold every case).
pub(super) fn release_sigint() {
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_DFL);
    }
}

/// Run `study`.
pub fn study(a: &StudyArgs) -> Result<(), Failure> {
    let study = Study::from_file(&a.study)?;
    let selection = Selection::parse(a.cases.as_deref(), a.shard.as_deref())?;
    let cases = study.select(&selection)?;
    if a.list {
        return list(&study, &cases);
    }
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("studies").join(&study.spec.study.name));
    solve_journaled(&study, &selection, cases.len(), &dir, a.quiet, "cases")?;
    if let Some((i, n)) = selection.journal_shard() {
        return emit(&format!(
            "shard {i}/{n} done; run `geartherm study {} --out {}` once every shard finished to merge them\n",
            a.study.display(),
            dir.display()
        ));
    }
    let c = runner::compact(&study, &dir)?;
    let failed: Vec<&CaseRow> = c.table.rows.iter().filter(|r| r.status != "ok").collect();
    for r in failed.iter().take(20) {
        warn(&format!(
            "case {} ({}): {}: {}",
            r.case, r.job, r.status, r.message
        ));
    }
    emit(&format!(
        "{} of {} cases in {} ({} ok, {} failed or invalid): {}\n",
        c.table.rows.len(),
        study.cases().len(),
        dir.display(),
        c.table.rows.len() - failed.len(),
        failed.len(),
        c.files.join(", ")
    ))
}

/// Solve the selected cases of `study` into the journal in `dir` with a progress bar (unless
/// `quiet`) and Ctrl-C caught; print the tally, counting in `noun` ("cases", "samples"). An
/// interruption is a failure that says how to resume.
pub(super) fn solve_journaled(
    study: &Study,
    selection: &Selection,
    n_cases: usize,
    dir: &std::path::Path,
    quiet: bool,
    noun: &str,
) -> Result<(), Failure> {
    let b = progress_bar(
        n_cases,
        &format!("{{msg}} [{{bar:40}}] {{pos}}/{{len}} {noun}, {{per_sec}}, ETA {{eta}}"),
        study.spec.study.name.clone(),
        quiet,
    );
    catch_sigint();
    let solved = runner::run(study, selection, Some(dir), &INTERRUPTED, &|_| {
        if let Some(b) = &b {
            b.inc(1);
        }
    });
    release_sigint();
    let (tally, _) = solved?;
    if let Some(b) = &b {
        b.finish_and_clear();
    }
    emit(&format!(
        "{} {noun} solved in {:.2} s ({:.2} {noun}/s on {} threads), {} already done\n",
        tally.solved,
        tally.wall_s,
        tally.rate(),
        tally.threads,
        tally.already_done
    ))?;
    if tally.cancelled {
        return Err(Failure {
            code: EXIT_INTERRUPTED,
            message: format!(
                "interrupted: {} of {} {noun} journaled in {}; run the same command again to resume",
                tally.already_done + tally.solved,
                tally.cases,
                dir.display()
            ),
        });
    }
    Ok(())
}
