//! A measured trace: CSV text with the inputs of a drive or rig cycle, optional boundary
//! temperatures and one or more measured node temperatures, checked with the line and column
//! of every problem.
//!
//! Header (column order free):
//! - the cycle's columns, as `geartherm run --cycle FILE` reads them: `time_s` and either
//!   `speed_kmh[,gear]` (vehicle cycle) or `input_speed_rpm,input_torque_nm,gear` (rig cycle);
//! - `boundary:NAME`: the temperature of boundary NAME of the model, °C (replaces the model's);
//! - `node:NAME`: the measured temperature of capacity node NAME, °C (at least one).
//!
//! Blank lines and lines starting with `#` are skipped. Every cell of a temperature column must
//! hold a finite number in [−60, 400] °C. [`Trace::parse`] reads one segment: an empty cell is an
//! error, as is a time step more than [`MAX_GAP_FACTOR`] times the median step (a gap in time);
//! [`super::trace_file::read`] reads a whole file, dropping rows with empty cells (counted) and
//! cutting it at its gaps.

use crate::cycle::{CycleError, DriveCycle};

/// A time step longer than this many median steps is a gap in the record.
pub const MAX_GAP_FACTOR: f64 = 10.0;
/// Least temperature a trace may hold, °C.
pub const MIN_TEMP_C: f64 = -60.0;
/// Greatest temperature a trace may hold, °C.
pub const MAX_TEMP_C: f64 = 400.0;

const CYCLE_COLUMNS: [&str; 5] = [
    "time_s",
    "speed_kmh",
    "input_speed_rpm",
    "input_torque_nm",
    "gear",
];

/// One temperature column.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The column as written in the header.
    pub column: String,
    /// The node or boundary it names.
    pub name: String,
    /// Its values, °C, one per row.
    pub values_c: Vec<f64>,
}

/// A checked trace.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// Where it came from (file path or a name), for messages.
    pub source: String,
    /// The cycle its input columns make.
    pub cycle: DriveCycle,
    /// 1-based line of each row in the text.
    pub lines: Vec<usize>,
    /// Time of each row, s.
    pub times: Vec<f64>,
    /// Boundary temperature columns.
    pub boundaries: Vec<Channel>,
    /// Measured node temperature columns.
    pub measured: Vec<Channel>,
    /// What reading the file did to it (rows dropped for empty cells, the segment it is of a
    /// file cut at its gaps); a calibration lists them among its warnings.
    pub notes: Vec<String>,
}

/// A problem with a trace: file, line, column, value, what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct TraceError(pub String);

impl From<CycleError> for TraceError {
    fn from(e: CycleError) -> Self {
        TraceError(e.to_string())
    }
}

fn is_record(line: &str) -> bool {
    let t = line.trim();
    !t.is_empty() && !t.starts_with('#')
}

/// What a header column is.
enum Kind {
    Cycle,
    Boundary(String),
    Node(String),
}

fn classify(source: &str, line: usize, col: &str) -> Result<Kind, TraceError> {
    let lower = col.to_ascii_lowercase();
    if CYCLE_COLUMNS.contains(&lower.as_str()) {
        return Ok(Kind::Cycle);
    }
    let named = |prefix: &str| {
        col.strip_prefix(prefix)
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .map(str::to_string)
    };
    if let Some(n) = named("boundary:") {
        return Ok(Kind::Boundary(n));
    }
    if let Some(n) = named("node:") {
        return Ok(Kind::Node(n));
    }
    Err(TraceError(format!(
        "{source}, line {line}: column \"{col}\": unknown column; a trace has the cycle's columns ({}), \
         boundary:NAME and node:NAME temperature columns (°C)",
        CYCLE_COLUMNS.join(", ")
    )))
}

/// What each header column is (a column named twice or unknown is an error naming it).
fn header_kinds(source: &str, line: usize, header: &[&str]) -> Result<Vec<Kind>, TraceError> {
    let mut kinds = Vec::with_capacity(header.len());
    for (i, col) in header.iter().enumerate() {
        if header[..i].iter().any(|c| c.eq_ignore_ascii_case(col)) {
            return Err(TraceError(format!(
                "{source}, line {line}: column \"{col}\": appears twice"
            )));
        }
        kinds.push(classify(source, line, col)?);
    }
    Ok(kinds)
}

/// The header's columns checked (each known, none twice) before any row is read.
pub(super) fn check_header(source: &str, line: usize, header: &[&str]) -> Result<(), TraceError> {
    header_kinds(source, line, header).map(|_| ())
}

impl Trace {
    /// Parse and check trace text of one segment; `source` names it in messages. An empty cell
    /// or a gap in time is an error here ([`super::trace_file::read`] cuts a file with them into
    /// segments).
    pub fn parse(text: &str, source: &str) -> Result<Trace, TraceError> {
        let t = Self::parse_segment(text, source)?;
        check_gaps(source, &t.times, &t.lines)?;
        Ok(t)
    }

    /// [`Trace::parse`] without the check for gaps in time (a segment cut at its gaps).
    pub(super) fn parse_segment(text: &str, source: &str) -> Result<Trace, TraceError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let lines: Vec<&str> = text.lines().collect();
        let head = lines
            .iter()
            .position(|l| is_record(l))
            .ok_or_else(|| TraceError(format!("{source}: empty trace: no header line")))?;
        let header: Vec<&str> = lines[head].split(',').map(str::trim).collect();
        let kinds = header_kinds(source, head + 1, &header)?;
        // The cycle columns, on the same line numbers, for the cycle reader.
        let cycle_cols: Vec<usize> = (0..header.len())
            .filter(|&i| matches!(kinds[i], Kind::Cycle))
            .collect();
        let mut cycle_text = String::with_capacity(text.len());
        for (k, l) in lines.iter().enumerate() {
            if k >= head && is_record(l) {
                let fields: Vec<&str> = l.split(',').collect();
                let keep: Vec<&str> = cycle_cols
                    .iter()
                    .filter_map(|&i| fields.get(i).copied())
                    .collect();
                cycle_text.push_str(&keep.join(","));
            } else {
                cycle_text.push('#');
            }
            cycle_text.push('\n');
        }
        let cycle = DriveCycle::parse(&cycle_text, source)?;
        let rows: Vec<(usize, &str)> = lines
            .iter()
            .enumerate()
            .skip(head + 1)
            .filter(|(_, l)| is_record(l))
            .map(|(k, l)| (k + 1, *l))
            .collect();
        let mut boundaries = Vec::new();
        let mut measured = Vec::new();
        for (i, kind) in kinds.iter().enumerate() {
            let (name, list) = match kind {
                Kind::Cycle => continue,
                Kind::Boundary(n) => (n, &mut boundaries),
                Kind::Node(n) => (n, &mut measured),
            };
            list.push(Channel {
                column: header[i].to_string(),
                name: name.clone(),
                values_c: column_values(source, &rows, i, header[i], header.len())?,
            });
        }
        if measured.is_empty() {
            return Err(TraceError(format!(
                "{source}, line {}: no measured temperature: name at least one column node:NAME (°C)",
                head + 1
            )));
        }
        let times: Vec<f64> = cycle.rows.iter().map(|r| r.time).collect();
        let lines_of: Vec<usize> = cycle.rows.iter().map(|r| r.line).collect();
        Ok(Trace {
            source: source.to_string(),
            cycle,
            lines: lines_of,
            times,
            boundaries,
            measured,
            notes: Vec::new(),
        })
    }

    /// Read and parse a trace file (one that cannot be read is I/O; one that is not UTF-8
    /// text or does not parse is invalid input: [`crate::job::read_text`]).
    pub fn load(path: &std::path::Path) -> Result<Trace, crate::job::JobError> {
        let text = crate::job::read_text(path)?;
        Ok(Trace::parse(&text, &path.display().to_string())?)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// True when the trace has no row.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }
}

/// The values of temperature column `i`, each a finite number in range.
fn column_values(
    source: &str,
    rows: &[(usize, &str)],
    i: usize,
    col: &str,
    width: usize,
) -> Result<Vec<f64>, TraceError> {
    let mut out = Vec::with_capacity(rows.len());
    for (line, text) in rows {
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != width {
            return Err(TraceError(format!(
                "{source}, line {line}: {} fields, the header has {width}",
                fields.len()
            )));
        }
        let raw = fields[i].trim();
        let at = |what: &str| TraceError(format!("{source}, line {line}: column {col} = \"{raw}\": {what}"));
        if raw.is_empty() {
            return Err(at(
                "empty (a gap in the record): every row needs a value; fill or cut the gap",
            ));
        }
        let v: f64 = raw.parse().map_err(|_| at("not a number"))?;
        if !v.is_finite() {
            return Err(at("not a finite number"));
        }
        if !(MIN_TEMP_C..=MAX_TEMP_C).contains(&v) {
            return Err(at(&format!("must lie in [{MIN_TEMP_C}, {MAX_TEMP_C}] °C")));
        }
        out.push(v);
    }
    Ok(out)
}

/// A time step above [`MAX_GAP_FACTOR`] × the median step is a gap.
fn check_gaps(source: &str, times: &[f64], lines: &[usize]) -> Result<(), TraceError> {
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return Ok(());
    }
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    for (k, w) in times.windows(2).enumerate() {
        let dt = w[1] - w[0];
        if dt > MAX_GAP_FACTOR * median {
            return Err(TraceError(format!(
                "{source}, line {}: column time_s = \"{}\": a gap of {dt} s after the row at {} s, more than \
                 {MAX_GAP_FACTOR} times the median step ({median} s): split the trace at the gap",
                lines[k + 1],
                w[1],
                w[0]
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = "time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:sump\n\
                      0,1000,50,g1,20,20\n60,1000,50,g1,20,21\n120,1000,50,g1,20,22\n";

    fn err(text: &str) -> String {
        Trace::parse(text, "t.csv").unwrap_err().to_string()
    }

    #[test]
    fn reads_columns() {
        let t = Trace::parse(OK, "t.csv").unwrap();
        assert_eq!(t.len(), 3);
        assert_eq!(t.measured[0].name, "sump");
        assert_eq!(t.measured[0].values_c, vec![20.0, 21.0, 22.0]);
        assert_eq!(t.boundaries[0].name, "ambient");
        assert_eq!(t.lines, vec![2, 3, 4]);
    }

    #[test]
    fn bad_traces_name_line_and_column() {
        let e = err(&OK.replace("0,1000,50,g1,20,21", "0,1000,50,g1,20,nan"));
        assert!(
            e.contains("line 3") && e.contains("node:sump") && e.contains("finite"),
            "{e}"
        );
        let e = err(&OK.replace(",20,22", ",20,"));
        assert!(e.contains("line 4") && e.contains("gap"), "{e}");
        let e = err(&OK.replace("node:sump", "boundary:ambient"));
        assert!(e.contains("twice") && e.contains("line 1"), "{e}");
        let e = err(&OK.replace("node:sump", "sump_c"));
        assert!(e.contains("unknown column") && e.contains("sump_c"), "{e}");
        let e = err(&OK.replace("120,1000", "30,1000"));
        assert!(e.contains("line 4") && e.contains("time"), "{e}");
        let e = err(&OK.replace(",node:sump", ",boundary:x"));
        assert!(e.contains("no measured temperature"), "{e}");
        let long = format!("{OK}180,1000,50,g1,20,22\n5000,1000,50,g1,20,22\n");
        let e = err(&long);
        assert!(e.contains("line 6") && e.contains("gap of 4820 s"), "{e}");
        let e = err(&OK.replace(",input_torque_nm", ""));
        assert!(e.contains("t.csv"), "{e}");
    }
}
