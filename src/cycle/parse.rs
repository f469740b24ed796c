//! Drive-cycle files: CSV text → [`DriveCycle`] (SI units inside).
//!
//! Two kinds, told apart by the header (column order free, names case-insensitive):
//! - vehicle cycle: `time_s,speed_kmh` with an optional `gear` column;
//! - rig cycle: `time_s,input_speed_rpm,input_torque_nm,gear`.
//!
//! Blank lines and lines starting with `#` are skipped; fields are trimmed. Every row keeps its
//! 1-based line number in the file so that later checks (gear names, at schedule time) can point
//! at the line.

use super::error::{CycleError, CycleErrorKind};
use std::path::Path;

/// km/h → m/s.
pub const KMH: f64 = 1.0 / 3.6;
/// rpm → rad/s.
pub const RPM: f64 = crate::physics::units::RAD_S_PER_RPM;

/// Which kind of cycle a file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CycleKind {
    /// Vehicle speed over time (needs a vehicle to turn into gearbox inputs).
    Vehicle,
    /// Gearbox input speed, torque and gear over time (test rig; no vehicle).
    Rig,
}

/// One row (sample) of a cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleRow {
    /// 1-based line number in the file.
    pub line: usize,
    /// Time, s.
    pub time: f64,
    /// Vehicle speed, m/s (≥ 0; vehicle cycles, 0 in rig cycles).
    pub vehicle_speed: f64,
    /// Gearbox input speed, rad/s (≥ 0; rig cycles, 0 in vehicle cycles).
    pub input_speed: f64,
    /// Gearbox input torque, N·m (any sign; rig cycles, 0 in vehicle cycles).
    pub input_torque: f64,
    /// Gear-state name from the `gear` column, if the file has one.
    pub gear: Option<String>,
}

/// A parsed drive cycle or rig cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveCycle {
    /// Short name (bundled name, or the file stem).
    pub name: String,
    /// Where it came from (file path or `bundled:<name>`), used in error messages.
    pub source: String,
    /// Vehicle or rig cycle.
    pub kind: CycleKind,
    /// Rows, time strictly increasing, at least two.
    pub rows: Vec<CycleRow>,
    /// Whether the file has a `gear` column (always true for rig cycles).
    pub has_gear: bool,
}

/// Highest vehicle speed a cycle may ask for, km/h (the fastest road cars reach about 490 km/h;
/// beyond that the vehicle model and the gearbox speeds are meaningless).
pub const MAX_VEHICLE_SPEED_KMH: f64 = 500.0;
/// Highest rig input speed, rpm (the same limit as the command-line `--speed-rpm`).
pub const MAX_INPUT_SPEED_RPM: f64 = 50_000.0;
/// Largest rig input torque magnitude, N·m (the same limit as the command line).
pub const MAX_INPUT_TORQUE_NM: f64 = 1e6;
/// Shortest time step between two rows, s (1 kHz logging; finer steps carry no thermal
/// information and make the energy integrals round-off).
pub const MIN_TIME_STEP_S: f64 = 1e-3;
/// Latest time in a cycle, s (about 116 days).
pub const MAX_TIME_S: f64 = 1e7;
/// Most rows a cycle may have (memory of the schedule and the output rows grows with it).
pub const MAX_ROWS: usize = 2_000_000;

const TIME: &str = "time_s";
const SPEED: &str = "speed_kmh";
const IN_SPEED: &str = "input_speed_rpm";
const IN_TORQUE: &str = "input_torque_nm";
const GEAR: &str = "gear";
const KNOWN: [&str; 5] = [TIME, SPEED, IN_SPEED, IN_TORQUE, GEAR];
const ALLOWED_HEADERS: &str =
    "a vehicle cycle has time_s,speed_kmh[,gear]; a rig cycle has time_s,input_speed_rpm,input_torque_nm,gear";

impl DriveCycle {
    /// Parse CSV text. `source` names the text in error messages (a path, or `bundled:<name>`);
    /// the cycle's `name` is the file stem of `source`.
    pub fn parse(text: &str, source: &str) -> Result<DriveCycle, CycleError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut records = records(text);
        let Some((header_line, header)) = records.next() else {
            return Err(CycleError::new(
                CycleErrorKind::TooShort,
                source,
                format!("empty file: {ALLOWED_HEADERS}"),
            ));
        };
        let cols = Columns::from_header(&header, header_line, source)?;
        let mut rows: Vec<CycleRow> = Vec::new();
        for (line, rec) in records {
            // (A row with the wrong number of fields is reported as such first.)
            if rows.len() >= MAX_ROWS && rec.len() == cols.names.len() {
                return Err(CycleError::new(
                    CycleErrorKind::Value,
                    source,
                    format!("a cycle may have at most {MAX_ROWS} rows"),
                )
                .at_line(line));
            }
            let row = cols.row(&rec, line, rows.last(), source)?;
            rows.push(row);
        }
        if rows.len() < 2 {
            let line = rows.last().map_or(header_line, |r| r.line);
            return Err(CycleError::new(
                CycleErrorKind::TooShort,
                source,
                format!("a cycle needs at least 2 rows, found {}", rows.len()),
            )
            .at_line(line));
        }
        Ok(DriveCycle {
            name: stem(source),
            source: source.to_string(),
            kind: cols.kind,
            rows,
            has_gear: cols.gear.is_some(),
        })
    }

    /// Read and parse a cycle file (the only function of the cycle layer that touches the file
    /// system).
    pub fn load(path: impl AsRef<Path>) -> Result<DriveCycle, CycleError> {
        let path = path.as_ref();
        let source = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| {
            // A file that is read but is not UTF-8 text is malformed input, as a model file.
            let kind = match e.kind() {
                std::io::ErrorKind::InvalidData => CycleErrorKind::Header,
                _ => CycleErrorKind::Io,
            };
            CycleError::new(kind, &source, format!("cannot read the file: {e}"))
        })?;
        DriveCycle::parse(&text, &source)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Always false for a parsed cycle (at least two rows); here for API completeness.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// First time, s.
    pub fn start_time(&self) -> f64 {
        self.rows.first().map_or(0.0, |r| r.time)
    }

    /// Last time, s.
    pub fn end_time(&self) -> f64 {
        self.rows.last().map_or(0.0, |r| r.time)
    }

    /// Duration (last time − first time), s.
    pub fn duration(&self) -> f64 {
        self.end_time() - self.start_time()
    }

    /// Distance driven, m: trapezoidal integral of the vehicle speed (speed linear between rows,
    /// the same assumption the schedule makes). 0 for rig cycles.
    pub fn distance(&self) -> f64 {
        self.rows
            .windows(2)
            .map(|w| 0.5 * (w[0].vehicle_speed + w[1].vehicle_speed) * (w[1].time - w[0].time))
            .sum()
    }

    /// Highest vehicle speed, m/s.
    pub fn max_vehicle_speed(&self) -> f64 {
        self.rows.iter().map(|r| r.vehicle_speed).fold(0.0, f64::max)
    }
}

/// The columns of a cycle file, from its header: the kind of cycle and where each value is.
struct Columns {
    /// Header names, lower case.
    names: Vec<String>,
    /// Vehicle or rig cycle.
    kind: CycleKind,
    /// Index of `time_s`.
    time: usize,
    /// Index of `speed_kmh` (vehicle cycles).
    speed: Option<usize>,
    /// Index of `input_speed_rpm` (rig cycles).
    input_speed: Option<usize>,
    /// Index of `input_torque_nm` (rig cycles).
    input_torque: Option<usize>,
    /// Index of `gear`, if the file has one.
    gear: Option<usize>,
}

impl Columns {
    /// Known, unique column names; the kind they make; the columns that kind needs.
    fn from_header(header: &[&str], header_line: usize, source: &str) -> Result<Columns, CycleError> {
        let err =
            |allowed: String| CycleError::new(CycleErrorKind::Header, source, allowed).at_line(header_line);
        let names: Vec<String> = header.iter().map(|h| h.to_ascii_lowercase()).collect();
        let mut col = [None::<usize>; 5];
        for (i, n) in names.iter().enumerate() {
            match KNOWN.iter().position(|k| k == n) {
                None => {
                    return Err(err(format!("unknown column; {ALLOWED_HEADERS}"))
                        .at_column(if n.is_empty() { "(empty)" } else { n }));
                }
                Some(k) if col[k].is_some() => {
                    return Err(err("column appears twice".into()).at_column(n));
                }
                Some(k) => col[k] = Some(i),
            }
        }
        let [c_time, c_speed, c_in_speed, c_in_torque, c_gear] = col;
        let kind = if c_in_speed.is_some() || c_in_torque.is_some() {
            if c_speed.is_some() {
                return Err(err(format!(
                    "speed_kmh cannot be mixed with rig columns; {ALLOWED_HEADERS}"
                )));
            }
            CycleKind::Rig
        } else {
            CycleKind::Vehicle
        };
        let required: &[(&str, Option<usize>)] = match kind {
            CycleKind::Vehicle => &[(TIME, c_time), (SPEED, c_speed)],
            CycleKind::Rig => &[
                (TIME, c_time),
                (IN_SPEED, c_in_speed),
                (IN_TORQUE, c_in_torque),
                (GEAR, c_gear),
            ],
        };
        if let Some((name, _)) = required.iter().find(|(_, c)| c.is_none()) {
            return Err(err(format!("missing column {name}; {ALLOWED_HEADERS}")));
        }
        Ok(Columns {
            names,
            kind,
            time: c_time.unwrap_or(0),
            speed: c_speed,
            input_speed: c_in_speed,
            input_torque: c_in_torque,
            gear: c_gear,
        })
    }

    /// One record (file line `line`) as a row, after the row `prev`: field count, time, the
    /// kind's values in range, gear name.
    fn row(
        &self,
        rec: &[&str],
        line: usize,
        prev: Option<&CycleRow>,
        source: &str,
    ) -> Result<CycleRow, CycleError> {
        let err = |kind, allowed: String| CycleError::new(kind, source, allowed).at_line(line);
        let field = |c: usize| rec.get(c).copied().unwrap_or("");
        if rec.len() != self.names.len() {
            return Err(err(
                CycleErrorKind::Fields,
                format!(
                    "row has {} fields, the header has {}",
                    rec.len(),
                    self.names.len()
                ),
            ));
        }
        let num = |c: usize| -> Result<f64, CycleError> {
            match field(c).parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(err(CycleErrorKind::Value, "must be a finite number".into())
                    .at_value(&self.names[c], field(c))),
            }
        };
        let bounded = |c: usize, lo: f64, hi: f64, unit: &str| -> Result<f64, CycleError> {
            let v = num(c)?;
            if (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(
                    err(CycleErrorKind::Value, format!("must lie in [{lo}, {hi}] {unit}"))
                        .at_value(&self.names[c], field(c)),
                )
            }
        };
        let time = num(self.time)?;
        if !(0.0..=MAX_TIME_S).contains(&time) {
            return Err(err(
                CycleErrorKind::Time,
                format!("time must lie in [0, {MAX_TIME_S:e}] s"),
            )
            .at_value(TIME, field(self.time)));
        }
        if let Some(prev) = prev {
            if time < prev.time + MIN_TIME_STEP_S {
                return Err(err(
                    CycleErrorKind::Time,
                    format!(
                        "time must increase by at least {MIN_TIME_STEP_S} s per row (line {} has time_s = {})",
                        prev.line, prev.time
                    ),
                )
                .at_value(TIME, field(self.time)));
            }
        }
        let mut row = CycleRow {
            line,
            time,
            vehicle_speed: 0.0,
            input_speed: 0.0,
            input_torque: 0.0,
            gear: None,
        };
        match self.kind {
            CycleKind::Vehicle => {
                row.vehicle_speed =
                    bounded(self.speed.unwrap_or(0), 0.0, MAX_VEHICLE_SPEED_KMH, "km/h")? * KMH;
            }
            CycleKind::Rig => {
                row.input_speed =
                    bounded(self.input_speed.unwrap_or(0), 0.0, MAX_INPUT_SPEED_RPM, "rpm")? * RPM;
                row.input_torque = bounded(
                    self.input_torque.unwrap_or(0),
                    -MAX_INPUT_TORQUE_NM,
                    MAX_INPUT_TORQUE_NM,
                    "N m",
                )?;
            }
        }
        if let Some(c) = self.gear {
            let g = field(c);
            if g.is_empty() {
                return Err(
                    err(CycleErrorKind::Value, "gear name must not be empty".into()).at_value(GEAR, g)
                );
            }
            row.gear = Some(g.to_string());
        }
        Ok(row)
    }
}

/// The records of the text with their 1-based line numbers: blank lines and `#` comment lines
/// skipped, fields split at commas, trimmed, and unquoted (`"x"` → `x`; the cycle columns are
/// numbers and gear names, so quoted commas are not supported).
fn records(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, l)| {
        let t = l.trim();
        if t.is_empty() || t.starts_with('#') {
            return None;
        }
        let fields = t
            .split(',')
            .map(|f| {
                let f = f.trim();
                f.strip_prefix('"')
                    .and_then(|x| x.strip_suffix('"'))
                    .map_or(f, str::trim)
            })
            .collect();
        Some((i + 1, fields))
    })
}

/// File stem of a path-like source (`a/b/wltc.csv` → `wltc`, `bundled:wltc` → `wltc`).
fn stem(source: &str) -> String {
    let s = source.strip_prefix("bundled:").unwrap_or(source);
    Path::new(s)
        .file_stem()
        .map_or_else(|| s.to_string(), |x| x.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn fails(text: &str) -> CycleError {
        match DriveCycle::parse(text, "t.csv") {
            Ok(c) => panic!("expected an error, parsed {} rows", c.len()),
            Err(e) => e,
        }
    }

    #[test]
    fn vehicle_cycle_parses_with_units_and_lines() {
        let c =
            DriveCycle::parse("# comment\ntime_s,speed_kmh\n0,0\n\n1,36\n2,72.0\n", "dir/my.csv").unwrap();
        assert_eq!(c.kind, CycleKind::Vehicle);
        assert_eq!(c.name, "my");
        assert!(!c.has_gear);
        assert_eq!(c.rows.iter().map(|r| r.line).collect::<Vec<_>>(), vec![3, 5, 6]);
        assert_relative_eq!(c.rows[1].vehicle_speed, 10.0, epsilon = 1e-12);
        assert_relative_eq!(c.rows[2].vehicle_speed, 20.0, epsilon = 1e-12);
        // trapezoid: 5 + 15 m
        assert_relative_eq!(c.distance(), 20.0, epsilon = 1e-12);
        assert_relative_eq!(c.duration(), 2.0);
    }

    #[test]
    fn column_order_case_and_spaces_are_free() {
        let c = DriveCycle::parse("\u{feff}Gear , Speed_KMH,time_s\n 1 ,0, 0\n2,10,1\n", "x").unwrap();
        assert!(c.has_gear);
        assert_eq!(c.rows[1].gear.as_deref(), Some("2"));
        assert_relative_eq!(c.rows[1].vehicle_speed, 10.0 / 3.6, epsilon = 1e-12);
    }

    #[test]
    fn rig_cycle_parses() {
        let c = DriveCycle::parse(
            "time_s,input_speed_rpm,input_torque_nm,gear\n0,0,0,1\n10,3000,-50,R\n",
            "rig.csv",
        )
        .unwrap();
        assert_eq!(c.kind, CycleKind::Rig);
        assert_relative_eq!(
            c.rows[1].input_speed,
            crate::physics::units::rpm_to_rad_s(3000.0),
            epsilon = 1e-12
        );
        assert_relative_eq!(c.rows[1].input_torque, -50.0);
        assert_eq!(c.rows[1].gear.as_deref(), Some("R"));
        assert_relative_eq!(c.distance(), 0.0);
    }

    #[test]
    fn first_time_may_be_positive() {
        let c = DriveCycle::parse("time_s,speed_kmh\n5,0\n6,1\n", "x").unwrap();
        assert_relative_eq!(c.start_time(), 5.0);
        assert_relative_eq!(c.duration(), 1.0);
    }

    #[test]
    fn header_errors_name_the_line_and_column() {
        let e = fails("time_s,speed_mph\n0,0\n1,1\n");
        assert_eq!(
            (e.kind, e.line, e.column.as_deref()),
            (CycleErrorKind::Header, Some(1), Some("speed_mph"))
        );
        let e = fails("# c\ntime_s\n0\n1\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Header, Some(2)));
        assert!(e.allowed.contains("speed_kmh"), "{e}");
        let e = fails("time_s,input_speed_rpm,input_torque_nm\n0,0,0\n1,1,1\n");
        assert!(e.allowed.contains("missing column gear"), "{e}");
        let e = fails("time_s,speed_kmh,time_s\n0,0,0\n1,1,1\n");
        assert_eq!(e.column.as_deref(), Some("time_s"));
        let e = fails("time_s,speed_kmh,input_torque_nm\n0,0,0\n1,1,1\n");
        assert_eq!(e.kind, CycleErrorKind::Header);
        let e = fails("");
        assert_eq!(e.kind, CycleErrorKind::TooShort);
    }

    #[test]
    fn value_errors_name_the_line() {
        let e = fails("time_s,speed_kmh\n0,0\n1,abc\n2,3\n");
        assert_eq!(
            (e.kind, e.line, e.column.as_deref(), e.value.as_deref()),
            (CycleErrorKind::Value, Some(3), Some("speed_kmh"), Some("abc"))
        );
        let e = fails("time_s,speed_kmh\n0,0\n1,1\n2,NaN\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Value, Some(4)));
        let e = fails("time_s,speed_kmh\n0,0\n1,inf\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Value, Some(3)));
        let e = fails("time_s,speed_kmh\n0,0\n1,-0.5\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Value, Some(3)));
        assert!(
            e.to_string()
                .starts_with("t.csv, line 3: column speed_kmh = \"-0.5\""),
            "{e}"
        );
        let e = fails("time_s,speed_kmh\n0,0\n1,1,1\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Fields, Some(3)));
        let e = fails("time_s,speed_kmh,gear\n0,0,1\n1,1,\n");
        assert_eq!(
            (e.kind, e.line, e.column.as_deref()),
            (CycleErrorKind::Value, Some(3), Some("gear"))
        );
        let e = fails("time_s,input_speed_rpm,input_torque_nm,gear\n0,0,0,1\n1,-1,0,1\n");
        assert_eq!(
            (e.kind, e.line, e.column.as_deref()),
            (CycleErrorKind::Value, Some(3), Some("input_speed_rpm"))
        );
    }

    #[test]
    fn time_errors_name_the_line() {
        let e = fails("time_s,speed_kmh\n0,0\n1,1\n1,2\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Time, Some(4)));
        assert!(e.allowed.contains("line 3"), "{e}");
        let e = fails("time_s,speed_kmh\n0,0\n2,1\n1.5,2\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Time, Some(4)));
        let e = fails("time_s,speed_kmh\n-1,0\n1,1\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::Time, Some(2)));
    }

    #[test]
    fn too_few_rows() {
        let e = fails("time_s,speed_kmh\n0,0\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::TooShort, Some(2)));
        let e = fails("time_s,speed_kmh\n");
        assert_eq!((e.kind, e.line), (CycleErrorKind::TooShort, Some(1)));
    }

    #[test]
    fn load_reports_io_errors() {
        let e = DriveCycle::load("/nonexistent/dir/cycle.csv").unwrap_err();
        assert_eq!(e.kind, CycleErrorKind::Io);
        assert!(e.to_string().contains("/nonexistent/dir/cycle.csv"));
    }
}
