//! A trace file as measurement systems write it (SCADA exports, loggers): rows with empty cells
//! and gaps in time. [`read`] cuts it into [`Trace`] segments:
//!
//! - an **empty cell** (in any column: a channel not recorded at that time) makes its row a
//!   missing row: dropped and counted per column ([`Missing::Drop`], the default), or refused
//!   with its line and column ([`Missing::Refuse`]);
//! - a **gap**: a time step (between kept rows) longer than [`MAX_GAP_FACTOR`] times the
//!   median step of the file starts a new segment. A file of one segment keeps its times; in a
//!   file of several, each segment's times are counted from its own first row (`offset_s` holds
//!   that row's time in the file), so a record of years stays within a cycle's time range.
//!
//! Each segment is then read as [`Trace::parse`] reads a whole trace (the same columns, ranges
//! and messages, with the file's line numbers).

use std::collections::BTreeMap;

use serde::Serialize;

use super::trace::{check_header, Trace, TraceError, MAX_GAP_FACTOR};

/// What an empty cell does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Missing {
    /// Its row is dropped and counted.
    #[default]
    Drop,
    /// It is an error naming line and column.
    Refuse,
}

/// One segment of a trace file.
#[derive(Debug, Clone)]
pub struct TraceSegment {
    /// Its rows, as a trace.
    pub trace: Trace,
    /// Time of its first row in the file, s (its times are counted from there; 0 for a file of
    /// one segment).
    pub offset_s: f64,
    /// Its rows as CSV text (the file's header, times counted from `offset_s`).
    pub csv: String,
}

/// A trace file cut into segments.
#[derive(Debug, Clone)]
pub struct TraceFile {
    /// Where it came from, for messages.
    pub source: String,
    /// Rows read (data lines after the header).
    pub rows: usize,
    /// Rows dropped for an empty cell.
    pub dropped_rows: usize,
    /// Empty cells per column (columns with none left out), in header order.
    pub missing_cells: Vec<(String, usize)>,
    /// The segments, in time order.
    pub segments: Vec<TraceSegment>,
}

/// The JSON summary of a trace file (`geartherm trace --json`, Python's `read_trace`).
#[derive(Debug, Clone, Serialize)]
pub struct TraceSummary {
    /// Where it came from.
    pub source: String,
    /// Rows read.
    pub rows: usize,
    /// Rows kept (in segments).
    pub kept_rows: usize,
    /// Rows dropped for an empty cell.
    pub dropped_rows: usize,
    /// Empty cells per column.
    pub missing_cells: BTreeMap<String, usize>,
    /// Per segment: first and last line, rows, time of its first row in the file and its
    /// duration, s.
    pub segments: Vec<SegmentSummary>,
    /// The measured node columns and the boundary columns.
    pub nodes: Vec<String>,
    /// Boundary columns.
    pub boundaries: Vec<String>,
}

/// One segment in a [`TraceSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct SegmentSummary {
    /// First line in the file (1-based).
    pub first_line: usize,
    /// Last line in the file.
    pub last_line: usize,
    /// Rows.
    pub rows: usize,
    /// Time of its first row in the file, s.
    pub start_s: f64,
    /// Its last row's time minus its first's, s.
    pub duration_s: f64,
}

fn is_record(line: &str) -> bool {
    let t = line.trim();
    !t.is_empty() && !t.starts_with('#')
}

/// A data row: 0-based line index, its fields.
struct Row<'a> {
    index: usize,
    fields: Vec<&'a str>,
}

/// Read and cut trace text; `source` names it in messages.
pub fn read(text: &str, source: &str, missing: Missing) -> Result<TraceFile, TraceError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let lines: Vec<&str> = text.lines().collect();
    let head = lines
        .iter()
        .position(|l| is_record(l))
        .ok_or_else(|| TraceError(format!("{source}: empty trace: no header line")))?;
    let header: Vec<&str> = lines[head].split(',').map(str::trim).collect();
    check_header(source, head + 1, &header)?;
    let mut counts = vec![0usize; header.len()];
    let mut kept = Vec::new();
    let mut rows = 0;
    for (index, line) in lines.iter().enumerate().skip(head + 1) {
        if !is_record(line) {
            continue;
        }
        rows += 1;
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != header.len() {
            return Err(TraceError(format!(
                "{source}, line {}: {} fields, the header has {}",
                index + 1,
                fields.len(),
                header.len()
            )));
        }
        let empty: Vec<usize> = (0..fields.len())
            .filter(|&i| fields[i].trim().is_empty())
            .collect();
        if let (Some(&i), Missing::Refuse) = (empty.first(), missing) {
            return Err(TraceError(format!(
                "{source}, line {}: column {} = \"\": empty (a missing value), refused: drop such rows \
                 (the default) or fill the cell",
                index + 1,
                header[i]
            )));
        }
        for &i in &empty {
            counts[i] += 1;
        }
        if empty.is_empty() {
            kept.push(Row { index, fields });
        }
    }
    let time_col = header.iter().position(|c| c.eq_ignore_ascii_case("time_s"));
    let groups = split(&kept, time_col);
    let many = groups.len() > 1;
    let mut segments = Vec::with_capacity(groups.len());
    for g in groups {
        segments.push(segment(&lines, head, &header, &kept[g], time_col, many, source)?);
    }
    let missing_cells: Vec<(String, usize)> = header
        .iter()
        .zip(&counts)
        .filter(|(_, &n)| n > 0)
        .map(|(c, &n)| (c.to_string(), n))
        .collect();
    let dropped_rows = rows - kept.len();
    annotate(&mut segments, dropped_rows, &missing_cells);
    Ok(TraceFile {
        source: source.to_string(),
        rows,
        dropped_rows,
        missing_cells,
        segments,
    })
}

/// Each segment's notes: the rows its file dropped, which segment it is.
fn annotate(segments: &mut [TraceSegment], dropped: usize, cells: &[(String, usize)]) {
    let n = segments.len();
    for (k, s) in segments.iter_mut().enumerate() {
        if dropped > 0 {
            let per: Vec<String> = cells.iter().map(|(c, m)| format!("{c} {m}")).collect();
            s.trace.notes.push(format!(
                "{}: {dropped} row(s) with empty cells dropped (empty cells per column: {})",
                s.trace.source,
                per.join(", ")
            ));
        }
        if n > 1 {
            s.trace.notes.push(format!(
                "{}: segment {k} of {n} (lines {}…{}; its times counted from {} s in the file)",
                s.trace.source,
                s.trace.lines.first().copied().unwrap_or(0),
                s.trace.lines.last().copied().unwrap_or(0),
                s.offset_s
            ));
        }
    }
}

fn time_of(row: &Row<'_>, col: Option<usize>) -> Option<f64> {
    col.and_then(|c| row.fields[c].trim().parse::<f64>().ok())
        .filter(|t| t.is_finite())
}

/// The rows' ranges of the segments: a step above [`MAX_GAP_FACTOR`] × the median step starts
/// a new one. Without readable times (the segment reader then names the bad cell) one segment.
fn split(rows: &[Row<'_>], col: Option<usize>) -> Vec<std::ops::Range<usize>> {
    let times: Option<Vec<f64>> = rows.iter().map(|r| time_of(r, col)).collect();
    let whole = 0..rows.len();
    let Some(times) = times.filter(|t| t.len() > 1) else {
        return vec![whole];
    };
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    // Times that do not increase: one segment, so the reader names the row with the file's own
    // time (a segment's times counted from its first row would show another value).
    if steps.iter().any(|s| *s <= 0.0) {
        return vec![whole];
    }
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    let mut out = Vec::new();
    let mut start = 0;
    for (k, w) in times.windows(2).enumerate() {
        if median > 0.0 && w[1] - w[0] > MAX_GAP_FACTOR * median {
            out.push(start..k + 1);
            start = k + 1;
        }
    }
    out.push(start..rows.len());
    out
}

/// One segment: its rows written back at their own line numbers (every other line a comment),
/// times counted from its first row when the file has several, read as a trace.
fn segment(
    lines: &[&str],
    head: usize,
    header: &[&str],
    rows: &[Row<'_>],
    time_col: Option<usize>,
    rebase: bool,
    source: &str,
) -> Result<TraceSegment, TraceError> {
    let offset_s = match (rebase, rows.first()) {
        (true, Some(r)) => time_of(r, time_col).unwrap_or(0.0),
        _ => 0.0,
    };
    let mut padded = String::with_capacity(lines.len() * 2 + rows.len() * 64);
    let mut csv = String::with_capacity(rows.len() * 64);
    csv.push_str(&header.join(","));
    csv.push('\n');
    let mut next = 0;
    for (k, _) in lines.iter().enumerate() {
        if k == head {
            padded.push_str(lines[head]);
        } else if next < rows.len() && rows[next].index == k {
            let line = row_text(&rows[next], time_col, offset_s);
            padded.push_str(&line);
            csv.push_str(&line);
            csv.push('\n');
            next += 1;
        } else {
            padded.push('#');
        }
        padded.push('\n');
    }
    let trace = Trace::parse_segment(&padded, source)?;
    Ok(TraceSegment { trace, offset_s, csv })
}

fn row_text(row: &Row<'_>, time_col: Option<usize>, offset_s: f64) -> String {
    let mut f: Vec<String> = row.fields.iter().map(|s| s.trim().to_string()).collect();
    if let (Some(c), true) = (time_col, offset_s != 0.0) {
        if let Some(t) = time_of(row, time_col) {
            f[c] = format!("{}", t - offset_s);
        }
    }
    f.join(",")
}

impl TraceFile {
    /// The segment calibrated: the only one, or `index` (0-based) of several.
    pub fn select(&self, index: Option<usize>) -> Result<&Trace, TraceError> {
        let n = self.segments.len();
        match index {
            Some(k) if k < n => Ok(&self.segments[k].trace),
            Some(k) => Err(TraceError(format!(
                "segment = {k}: must lie in [0, {}] ({} has {n} segment(s))",
                n.saturating_sub(1),
                self.source
            ))),
            None if n == 1 => Ok(&self.segments[0].trace),
            None => Err(TraceError(format!(
                "{}: {n} segments (gaps in time cut the record; `geartherm trace {}` lists them): \
                 choose one with --segment K (Python: segment=K), K in [0, {}]",
                self.source,
                self.source,
                n - 1
            ))),
        }
    }

    /// The JSON summary.
    pub fn summary(&self) -> TraceSummary {
        let first = self.segments.first().map(|s| &s.trace);
        TraceSummary {
            source: self.source.clone(),
            rows: self.rows,
            kept_rows: self.segments.iter().map(|s| s.trace.len()).sum(),
            dropped_rows: self.dropped_rows,
            missing_cells: self.missing_cells.iter().cloned().collect(),
            segments: self
                .segments
                .iter()
                .map(|s| SegmentSummary {
                    first_line: s.trace.lines.first().copied().unwrap_or(0),
                    last_line: s.trace.lines.last().copied().unwrap_or(0),
                    rows: s.trace.len(),
                    start_s: s.offset_s + s.trace.times.first().copied().unwrap_or(0.0),
                    duration_s: s.trace.times.last().copied().unwrap_or(0.0)
                        - s.trace.times.first().copied().unwrap_or(0.0),
                })
                .collect(),
            nodes: first.map_or_else(Vec::new, |t| {
                t.measured.iter().map(|c| c.column.clone()).collect()
            }),
            boundaries: first.map_or_else(Vec::new, |t| {
                t.boundaries.iter().map(|c| c.column.clone()).collect()
            }),
        }
    }

    /// Read and cut a trace file (one that cannot be read is I/O; one that is not UTF-8 text
    /// or does not parse is invalid input: [`crate::job::read_text`]).
    pub fn load(path: &std::path::Path, missing: Missing) -> Result<TraceFile, crate::job::JobError> {
        let text = crate::job::read_text(path)?;
        Ok(read(&text, &path.display().to_string(), missing)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:sump\n";

    fn rows(times: &[f64]) -> String {
        let mut s = HEAD.to_string();
        for (k, t) in times.iter().enumerate() {
            s.push_str(&format!("{t},1000,50,g1,20,{}\n", 20 + k));
        }
        s
    }

    #[test]
    fn a_gap_starts_a_new_segment_counted_from_its_first_row() {
        let text = rows(&[0.0, 600.0, 1200.0, 1800.0, 2e7, 2e7 + 600.0, 2e7 + 1200.0]);
        let f = read(&text, "t.csv", Missing::Drop).unwrap();
        assert_eq!(f.segments.len(), 2);
        let (a, b) = (&f.segments[0], &f.segments[1]);
        assert_eq!((a.trace.len(), b.trace.len()), (4, 3));
        assert_eq!(b.offset_s, 2e7);
        assert_eq!(b.trace.times, vec![0.0, 600.0, 1200.0]);
        assert_eq!(b.trace.lines, vec![6, 7, 8]);
        assert_eq!(b.trace.measured[0].values_c, vec![24.0, 25.0, 26.0]);
        let s = f.summary();
        assert_eq!((s.segments[1].first_line, s.segments[1].start_s), (6, 2e7));
        assert!(f.select(None).unwrap_err().to_string().contains("2 segments"));
        assert_eq!(f.select(Some(1)).unwrap().len(), 3);
        assert!(f.select(Some(2)).unwrap_err().to_string().contains("[0, 1]"));
    }

    #[test]
    fn empty_cells_drop_their_rows_with_a_count_or_are_refused() {
        let text = rows(&[0.0, 600.0, 1200.0, 1800.0]).replace("600,1000,50,g1,20,21", "600,1000,50,g1,,");
        let f = read(&text, "t.csv", Missing::Drop).unwrap();
        assert_eq!((f.rows, f.dropped_rows, f.segments.len()), (4, 1, 1));
        assert_eq!(
            f.missing_cells,
            vec![("boundary:ambient".to_string(), 1), ("node:sump".to_string(), 1)]
        );
        assert_eq!(f.segments[0].trace.times, vec![0.0, 1200.0, 1800.0]);
        assert_eq!(f.segments[0].offset_s, 0.0);
        let e = read(&text, "t.csv", Missing::Refuse).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("boundary:ambient"), "{e}");
    }

    #[test]
    fn a_bad_cell_in_a_segment_names_its_line_in_the_file() {
        let text = rows(&[0.0, 600.0, 1200.0, 1e6, 1e6 + 600.0]).replace(",24\n", ",x\n");
        let e = read(&text, "t.csv", Missing::Drop).unwrap_err().to_string();
        assert!(e.contains("line 6") && e.contains("not a number"), "{e}");
    }

    #[test]
    fn a_time_that_goes_back_is_named_with_the_files_own_value() {
        // A gap later in the file would cut it into segments counted from their first rows;
        // the row whose time goes back is still named with the time the file holds.
        let text = rows(&[600.0, 0.0, -600.0, 1200.0, 1e6, 1e6 + 600.0]);
        let e = read(&text, "t.csv", Missing::Drop).unwrap_err().to_string();
        assert!(
            e.contains("line 3") && e.contains("\"0\"") && e.contains("increase"),
            "{e}"
        );
    }
}
