//! The study runner `geartherm study` and the Python package share: the cases still to do
//! (resume from the journals of the output directory), each finished case journaled (its files
//! first), a cancellation flag checked before every case, and the compaction of the journals into
//! `study.csv`, `study.parquet` and the figures.
//!
//! Cancellation is cooperative: once the flag is set no new case starts, the cases already
//! running finish and are journaled, and [`run`] returns with [`Tally::cancelled`] set. A rerun
//! into the same directory solves only the cases not journaled.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::report::files::{lock_in_place, write_all_atomic};
use crate::report::study::{journal_name, read_journals, study_csv, study_parquet, CaseRow, Journal, Table};

use super::{Case, Study};

/// Why the runner stopped before its work was done.
#[derive(Debug, thiserror::Error)]
pub enum RunnerError {
    /// The output directory holds the journal of another study (a usage error).
    #[error("{0}")]
    Foreign(String),
    /// The directory is locked by another writer, or a file could not be read or written.
    #[error("{0}")]
    Io(String),
}

impl RunnerError {
    fn io(dir: &Path) -> impl Fn(std::io::Error) -> RunnerError + '_ {
        move |e| {
            let m = format!("{}: {e}", dir.display());
            if e.kind() == std::io::ErrorKind::InvalidInput {
                RunnerError::Foreign(m)
            } else {
                RunnerError::Io(m)
            }
        }
    }
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct Tally {
    /// Cases asked for.
    pub cases: usize,
    /// Cases found in the journals (not solved again).
    pub already_done: usize,
    /// Cases solved by this run.
    pub solved: usize,
    /// Wall time of the solves, s.
    pub wall_s: f64,
    /// Worker threads.
    pub threads: usize,
    /// Stopped by the cancellation flag before every case was solved.
    pub cancelled: bool,
}

impl Tally {
    /// Solved cases per second of wall time.
    pub fn rate(&self) -> f64 {
        self.solved as f64 / self.wall_s.max(1e-9)
    }
}

/// Where a run writes: the output directory and the shard (its journal's name).
#[derive(Debug, Clone)]
pub struct Output {
    /// Output directory (journals, `cases/<id>/`, the compacted table and figures).
    pub dir: PathBuf,
    /// Shard `(i, n)`: the journal is `journal.shard-i-of-n.jsonl`.
    pub shard: Option<(usize, usize)>,
}

/// Solve `cases` of `study`. With `out`, cases already journaled there are skipped, every
/// finished case is journaled (after its files when per-case files are asked for), and one
/// writer at a time holds the journal. `on_done` receives every case solved by this run (from
/// worker threads, in completion order). Returns the tally and the rows solved by this run.
pub fn run(
    study: &Study,
    cases: &[Case],
    out: Option<&Output>,
    cancel: &AtomicBool,
    on_done: &(dyn Fn(&CaseRow) + Sync),
) -> Result<(Tally, Vec<CaseRow>), RunnerError> {
    let per_case = study.spec.outputs.per_case && out.is_some();
    let mut tally = Tally {
        cases: cases.len(),
        already_done: 0,
        solved: 0,
        wall_s: 0.0,
        threads: rayon::current_num_threads(),
        cancelled: false,
    };
    let (_lock, journal, todo) = match out {
        Some(o) => {
            let lock =
                lock_in_place(&o.dir, &journal_name(o.shard)).map_err(|e| RunnerError::Io(e.to_string()))?;
            let done = read_journals(&o.dir, &study.fingerprint).map_err(RunnerError::io(&o.dir))?;
            let todo: Vec<Case> = cases
                .iter()
                .filter(|c| !done.contains_key(&study.case_id(c)))
                .copied()
                .collect();
            let journal = Journal::open(&o.dir, &journal_name(o.shard), &study.fingerprint)
                .map_err(RunnerError::io(&o.dir))?;
            (Some(lock), Some(journal), todo)
        }
        None => (None, None, cases.to_vec()),
    };
    tally.already_done = cases.len() - todo.len();
    let rows: Mutex<Vec<CaseRow>> = Mutex::new(Vec::with_capacity(todo.len()));
    let write_error: Mutex<Option<String>> = Mutex::new(None);
    let start = Instant::now();
    study.run_until(&todo, per_case, cancel, &|row: CaseRow, files| {
        if let (Some(o), Some(j)) = (out, &journal) {
            let mut result = Ok(());
            if !files.is_empty() {
                let named: Vec<(&str, &[u8])> =
                    files.iter().map(|(n, b)| (n.as_str(), b.as_slice())).collect();
                result = write_all_atomic(&o.dir.join("cases").join(&row.case), &named).map(|_| ());
            }
            // The row is journaled only after its files are in place: a journaled case is
            // complete.
            if let Err(e) = result.and_then(|_| j.append(&row)) {
                let mut w = write_error.lock().unwrap_or_else(|e| e.into_inner());
                w.get_or_insert_with(|| format!("{}: {e}", j.path().display()));
                // A study that cannot journal stops: nothing it solves could be kept.
                cancel.store(true, Ordering::SeqCst);
                return;
            }
        }
        on_done(&row);
        rows.lock().unwrap_or_else(|e| e.into_inner()).push(row);
    });
    tally.wall_s = start.elapsed().as_secs_f64();
    if let Some(e) = write_error.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(RunnerError::Io(e));
    }
    let rows = rows.into_inner().unwrap_or_else(|e| e.into_inner());
    tally.solved = rows.len();
    tally.cancelled = tally.already_done + tally.solved < cases.len();
    Ok((tally, rows))
}

/// Journal rows solved elsewhere (e.g. by remote workers) into `dir`, skipping the cases
/// already journaled there, under the same lock as [`run`].
pub fn record(study: &Study, dir: &Path, rows: &[CaseRow]) -> Result<(), RunnerError> {
    let name = journal_name(None);
    let _lock = lock_in_place(dir, &name).map_err(|e| RunnerError::Io(e.to_string()))?;
    let done = read_journals(dir, &study.fingerprint).map_err(RunnerError::io(dir))?;
    let journal = Journal::open(dir, &name, &study.fingerprint).map_err(RunnerError::io(dir))?;
    for r in rows.iter().filter(|r| !done.contains_key(&r.case)) {
        journal.append(r).map_err(RunnerError::io(dir))?;
    }
    Ok(())
}

/// The table of `rows` in the study's case order (every case of the study that has a row).
pub fn table(study: &Study, rows: impl IntoIterator<Item = CaseRow>) -> Table {
    let mut by_id: std::collections::HashMap<String, CaseRow> =
        rows.into_iter().map(|r| (r.case.clone(), r)).collect();
    Table::with_outputs(
        study
            .cases()
            .iter()
            .filter_map(|c| by_id.remove(&study.case_id(c)))
            .collect(),
        &study.outputs,
    )
}

/// The journaled rows of `dir` as the study table (all shards merged, case order).
pub fn journaled(study: &Study, dir: &Path) -> Result<Table, RunnerError> {
    let done = read_journals(dir, &study.fingerprint).map_err(RunnerError::io(dir))?;
    Ok(table(study, done.into_values()))
}

/// What [`compact`] wrote.
pub struct Compacted {
    /// The table (case order).
    pub table: Table,
    /// `study.csv`'s contents.
    pub csv: Vec<u8>,
    /// Files written, in order.
    pub files: Vec<String>,
}

/// Merge every journal of `dir` into `study.csv`, `study.parquet` and the figures
/// (`main_effects.png`; `pareto.png` when two outputs are named or found).
pub fn compact(study: &Study, dir: &Path) -> Result<Compacted, RunnerError> {
    let table = journaled(study, dir)?;
    let csv = study_csv(&table).map_err(|e| RunnerError::Io(format!("study.csv: {e}")))?;
    let pq = study_parquet(&table).map_err(|e| RunnerError::Io(format!("study.parquet: {e}")))?;
    write_all_atomic(dir, &[("study.csv", &csv), ("study.parquet", &pq)]).map_err(RunnerError::io(dir))?;
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
    crate::report::plots::study::render(
        dir,
        &table,
        &study.spec.study.name,
        &effects,
        pareto.as_ref().map(|[a, b]| (a.as_str(), b.as_str())),
    )
    .map_err(|e| RunnerError::Io(format!("study figures: {e}")))?;
    let mut files = vec![
        "study.csv".to_string(),
        "study.parquet".into(),
        "main_effects.png".into(),
    ];
    if pareto.is_some() {
        files.push("pareto.png".into());
    }
    Ok(Compacted { table, csv, files })
}

/// Default outputs of the figures: total loss energy (or power), efficiency, and the highest
/// node temperature column of the first node.
pub fn default_effects(t: &Table) -> Vec<String> {
    let pick = |prefix: &str| t.outputs.iter().find(|o| o.starts_with(prefix)).cloned();
    [
        pick("energy_total").or_else(|| pick("loss_total")),
        pick("cycle_efficiency").or_else(|| pick("efficiency")),
        pick("temp_max_").or_else(|| pick("temp_")),
    ]
    .into_iter()
    .flatten()
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn study(dir: &Path) -> Study {
        let toml = r#"
[study]
name = "t"
model = "MODEL"
[job]
kind = "steady"
points = [{ gear = "1", speed_rpm = 1500, torque_nm = 60 }]
[sampling]
plan = "grid"
[[parameters]]
path = "lubrication.oil_level_mm"
values = [40, 50, 60, 70]
"#;
        let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/fzg_c.toml");
        let f = dir.join("s.toml");
        std::fs::write(&f, toml.replace("MODEL", &model.display().to_string())).unwrap();
        Study::from_file(&f).unwrap()
    }

    #[test]
    fn a_cancelled_run_journals_what_it_solved_and_the_rerun_does_the_rest() {
        let d = tempfile::tempdir().unwrap();
        let s = study(d.path());
        let out = Output {
            dir: d.path().join("out"),
            shard: None,
        };
        let cancel = AtomicBool::new(false);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        // Cancel after the first case: with one thread no other case starts.
        let (t, rows) = pool
            .install(|| {
                run(&s, &s.cases(), Some(&out), &cancel, &|_| {
                    cancel.store(true, Ordering::SeqCst)
                })
            })
            .unwrap();
        assert!(t.cancelled);
        assert_eq!((t.solved, rows.len()), (1, 1));
        let cancel = AtomicBool::new(false);
        let (t, rows) = run(&s, &s.cases(), Some(&out), &cancel, &|_| {}).unwrap();
        assert!(!t.cancelled);
        assert_eq!((t.already_done, t.solved), (1, 3));
        assert!(rows.iter().all(|r| r.case != "000000-p0000"));
        let c = compact(&s, &out.dir).unwrap();
        assert_eq!(c.table.rows.len(), 4);
        let ids: Vec<&str> = c.table.rows.iter().map(|r| r.case.as_str()).collect();
        assert_eq!(
            ids,
            ["000000-p0000", "000001-p0000", "000002-p0000", "000003-p0000"]
        );
        assert!(out.dir.join("study.parquet").is_file());
    }
}
