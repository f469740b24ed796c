//! `geartherm study STUDY.toml --out DIR [--shard I/N] [--list]`: parses, calls
//! `geartherm::study`, journals each finished case, compacts `study.csv` / `study.parquet` and
//! the figures at the end, prints the tally.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use geartherm::report::files::write_all_atomic;
use geartherm::report::study::{
    journal_name, read_journals, study_csv, study_parquet, CaseRow, Journal, Table,
};
use geartherm::study::{Case, Study, StudyError};

use super::output::{emit, invalid, progress_bar, warn, Failure, EXIT_INVALID, EXIT_IO};

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
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Print each case's id and the equivalent stand-alone `geartherm run`/`steady` command
    /// line, then exit.
    #[arg(long)]
    pub list: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

fn io(dir: &std::path::Path) -> impl Fn(std::io::Error) -> Failure + '_ {
    move |e| Failure {
        // A directory holding another study's journal is a usage error, not an I/O failure.
        code: if e.kind() == std::io::ErrorKind::InvalidInput {
            EXIT_INVALID
        } else {
            EXIT_IO
        },
        message: format!("{}: {e}", dir.display()),
    }
}

fn parse_shard(s: &str) -> Result<(usize, usize), Failure> {
    let bad = || invalid(format!("--shard {s}: expected I/N with 0 ≤ I < N"));
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
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

/// Run `study`.
pub fn study(a: &StudyArgs) -> Result<(), Failure> {
    let study = Study::from_file(&a.study).map_err(|e| match e {
        // A study or model file that cannot be read is I/O, as for every other command.
        StudyError::Io { .. } => Failure {
            code: EXIT_IO,
            message: e.to_string(),
        },
        StudyError::Invalid(m) => invalid(m),
        StudyError::Job(j) => j.into(),
    })?;
    let shard = a.shard.as_deref().map(parse_shard).transpose()?;
    let cases = match shard {
        Some((i, n)) => study.shard(i, n),
        None => study.cases(),
    };
    if a.list {
        return list(&study, &cases);
    }
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("studies").join(&study.spec.study.name));
    // One writer per journal: a second run of the same study (or shard) into this directory
    // is refused while the first runs; different shards run side by side.
    let _lock = geartherm::report::files::lock_in_place(&dir, &journal_name(shard)).map_err(|e| Failure {
        code: EXIT_IO,
        message: e.to_string(),
    })?;
    let done = read_journals(&dir, &study.fingerprint).map_err(io(&dir))?;
    let todo: Vec<Case> = cases
        .iter()
        .filter(|c| !done.contains_key(&study.case_id(c)))
        .copied()
        .collect();
    let journal = Journal::open(&dir, &journal_name(shard), &study.fingerprint).map_err(io(&dir))?;
    let per_case = study.spec.outputs.per_case;
    let b = progress_bar(
        todo.len(),
        "{msg} [{bar:40}] {pos}/{len} cases, {per_sec}, ETA {eta}",
        study.spec.study.name.clone(),
        a.quiet,
    );
    let write_error: Mutex<Option<String>> = Mutex::new(None);
    let start = Instant::now();
    study.run(&todo, per_case, &|row: CaseRow, files| {
        let mut result = Ok(());
        if per_case && !files.is_empty() {
            let named: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (n.as_str(), b.as_slice())).collect();
            result = write_all_atomic(&dir.join("cases").join(&row.case), &named).map(|_| ());
        }
        // The row is journaled only after its files are in place: a journaled case is complete.
        let result = result.and_then(|_| journal.append(&row));
        if let Err(e) = result {
            let mut w = write_error.lock().unwrap_or_else(|e| e.into_inner());
            w.get_or_insert_with(|| format!("{}: {e}", journal.path().display()));
        }
        if let Some(b) = &b {
            b.inc(1);
        }
    });
    if let Some(b) = &b {
        b.finish_and_clear();
    }
    let wall = start.elapsed().as_secs_f64();
    if let Some(e) = write_error.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(Failure {
            code: EXIT_IO,
            message: e,
        });
    }
    emit(&format!(
        "{} cases solved in {wall:.2} s ({:.2} cases/s on {} threads), {} already done\n",
        todo.len(),
        todo.len() as f64 / wall.max(1e-9),
        rayon::current_num_threads(),
        cases.len() - todo.len()
    ))?;
    if let Some((i, n)) = shard {
        return emit(&format!(
            "shard {i}/{n} done; run `geartherm study {} --out {}` once every shard finished to merge them\n",
            a.study.display(),
            dir.display()
        ));
    }
    compact(&study, &dir)
}

/// Merge every journal of `dir` into study.csv, study.parquet and the figures (in case order).
fn compact(study: &Study, dir: &std::path::Path) -> Result<(), Failure> {
    let done = read_journals(dir, &study.fingerprint).map_err(io(dir))?;
    let rows: Vec<CaseRow> = study
        .cases()
        .iter()
        .filter_map(|c| done.get(&study.case_id(c)).cloned())
        .collect();
    let failed: Vec<&CaseRow> = rows.iter().filter(|r| r.status != "ok").collect();
    for r in failed.iter().take(20) {
        warn(&format!(
            "case {} ({}): {}: {}",
            r.case, r.job, r.status, r.message
        ));
    }
    let table = Table::new(rows.clone());
    let csv = study_csv(&table).map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("study.csv: {e}"),
    })?;
    let pq = study_parquet(&table).map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("study.parquet: {e}"),
    })?;
    write_all_atomic(dir, &[("study.csv", &csv), ("study.parquet", &pq)]).map_err(io(dir))?;
    let effects = study
        .spec
        .outputs
        .effects
        .clone()
        .unwrap_or_else(|| default_effects(&table));
    let pareto = study.spec.outputs.pareto.clone().or_else(|| {
        let e = default_effects(&table);
        (e.len() >= 2).then(|| [e[0].clone(), e[e.len() - 1].clone()])
    });
    geartherm::report::plots::study::render(
        dir,
        &table,
        &study.spec.study.name,
        &effects,
        pareto.as_ref().map(|[a, b]| (a.as_str(), b.as_str())),
    )
    .map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("study figures: {e}"),
    })?;
    emit(&format!(
        "{} of {} cases in {} ({} ok, {} failed or invalid): study.csv, study.parquet, main_effects.png{}\n",
        rows.len(),
        study.cases().len(),
        dir.display(),
        rows.len() - failed.len(),
        failed.len(),
        if pareto.is_some() { ", pareto.png" } else { "" }
    ))
}

/// Default outputs of the figures: total loss energy (or power), efficiency, and the highest
/// node temperature column of the first node.
fn default_effects(t: &Table) -> Vec<String> {
    let pick = |prefix: &str| t.outputs.iter().find(|o| o.starts_with(prefix)).cloned();
    [
        pick("energy_total").or_else(|| pick("total_loss")),
        pick("cycle_efficiency").or_else(|| pick("efficiency")),
        pick("max_temp_").or_else(|| pick("temp_")),
    ]
    .into_iter()
    .flatten()
    .collect()
}
