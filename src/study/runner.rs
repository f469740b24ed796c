//! The study runner `geartherm study` and the Python package share: the cases still to do
//! (resume from the journals of the output directory), each finished case journaled (its files
//! first; the journal synced to disk every half second and at the end), a cancellation flag
//! checked before every case, and the compaction of the journals into `study.csv`,
//! `study.parquet` and the figures.
//!
//! Cancellation is cooperative: once the flag is set no new case starts, the cases already
//! running finish and are journaled, and [`run`] returns with [`Tally::cancelled`] set. A rerun
//! into the same directory solves only the cases not journaled.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use rayon::prelude::*;

use crate::job::JobError;
use crate::report::files::{lock_in_place, write_all_atomic, DirLock};
use crate::report::study::{journal_name, read_journals, study_csv, study_parquet, CaseRow, Journal, Table};

use super::{Case, CaseFiles, Selection, Study};

fn io_error(what: &Path) -> impl Fn(std::io::Error) -> JobError + '_ {
    move |e| JobError::io(format!("{}: {e}", what.display()), e.kind())
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

/// The journal side of a run into an output directory: its lock, the journal, and the case ids
/// journaled there.
struct Journaled {
    dir: PathBuf,
    _lock: DirLock,
    journal: Journal,
    done: Mutex<HashSet<String>>,
}

/// One run of a selection of a study's cases, whoever solves them: this process
/// ([`run`]) or remote workers (the Python package's Dask path solves [`Session::todo`]
/// elsewhere and hands each row to [`Session::record`]). With an output directory, the cases
/// already journaled there are not in `todo`, every recorded case is journaled (after its files)
/// once, and one writer at a time holds the journal.
pub struct Session {
    cases: usize,
    todo: Vec<Case>,
    journal: Option<Journaled>,
    rows: Mutex<Vec<CaseRow>>,
    start: Instant,
}

impl Session {
    /// Select the cases, take the output directory's lock and read its journals (resume).
    pub fn open(study: &Study, selection: &Selection, out: Option<&Path>) -> Result<Session, JobError> {
        let cases = study.select(selection)?;
        let (journal, todo) = match out {
            Some(dir) => {
                let name = journal_name(selection.journal_shard());
                let lock = lock_in_place(dir, &name)?;
                let done = read_journals(dir, &study.fingerprint)?;
                let todo: Vec<Case> = cases
                    .iter()
                    .filter(|c| !done.contains_key(&study.case_id(c)))
                    .copied()
                    .collect();
                let journal = Journal::open(dir, &name, &study.fingerprint).map_err(io_error(dir))?;
                let done = Mutex::new(done.into_keys().collect());
                let dir = dir.to_path_buf();
                (
                    Some(Journaled {
                        dir,
                        _lock: lock,
                        journal,
                        done,
                    }),
                    todo,
                )
            }
            None => (None, cases.clone()),
        };
        Ok(Session {
            cases: cases.len(),
            rows: Mutex::new(Vec::with_capacity(todo.len())),
            todo,
            journal,
            start: Instant::now(),
        })
    }

    /// The cases still to solve, in case order.
    pub fn todo(&self) -> &[Case] {
        &self.todo
    }

    /// A solved case: its files written under `cases/<id>/`, then its row journaled (a
    /// journaled case is complete). A case already recorded or journaled is not recorded
    /// again (a task rerun after a lost worker); returns whether this call recorded it.
    pub fn record(&self, row: CaseRow, files: &CaseFiles) -> Result<bool, JobError> {
        if let Some(j) = &self.journal {
            let mut done = j.done.lock().unwrap_or_else(|e| e.into_inner());
            if !done.insert(row.case.clone()) {
                return Ok(false);
            }
            if !files.is_empty() {
                let named: Vec<(&str, &[u8])> =
                    files.iter().map(|(n, b)| (n.as_str(), b.as_slice())).collect();
                let dir = j.dir.join("cases").join(&row.case);
                write_all_atomic(&dir, &named).map_err(io_error(&dir))?;
            }
            j.journal.append(&row).map_err(io_error(j.journal.path()))?;
        }
        self.rows.lock().unwrap_or_else(|e| e.into_inner()).push(row);
        Ok(true)
    }

    /// Sync the journal's rows to disk (they are written as each case finishes and synced at
    /// most [`crate::report::study::SYNC_INTERVAL_S`] later; closing the session syncs too).
    pub fn sync(&self) -> Result<(), JobError> {
        match &self.journal {
            Some(j) => j.journal.sync().map_err(io_error(j.journal.path())),
            None => Ok(()),
        }
    }

    /// The tally and the rows recorded by this session (in the order recorded); the journal is
    /// synced and closed.
    pub fn finish(self) -> (Tally, Vec<CaseRow>) {
        let rows = self.rows.into_inner().unwrap_or_else(|e| e.into_inner());
        let already_done = self.cases - self.todo.len();
        let tally = Tally {
            cases: self.cases,
            already_done,
            solved: rows.len(),
            wall_s: self.start.elapsed().as_secs_f64(),
            threads: rayon::current_num_threads(),
            cancelled: already_done + rows.len() < self.cases,
        };
        (tally, rows)
    }
}

/// Solve the `selection` of `study` in parallel (rayon): the one entry point of `geartherm
/// study`, Python's local run and a Dask task. With `out`, cases already journaled there are
/// skipped, every finished case is journaled (after its files when per-case files are asked
/// for). No new case starts once `cancel` is set. `on_done` receives every case solved by this
/// run (from worker threads, in completion order). Returns the tally and the rows solved by
/// this run.
pub fn run(
    study: &Study,
    selection: &Selection,
    out: Option<&Path>,
    cancel: &AtomicBool,
    on_done: &(dyn Fn(&CaseRow) + Sync),
) -> Result<(Tally, Vec<CaseRow>), JobError> {
    let per_case = study.spec.outputs.per_case && out.is_some();
    let session = Session::open(study, selection, out)?;
    let write_error: Mutex<Option<JobError>> = Mutex::new(None);
    session.todo().par_iter().with_max_len(1).for_each(|c| {
        if cancel.load(Ordering::SeqCst) {
            return;
        }
        let (row, files) = study.run_case(c, per_case);
        let shown = row.clone();
        match session.record(row, &files) {
            Ok(_) => on_done(&shown),
            Err(e) => {
                write_error
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .get_or_insert(e);
                // A study that cannot journal stops: nothing it solves could be kept.
                cancel.store(true, Ordering::SeqCst);
            }
        }
    });
    if let Some(e) = write_error.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    session.sync()?;
    Ok(session.finish())
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
pub fn journaled(study: &Study, dir: &Path) -> Result<Table, JobError> {
    let done = read_journals(dir, &study.fingerprint)?;
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
pub fn compact(study: &Study, dir: &Path) -> Result<Compacted, JobError> {
    let table = journaled(study, dir)?;
    let other = std::io::ErrorKind::Other;
    let csv = study_csv(&table).map_err(|e| JobError::io(format!("study.csv: {e}"), other))?;
    let pq = study_parquet(&table).map_err(|e| JobError::io(format!("study.parquet: {e}"), other))?;
    write_all_atomic(dir, &[("study.csv", &csv), ("study.parquet", &pq)]).map_err(io_error(dir))?;
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
    .map_err(|e| JobError::io(format!("study figures: {e}"), other))?;
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
        let out = d.path().join("out");
        let cancel = AtomicBool::new(false);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        // Cancel after the first case: with one thread no other case starts.
        let (t, rows) = pool
            .install(|| {
                run(&s, &Selection::All, Some(&out), &cancel, &|_| {
                    cancel.store(true, Ordering::SeqCst)
                })
            })
            .unwrap();
        assert!(t.cancelled);
        assert_eq!((t.solved, rows.len()), (1, 1));
        let cancel = AtomicBool::new(false);
        let (t, rows) = run(&s, &Selection::All, Some(&out), &cancel, &|_| {}).unwrap();
        assert!(!t.cancelled);
        assert_eq!((t.already_done, t.solved), (1, 3));
        assert!(rows.iter().all(|r| r.case != "000000-p0000"));
        let c = compact(&s, &out).unwrap();
        assert_eq!(c.table.rows.len(), 4);
        let ids: Vec<&str> = c.table.rows.iter().map(|r| r.case.as_str()).collect();
        assert_eq!(
            ids,
            ["000000-p0000", "000001-p0000", "000002-p0000", "000003-p0000"]
        );
        assert!(out.join("study.parquet").is_file());
    }
}
