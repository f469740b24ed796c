//! Outputs of a design study: the journal (one JSON line per finished case, appended and synced
//! as cases finish, so an interrupted study resumes without recomputing them), and the compacted
//! table `study.csv` / `study.parquet` (one row per case).
//!
//! Journal format (`journal*.jsonl`): the first line is `{"study": "<fingerprint>"}`, then one
//! [`CaseRow`] per line. A line torn by a kill is ignored on reading (and that case is rerun).

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use serde::{Deserialize, Serialize};

/// A parameter value of one case: a number or a string (e.g. an oil's catalogue key).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// A number.
    Number(f64),
    /// A string.
    Text(String),
}

/// One finished case: its parameters and outputs, or its failure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseRow {
    /// Case id (`<sample>-<job>`), unique in the study.
    pub case: String,
    /// Sample index (the parameter set).
    pub sample: usize,
    /// What was solved: the cycle name, or the operating point (`gear 3 @ 2000 rpm, 100 N·m`).
    pub job: String,
    /// Parameter values in the study's order (column name = the key path).
    pub params: Vec<(String, ParamValue)>,
    /// `ok`, `invalid` (the overrides made an invalid model) or `failed` (numerical failure).
    pub status: String,
    /// Failure message (empty when ok).
    pub message: String,
    /// Outputs with units in their names (`energy_total_j`, `temp_max_sump_c`, …); absent on
    /// failure; None for an undefined value (e.g. efficiency without output power).
    pub outputs: Vec<(String, Option<f64>)>,
    /// An uncertainty study's time series of the case on the study's grid (node temperatures
    /// rounded to 0.001 °C, energies per source to 0.1 J), one vector per series; absent
    /// otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub series: Option<Vec<Vec<f64>>>,
}

/// Journal file name of a shard (`None`: the whole study).
pub fn journal_name(shard: Option<(usize, usize)>) -> String {
    match shard {
        Some((i, n)) => format!("journal.shard-{i}-of-{n}.jsonl"),
        None => "journal.jsonl".into(),
    }
}

/// Why the journals of a directory cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// A journal of another study (different fingerprint): the directory belongs to it.
    #[error("{}: belongs to a different study (another study file or model); choose another output directory", .0.display())]
    Foreign(PathBuf),
    /// A journal could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The journal or directory.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
}

/// Rows already in every journal of `dir` (all shards), by case id. Journals of another study
/// (different fingerprint) are an error: the directory belongs to a different study.
pub fn read_journals(dir: &Path, fingerprint: &str) -> Result<BTreeMap<String, CaseRow>, JournalError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| JournalError::Io { path, source }
    };
    let mut done = BTreeMap::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(done);
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("journal") && n.ends_with(".jsonl"))
        })
        .collect();
    files.sort();
    for f in files {
        let mut reader = BufReader::new(File::open(&f).map_err(io(&f))?);
        let mut head = String::new();
        // A header without its newline is being written by a writer that has just created
        // the journal (another shard starting at the same time): it holds no rows yet.
        if reader.read_line(&mut head).is_err() || !head.ends_with('\n') {
            continue;
        }
        let lines = reader.lines();
        let head: serde_json::Value = serde_json::from_str(&head).unwrap_or_default();
        if head.get("study").and_then(|s| s.as_str()) != Some(fingerprint) {
            return Err(JournalError::Foreign(f));
        }
        for line in lines {
            // A torn last line (killed mid-write) does not parse and is skipped.
            if let Ok(row) = serde_json::from_str::<CaseRow>(&line.map_err(io(&f))?) {
                done.insert(row.case.clone(), row);
            }
        }
    }
    Ok(done)
}

/// Longest time a written row waits for its sync to disk, s.
pub const SYNC_INTERVAL_S: f64 = 0.5;

/// An append-only journal: each row is one line, written whole as its case finishes (a process
/// killed at any moment keeps every row written), and synced to disk at most
/// [`SYNC_INTERVAL_S`] after it and when the journal is closed ([`Journal::sync`], or dropped).
/// An operating-system crash can thus lose the rows of the last half second, which a rerun
/// solves again; a sync per row would cost a disk flush per case (milliseconds, longer than a
/// case's solve).
pub struct Journal {
    /// The file and the time of its last sync.
    file: Mutex<(File, std::time::Instant)>,
    path: PathBuf,
}

impl Journal {
    /// Open (or create with its header) the journal `name` in `dir`. A torn last line from an
    /// earlier kill is cut off first, so new rows start on a line of their own.
    pub fn open(dir: &Path, name: &str, fingerprint: &str) -> std::io::Result<Journal> {
        std::fs::create_dir_all(dir)?;
        let path = dir.join(name);
        let mut file = OpenOptions::new()
            .create(true)
            .read(true)
            .append(true)
            .open(&path)?;
        let text = std::fs::read(&path)?;
        if text.is_empty() {
            writeln!(file, "{}", serde_json::json!({ "study": fingerprint }))?;
        } else if text.last() != Some(&b'\n') {
            let keep = text.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
            file.set_len(keep as u64)?;
            if keep == 0 {
                writeln!(file, "{}", serde_json::json!({ "study": fingerprint }))?;
            }
        }
        file.sync_all()?;
        Ok(Journal {
            file: Mutex::new((file, std::time::Instant::now())),
            path,
        })
    }

    /// Append one finished case (one write of its whole line); sync the journal to disk when
    /// the last sync is [`SYNC_INTERVAL_S`] old.
    pub fn append(&self, row: &CaseRow) -> std::io::Result<()> {
        let mut line = serde_json::to_string(row).map_err(std::io::Error::other)?;
        line.push('\n');
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.0.write_all(line.as_bytes())?;
        if f.1.elapsed().as_secs_f64() >= SYNC_INTERVAL_S {
            f.0.sync_data()?;
            f.1 = std::time::Instant::now();
        }
        Ok(())
    }

    /// Sync every row written to disk.
    pub fn sync(&self) -> std::io::Result<()> {
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.0.sync_data()?;
        f.1 = std::time::Instant::now();
        Ok(())
    }

    /// The journal's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Journal {
    /// A journal dropped without [`Journal::sync`] (an error ended its run) still syncs what it
    /// wrote; a failure here has no one to report to, and the rows are written either way.
    fn drop(&mut self) {
        let f = self.file.get_mut().unwrap_or_else(|e| e.into_inner());
        let _ = f.0.sync_data();
    }
}

/// Column kinds of the study table.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Text,
    Int,
    Number,
}

/// The study table: the rows in case order and the union of their columns.
pub struct Table {
    /// Rows sorted by (sample, job order as given).
    pub rows: Vec<CaseRow>,
    /// Parameter columns (key paths) and whether they hold text.
    pub params: Vec<(String, bool)>,
    /// Output columns in order of first appearance.
    pub outputs: Vec<String>,
}

impl Table {
    /// Build the table of `rows` (already in case order).
    pub fn new(rows: Vec<CaseRow>) -> Table {
        let mut params: Vec<(String, bool)> = Vec::new();
        let mut outputs: Vec<String> = Vec::new();
        for r in &rows {
            for (k, v) in &r.params {
                let text = matches!(v, ParamValue::Text(_));
                match params.iter_mut().find(|(n, _)| n == k) {
                    Some(p) => p.1 |= text,
                    None => params.push((k.clone(), text)),
                }
            }
            for (k, _) in &r.outputs {
                if !outputs.contains(k) {
                    outputs.push(k.clone());
                }
            }
        }
        Table {
            rows,
            params,
            outputs,
        }
    }

    /// The table of `rows` with the output columns `outputs` in this order (the study's columns:
    /// the same whatever the rows hold), then any other output the rows carry.
    pub fn with_outputs(rows: Vec<CaseRow>, outputs: &[String]) -> Table {
        let mut t = Table::new(rows);
        let extra: Vec<String> = t.outputs.drain(..).filter(|o| !outputs.contains(o)).collect();
        t.outputs = outputs.to_vec();
        t.outputs.extend(extra);
        t
    }

    /// The value of an output column in a row.
    pub fn output(&self, row: &CaseRow, name: &str) -> Option<f64> {
        row.outputs.iter().find(|(k, _)| k == name).and_then(|(_, v)| *v)
    }

    fn columns(&self) -> Vec<(String, Kind)> {
        let mut c = vec![
            ("case".to_string(), Kind::Text),
            ("sample".to_string(), Kind::Int),
            ("job".to_string(), Kind::Text),
        ];
        c.extend(
            self.params
                .iter()
                .map(|(k, t)| (k.clone(), if *t { Kind::Text } else { Kind::Number })),
        );
        c.push(("status".into(), Kind::Text));
        c.push(("message".into(), Kind::Text));
        c.extend(self.outputs.iter().map(|k| (k.clone(), Kind::Number)));
        c
    }

    /// Cell `col` of `row`: text, or a finite number, or None (empty / null).
    fn cell(&self, row: &CaseRow, col: usize) -> Cell {
        let np = self.params.len();
        match col {
            0 => Cell::Text(row.case.clone()),
            1 => Cell::Int(row.sample as i64),
            2 => Cell::Text(row.job.clone()),
            c if c < 3 + np => {
                let name = &self.params[c - 3].0;
                match row.params.iter().find(|(k, _)| k == name).map(|(_, v)| v) {
                    Some(ParamValue::Number(x)) if self.params[c - 3].1 => Cell::Text(x.to_string()),
                    Some(ParamValue::Number(x)) if x.is_finite() => Cell::Number(*x),
                    Some(ParamValue::Text(s)) => Cell::Text(s.clone()),
                    _ => Cell::Null,
                }
            }
            c if c == 3 + np => Cell::Text(row.status.clone()),
            c if c == 4 + np => Cell::Text(row.message.clone()),
            c => match self.output(row, &self.outputs[c - 5 - np]) {
                Some(x) if x.is_finite() => Cell::Number(x),
                _ => Cell::Null,
            },
        }
    }
}

enum Cell {
    Text(String),
    Int(i64),
    Number(f64),
    Null,
}

/// `study.csv`: one row per case; numbers in shortest round-trip form; empty cells for failed or
/// undefined values (never NaN).
pub fn study_csv(t: &Table) -> Result<Vec<u8>, csv::Error> {
    let cols = t.columns();
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(cols.iter().map(|(n, _)| n.as_str()))?;
    for r in &t.rows {
        let rec: Vec<String> = (0..cols.len())
            .map(|c| match t.cell(r, c) {
                Cell::Text(s) => s,
                Cell::Int(i) => i.to_string(),
                Cell::Number(x) => x.to_string(),
                Cell::Null => String::new(),
            })
            .collect();
        w.write_record(&rec)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// `study.parquet`: the same table, typed columns (UTF-8 text, INT64 sample, DOUBLE numbers,
/// null for empty cells), one row group.
pub fn study_parquet(t: &Table) -> parquet::errors::Result<Vec<u8>> {
    use parquet::basic::{LogicalType, Repetition, Type as Physical};
    use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
    use parquet::file::properties::WriterProperties;
    use parquet::file::writer::SerializedFileWriter;
    use parquet::schema::types::Type;
    use std::sync::Arc;

    let cols = t.columns();
    let fields = cols
        .iter()
        .map(|(name, kind)| {
            let b = match kind {
                Kind::Text => Type::primitive_type_builder(name, Physical::BYTE_ARRAY)
                    .with_logical_type(Some(LogicalType::String)),
                Kind::Int => Type::primitive_type_builder(name, Physical::INT64),
                Kind::Number => Type::primitive_type_builder(name, Physical::DOUBLE),
            };
            b.with_repetition(Repetition::OPTIONAL).build().map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let schema = Arc::new(Type::group_type_builder("study").with_fields(fields).build()?);
    let props = Arc::new(WriterProperties::builder().build());
    let mut w = SerializedFileWriter::new(Vec::new(), schema, props)?;
    let mut rg = w.next_row_group()?;
    let mut c = 0;
    while let Some(mut col) = rg.next_column()? {
        let cells: Vec<Cell> = t.rows.iter().map(|r| t.cell(r, c)).collect();
        let def: Vec<i16> = cells
            .iter()
            .map(|x| i16::from(!matches!(x, Cell::Null)))
            .collect();
        match cols[c].1 {
            Kind::Text => {
                let v: Vec<ByteArray> = cells
                    .iter()
                    .filter_map(|x| match x {
                        Cell::Text(s) => Some(ByteArray::from(s.as_str())),
                        _ => None,
                    })
                    .collect();
                col.typed::<ByteArrayType>().write_batch(&v, Some(&def), None)?;
            }
            Kind::Int => {
                let v: Vec<i64> = cells
                    .iter()
                    .filter_map(|x| if let Cell::Int(i) = x { Some(*i) } else { None })
                    .collect();
                col.typed::<Int64Type>().write_batch(&v, Some(&def), None)?;
            }
            Kind::Number => {
                let v: Vec<f64> = cells
                    .iter()
                    .filter_map(|x| if let Cell::Number(f) = x { Some(*f) } else { None })
                    .collect();
                col.typed::<DoubleType>().write_batch(&v, Some(&def), None)?;
            }
        }
        col.close()?;
        c += 1;
    }
    rg.close()?;
    w.into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two shards starting at once: one reads the other's journal while its header is being
    /// written (seen by the hostile campaign as "belongs to a different study", exit 1).
    #[test]
    fn a_journal_whose_header_is_being_written_holds_no_rows_yet() {
        let dir = tempfile::tempdir().unwrap();
        let fp = "0123456789abcdef";
        let full = format!("{}\n", serde_json::json!({ "study": fp }));
        std::fs::write(dir.path().join("journal.shard-1-of-2.jsonl"), &full[..9]).unwrap();
        assert!(read_journals(dir.path(), fp).unwrap().is_empty());
        std::fs::write(dir.path().join("journal.shard-1-of-2.jsonl"), &full).unwrap();
        assert!(read_journals(dir.path(), fp).unwrap().is_empty());
        // A complete header of another study is still refused.
        let other = format!("{}\n", serde_json::json!({ "study": "fedcba9876543210" }));
        std::fs::write(dir.path().join("journal.shard-1-of-2.jsonl"), other).unwrap();
        let e = read_journals(dir.path(), fp).unwrap_err().to_string();
        assert!(e.contains("belongs to a different study"), "{e}");
    }

    fn row(i: usize, ok: bool) -> CaseRow {
        CaseRow {
            series: None,
            case: format!("{i:05}-wltc"),
            sample: i,
            job: "wltc".into(),
            params: vec![
                (
                    "lubrication.oil_level_mm".into(),
                    ParamValue::Number(40.0 + i as f64),
                ),
                ("oil.catalogue".into(), ParamValue::Text("fva_3a".into())),
            ],
            status: if ok { "ok" } else { "failed" }.into(),
            message: if ok {
                String::new()
            } else {
                "no equilibrium, \"x\"".into()
            },
            outputs: if ok {
                vec![
                    ("energy_total_j".into(), Some(1.0 / 3.0 + i as f64)),
                    ("cycle_efficiency".into(), None),
                ]
            } else {
                vec![]
            },
        }
    }

    #[test]
    fn journal_survives_a_torn_line_and_skips_it() {
        let d = tempfile::tempdir().unwrap();
        let j = Journal::open(d.path(), "journal.jsonl", "abc").unwrap();
        j.append(&row(0, true)).unwrap();
        j.append(&row(1, false)).unwrap();
        drop(j);
        // A kill in the middle of a write leaves a partial line.
        let mut f = OpenOptions::new()
            .append(true)
            .open(d.path().join("journal.jsonl"))
            .unwrap();
        f.write_all(b"{\"case\":\"00002-wl").unwrap();
        drop(f);
        let done = read_journals(d.path(), "abc").unwrap();
        assert_eq!(done.len(), 2);
        assert_eq!(done["00000-wltc"], row(0, true));
        // Reopening cuts the torn line; new rows parse.
        let j = Journal::open(d.path(), "journal.jsonl", "abc").unwrap();
        j.append(&row(2, true)).unwrap();
        assert_eq!(read_journals(d.path(), "abc").unwrap().len(), 3);
        assert!(read_journals(d.path(), "other").is_err());
    }

    #[test]
    fn csv_and_parquet_hold_every_row_without_nan() {
        let t = Table::new(vec![row(0, true), row(1, false), row(2, true)]);
        let csv = String::from_utf8(study_csv(&t).unwrap()).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines[0],
            "case,sample,job,lubrication.oil_level_mm,oil.catalogue,status,message,energy_total_j,cycle_efficiency"
        );
        assert_eq!(lines.len(), 4);
        assert!(
            lines[1].ends_with(&format!(",ok,,{},", 1.0 / 3.0)),
            "{}",
            lines[1]
        );
        assert!(!csv.contains("NaN"));
        let pq = study_parquet(&t).unwrap();
        use parquet::file::reader::{FileReader, SerializedFileReader};
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("s.parquet"), pq).unwrap();
        let r = SerializedFileReader::new(File::open(d.path().join("s.parquet")).unwrap()).unwrap();
        assert_eq!(r.metadata().file_metadata().num_rows(), 3);
        let rows: Vec<String> = r
            .get_row_iter(None)
            .unwrap()
            .map(|x| x.unwrap().to_string())
            .collect();
        assert!(
            rows[0].contains("energy_total_j: 0.3333333333333333"),
            "{}",
            rows[0]
        );
        assert!(rows[1].contains("energy_total_j: null"), "{}", rows[1]);
    }
}
