//! `timeseries.csv` as one table: the run builds it ([`super::run::timeseries`]), writes it
//! ([`Timeseries::to_csv`]), and `report DIR`, the plots and Python's `read_run` read the file
//! back into the same table ([`Timeseries::parse`]).
//!
//! Every column but `gear` holds numbers; an empty field is "no value" (NaN in the table,
//! written empty). A number is written with Rust's shortest round-trip form, so a table written
//! and read back holds the same bits.

use std::fmt::Write as _;
use std::path::Path;

use super::plots::error::PlotError;

/// The one text column of `timeseries.csv` (the gear-state name).
pub const TEXT_COLUMN: &str = "gear";

/// A column's values.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Numbers (NaN = no value, an empty field).
    Num(Vec<f64>),
    /// Text (the gear-state names).
    Text(Vec<String>),
}

/// One named column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Header name (`time_s`, `temp_<node>_c`, `loss_<source>_<item>_w`, …; docs/outputs.md).
    pub name: String,
    /// One value per row.
    pub values: Values,
}

/// The rows of `timeseries.csv`, column by column, in the file's column order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timeseries {
    /// The columns in header order.
    pub columns: Vec<Column>,
}

impl Timeseries {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| match &c.values {
            Values::Num(v) => v.len(),
            Values::Text(v) => v.len(),
        })
    }

    /// Append a numeric column.
    pub fn push_num(&mut self, name: impl Into<String>, values: Vec<f64>) {
        self.columns.push(Column {
            name: name.into(),
            values: Values::Num(values),
        });
    }

    /// Append a text column.
    pub fn push_text(&mut self, name: impl Into<String>, values: Vec<String>) {
        self.columns.push(Column {
            name: name.into(),
            values: Values::Text(values),
        });
    }

    /// Position of the column named `name`.
    pub fn position(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c.name == name)
    }

    /// The numbers of column `name` (None when there is no such numeric column).
    pub fn num(&self, name: &str) -> Option<&[f64]> {
        match &self.columns[self.position(name)?].values {
            Values::Num(v) => Some(v),
            Values::Text(_) => None,
        }
    }

    /// The text of column `name` (None when there is no such text column).
    pub fn text(&self, name: &str) -> Option<&[String]> {
        match &self.columns[self.position(name)?].values {
            Values::Text(v) => Some(v),
            Values::Num(_) => None,
        }
    }

    /// The CSV text: the header, then one line per row; a finite number in its shortest
    /// round-trip form, no value as an empty field.
    pub fn to_csv(&self) -> String {
        let n = self.rows();
        let mut s = String::with_capacity(64 + n * 16 * self.columns.len());
        let names: Vec<&str> = self.columns.iter().map(|c| c.name.as_str()).collect();
        s.push_str(&names.join(","));
        s.push('\n');
        for k in 0..n {
            for (i, c) in self.columns.iter().enumerate() {
                if i > 0 {
                    s.push(',');
                }
                match &c.values {
                    Values::Num(v) if v[k].is_finite() => {
                        let _ = write!(s, "{}", v[k]);
                    }
                    Values::Num(_) => {}
                    Values::Text(v) => s.push_str(&v[k]),
                }
            }
            s.push('\n');
        }
        s
    }

    /// Read `timeseries.csv` at `path`; errors name the file (and the line and column).
    pub fn read(path: &Path) -> Result<Timeseries, PlotError> {
        let text = std::fs::read(path).map_err(|e| PlotError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        Timeseries::parse(&text, path)
    }

    /// Parse CSV bytes (`path` names them in errors): every column but [`TEXT_COLUMN`] holds
    /// finite numbers or empty fields; `NaN`, `inf` and anything that is not a number is an
    /// error naming line and column (geartherm never writes them).
    pub fn parse(bytes: &[u8], path: &Path) -> Result<Timeseries, PlotError> {
        let csv_err = |msg: String| PlotError::Csv {
            path: path.to_path_buf(),
            msg,
        };
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .from_reader(bytes);
        let headers = rdr.headers().map_err(|e| csv_err(e.to_string()))?.clone();
        let mut t = Timeseries::default();
        for h in headers.iter() {
            if h == TEXT_COLUMN {
                t.push_text(h, Vec::new());
            } else {
                t.push_num(h, Vec::new());
            }
        }
        let mut record = csv::StringRecord::new();
        let mut line = 1u64;
        loop {
            match rdr.read_record(&mut record) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => return Err(csv_err(e.to_string())),
            }
            line = record.position().map(|p| p.line()).unwrap_or(line + 1);
            for (c, field) in t.columns.iter_mut().zip(record.iter()) {
                match &mut c.values {
                    Values::Text(v) => v.push(field.to_string()),
                    Values::Num(v) => v.push(parse_num(field).ok_or_else(|| {
                        csv_err(format!(
                            "line {line}, column `{}`: `{field}` is not a finite number",
                            c.name
                        ))
                    })?),
                }
            }
        }
        Ok(t)
    }
}

/// A CSV number: empty is "no value" (NaN); anything that is not a finite number is `None`.
pub fn parse_num(field: &str) -> Option<f64> {
    let f = field.trim();
    if f.is_empty() {
        return Some(f64::NAN);
    }
    f.parse::<f64>().ok().filter(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_written_and_read_back_holds_the_same_bits() {
        let mut t = Timeseries::default();
        t.push_num("time_s", vec![0.0, 0.1, 1e-7, 12345.678901234567]);
        t.push_text("gear", vec!["1".into(), "".into(), "R".into(), "6".into()]);
        t.push_num("efficiency", vec![f64::NAN, -0.0, 0.1 + 0.2, 1.0]);
        let text = t.to_csv();
        assert_eq!(text.lines().next(), Some("time_s,gear,efficiency"));
        assert_eq!(text.lines().nth(1), Some("0,1,"));
        let back = Timeseries::parse(text.as_bytes(), Path::new("t.csv")).unwrap();
        assert_eq!(back.rows(), 4);
        for (a, b) in t.columns.iter().zip(&back.columns) {
            assert_eq!(a.name, b.name);
            match (&a.values, &b.values) {
                (Values::Num(x), Values::Num(y)) => {
                    let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(x), bits(y), "{}", a.name);
                }
                (Values::Text(x), Values::Text(y)) => assert_eq!(x, y),
                _ => panic!("column kinds differ"),
            }
        }
        assert_eq!(back.to_csv(), text);
        let err = Timeseries::parse(b"time_s,gear\n1,a\nx,b\n", Path::new("t.csv")).unwrap_err();
        assert!(err.to_string().contains("line 3, column `time_s`"), "{err}");
    }
}
