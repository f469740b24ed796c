//! Outputs of an uncertainty run (`geartherm uq`): the summary (`uq.json`) and the percentile
//! bands over time (`bands.csv`, `bands.parquet`). The same types write and read each file
//! ([`UqSummary`] with serde; [`Bands`] with [`write_bands_csv`] / [`read_bands_csv`]).
//! Nothing non-finite is written: every writer checks first and names the value.
//!
//! Band columns follow the naming rule of docs/outputs.md: `time_s`, then per series and
//! percentile `<quantity>_p<PP>_<name>_<unit>`, e.g. `temp_p05_sump_c`, `temp_p50_sump_c`,
//! `temp_p95_sump_c` (quantity and unit from the series' unit: °C → `temp`/`c`, W → `loss`/`w`,
//! J → `energy`/`j`). `PP` is the percentile with at least two integer digits and its decimals
//! if any (`p05`, `p50`, `p97.5`).

use serde::{Deserialize, Serialize};

/// One uncertain input as run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UqInput {
    /// Key path in the model file (`lubrication.oil_level_mm`).
    pub path: String,
    /// The distribution, in words (`normal(mean 40, sd 2)`).
    pub distribution: String,
    /// The distribution's mean.
    pub mean: f64,
    /// Its 5th and 95th percentiles.
    pub p05: f64,
    /// Its 95th percentile.
    pub p95: f64,
}

/// The probability that a quantity exceeds a limit, with its interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExceedanceRow {
    /// What is compared (`temp_max`: the maximum over the cycle; `temp_final`).
    pub quantity: String,
    /// The node.
    pub node: String,
    /// The limit, °C.
    pub limit_c: f64,
    /// Samples above the limit.
    pub count: usize,
    /// Samples counted (finished ones).
    pub n: usize,
    /// count / n.
    pub probability: f64,
    /// Lower end of the interval.
    pub lo: f64,
    /// Upper end of the interval.
    pub hi: f64,
    /// Confidence of the interval (0.95).
    pub confidence: f64,
    /// The interval's method (`wilson`).
    pub interval: String,
}

/// First-order and total Sobol' indices of one input for one output, with bootstrap intervals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SobolRow {
    /// Output column (`temp_max_sump_c`, `energy_total_j`).
    pub output: String,
    /// Input key path.
    pub input: String,
    /// First-order index S_i.
    pub first: f64,
    /// Lower end of its interval.
    pub first_lo: f64,
    /// Upper end of its interval.
    pub first_hi: f64,
    /// Total index S_Ti.
    pub total: f64,
    /// Lower end of its interval.
    pub total_lo: f64,
    /// Upper end of its interval.
    pub total_hi: f64,
}

/// Percentiles of the energy lost by one source over the cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnergyBand {
    /// Source (`churning`, …, `total`).
    pub source: String,
    /// (percentile, energy in J), in the summary's percentile order.
    pub p: Vec<(f64, f64)>,
}

/// Percentiles of a scalar output (a study-table column such as `temp_max_sump_c`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScalarBand {
    /// Column name with its unit (`temp_max_sump_c`, `cycle_efficiency`).
    pub name: String,
    /// Sample mean.
    pub mean: f64,
    /// (percentile, value).
    pub p: Vec<(f64, f64)>,
}

/// `uq.json`: what was sampled and what came out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UqSummary {
    /// Model name.
    pub model: String,
    /// The cycle, or the steady operating point's label.
    pub cycle_or_point: String,
    /// Model runs asked for.
    pub samples: usize,
    /// `sobol-qmc` (percentiles and exceedance from scrambled Sobol' points) or `saltelli`
    /// (the Saltelli design, N (d + 2) runs, indices as well).
    pub method: String,
    /// Seed of the scrambling and of the bootstrap.
    pub seed: u64,
    /// The uncertain inputs.
    pub inputs: Vec<UqInput>,
    /// The percentiles reported (percent).
    pub percentiles: Vec<f64>,
    /// Exceedance probabilities of the asked limits.
    pub exceedance: Vec<ExceedanceRow>,
    /// Sobol' indices (empty without the Saltelli design).
    pub sobol: Vec<SobolRow>,
    /// Energy per source.
    pub energy: Vec<EnergyBand>,
    /// Other scalar outputs.
    pub scalars: Vec<ScalarBand>,
    /// Runs that failed (left out of every estimate).
    pub failed_samples: usize,
    /// Notes on what the numbers mean and do not mean.
    pub notes: Vec<String>,
}

/// The first non-finite (name, value) of a list, as an error naming it.
fn first_bad(items: impl IntoIterator<Item = (String, f64)>) -> Result<(), String> {
    match items.into_iter().find(|(_, v)| !v.is_finite()) {
        Some((name, v)) => Err(format!("{name} is {v}: not written")),
        None => Ok(()),
    }
}

impl UqSummary {
    /// The first non-finite number of the summary, named, or `Ok`.
    pub fn check_finite(&self) -> Result<(), String> {
        let mut all: Vec<(String, f64)> = Vec::new();
        for i in &self.inputs {
            for (k, v) in [("mean", i.mean), ("p05", i.p05), ("p95", i.p95)] {
                all.push((format!("inputs[{}].{k}", i.path), v));
            }
        }
        for (k, p) in self.percentiles.iter().enumerate() {
            all.push((format!("percentiles[{k}]"), *p));
        }
        for e in &self.exceedance {
            let at = format!("exceedance[{} {}]", e.quantity, e.node);
            for (k, v) in [
                ("limit_c", e.limit_c),
                ("probability", e.probability),
                ("lo", e.lo),
                ("hi", e.hi),
                ("confidence", e.confidence),
            ] {
                all.push((format!("{at}.{k}"), v));
            }
        }
        for s in &self.sobol {
            let at = format!("sobol[{} / {}]", s.output, s.input);
            for (k, v) in [
                ("first", s.first),
                ("first_lo", s.first_lo),
                ("first_hi", s.first_hi),
                ("total", s.total),
                ("total_lo", s.total_lo),
                ("total_hi", s.total_hi),
            ] {
                all.push((format!("{at}.{k}"), v));
            }
        }
        for e in &self.energy {
            for (p, v) in &e.p {
                all.push((format!("energy[{}] p{p}", e.source), *v));
                all.push((format!("energy[{}] percentile", e.source), *p));
            }
        }
        for s in &self.scalars {
            all.push((format!("scalars[{}].mean", s.name), s.mean));
            for (p, v) in &s.p {
                all.push((format!("scalars[{}] p{p}", s.name), *v));
                all.push((format!("scalars[{}] percentile", s.name), *p));
            }
        }
        first_bad(all)
    }

    /// `uq.json` text (pretty), after [`UqSummary::check_finite`].
    pub fn to_json(&self) -> Result<String, String> {
        self.check_finite()?;
        serde_json::to_string_pretty(self).map_err(|e| format!("cannot serialise uq.json: {e}"))
    }

    /// Read `uq.json` text.
    pub fn from_json(text: &str) -> Result<UqSummary, String> {
        serde_json::from_str(text).map_err(|e| format!("uq.json: {e}"))
    }
}

/// Percentile bands of one series over time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandSeries {
    /// Node (or source) name.
    pub name: String,
    /// Unit: `°C`, `W` or `J`.
    pub unit: String,
    /// `[percentile][time]`, in the order of [`Bands::percentiles`].
    pub values: Vec<Vec<f64>>,
}

/// Percentile bands over time (`bands.csv`, `bands.parquet`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bands {
    /// Output times, s.
    pub time_s: Vec<f64>,
    /// Percentiles (percent, increasing).
    pub percentiles: Vec<f64>,
    /// The series.
    pub series: Vec<BandSeries>,
}

/// Column quantity and unit suffix of a series unit.
fn unit_parts(unit: &str) -> Option<(&'static str, &'static str)> {
    match unit {
        "°C" => Some(("temp", "c")),
        "W" => Some(("loss", "w")),
        "J" => Some(("energy", "j")),
        _ => None,
    }
}

/// The unit of a column's quantity and suffix.
fn unit_of(quantity: &str, suffix: &str) -> Option<&'static str> {
    match (quantity, suffix) {
        ("temp", "c") => Some("°C"),
        ("loss", "w") => Some("W"),
        ("energy", "j") => Some("J"),
        _ => None,
    }
}

/// Percentile label: `05`, `50`, `97.5` (two integer digits at least).
pub fn percentile_label(p: f64) -> String {
    let s = format!("{p}");
    if p < 10.0 {
        format!("0{s}")
    } else {
        s
    }
}

/// Column name of a series at a percentile (`temp_p05_sump_c`); `None` for a unit without a
/// column rule.
pub fn band_column(name: &str, unit: &str, p: f64) -> Option<String> {
    let (q, u) = unit_parts(unit)?;
    Some(format!("{q}_p{}_{name}_{u}", percentile_label(p)))
}

/// Parse a band column into (name, unit, percentile).
fn parse_column(col: &str) -> Option<(String, &'static str, f64)> {
    let (quantity, rest) = col.split_once("_p")?;
    let (label, rest) = rest.split_once('_')?;
    let (name, suffix) = rest.rsplit_once('_')?;
    let unit = unit_of(quantity, suffix)?;
    let p: f64 = label.parse().ok()?;
    (!name.is_empty() && p.is_finite()).then(|| (name.to_string(), unit, p))
}

impl Bands {
    /// Shapes agree (every series has one row per percentile, one value per time), units have a
    /// column rule, percentiles increase within (0, 100), every number is finite.
    pub fn check(&self) -> Result<(), String> {
        let nt = self.time_s.len();
        first_bad(
            self.time_s
                .iter()
                .enumerate()
                .map(|(i, t)| (format!("time_s[{i}]"), *t)),
        )?;
        for (k, p) in self.percentiles.iter().enumerate() {
            if !(*p > 0.0 && *p < 100.0) || (k > 0 && *p <= self.percentiles[k - 1]) {
                return Err(format!(
                    "percentile {p}: percentiles must increase within (0, 100)"
                ));
            }
        }
        for s in &self.series {
            if unit_parts(&s.unit).is_none() {
                return Err(format!(
                    "series {}: unit {:?} has no column rule (°C, W, J)",
                    s.name, s.unit
                ));
            }
            if s.name.is_empty() || s.name.contains(',') {
                return Err(format!("series name {:?}: not a plain name", s.name));
            }
            if s.values.len() != self.percentiles.len() {
                return Err(format!(
                    "series {}: {} percentile rows for {} percentiles",
                    s.name,
                    s.values.len(),
                    self.percentiles.len()
                ));
            }
            for (k, row) in s.values.iter().enumerate() {
                let p = self.percentiles[k];
                if row.len() != nt {
                    return Err(format!(
                        "series {} p{p}: {} values for {nt} times",
                        s.name,
                        row.len()
                    ));
                }
                if let Some(i) = row.iter().position(|v| !v.is_finite()) {
                    return Err(format!(
                        "series {} p{p} at time {} s is {}: not written",
                        s.name, self.time_s[i], row[i]
                    ));
                }
            }
        }
        Ok(())
    }

    /// Column names after `time_s`, series-major then percentile.
    pub fn columns(&self) -> Vec<String> {
        self.series
            .iter()
            .flat_map(|s| {
                self.percentiles
                    .iter()
                    .filter_map(move |&p| band_column(&s.name, &s.unit, p))
            })
            .collect()
    }

    /// The columns' values in [`Bands::columns`] order.
    fn column_values(&self) -> Vec<&[f64]> {
        self.series
            .iter()
            .flat_map(|s| s.values.iter().map(Vec::as_slice))
            .collect()
    }
}

/// `bands.csv`: `time_s`, then every series' percentiles (module docs); checked first.
pub fn write_bands_csv(b: &Bands) -> Result<String, String> {
    b.check()?;
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["time_s".to_string()];
    header.extend(b.columns());
    let io = |e: csv::Error| format!("bands.csv: {e}");
    w.write_record(&header).map_err(io)?;
    let cols = b.column_values();
    for (i, t) in b.time_s.iter().enumerate() {
        let mut rec = vec![t.to_string()];
        rec.extend(cols.iter().map(|c| c[i].to_string()));
        w.write_record(&rec).map_err(io)?;
    }
    let bytes = w.into_inner().map_err(|e| format!("bands.csv: {e}"))?;
    String::from_utf8(bytes).map_err(|e| format!("bands.csv: {e}"))
}

/// Read `bands.csv` text back into [`Bands`] (the writer's column rule; every series must have
/// the same percentiles in the same order).
pub fn read_bands_csv(text: &str) -> Result<Bands, String> {
    let mut r = csv::ReaderBuilder::new().from_reader(text.as_bytes());
    let header: Vec<String> = r
        .headers()
        .map_err(|e| format!("bands.csv: {e}"))?
        .iter()
        .map(String::from)
        .collect();
    if header.first().map(String::as_str) != Some("time_s") {
        return Err("bands.csv: the first column must be time_s".into());
    }
    let mut bands = Bands {
        time_s: Vec::new(),
        percentiles: Vec::new(),
        series: Vec::new(),
    };
    // (series index, percentile index) of every column after time_s.
    let mut slot = Vec::new();
    for col in &header[1..] {
        let (name, unit, p) =
            parse_column(col).ok_or_else(|| format!("bands.csv: column {col:?} is not a band column"))?;
        let si = match bands.series.iter().position(|s| s.name == name && s.unit == unit) {
            Some(i) => i,
            None => {
                bands.series.push(BandSeries {
                    name,
                    unit: unit.to_string(),
                    values: Vec::new(),
                });
                bands.series.len() - 1
            }
        };
        let pi = bands.series[si].values.len();
        if si == 0 {
            bands.percentiles.push(p);
        } else if bands.percentiles.get(pi) != Some(&p) {
            return Err(format!(
                "bands.csv: column {col:?}: every series needs the percentiles of the first"
            ));
        }
        bands.series[si].values.push(Vec::new());
        slot.push((si, pi));
    }
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| format!("bands.csv: {e}"))?;
        let num = |k: usize| -> Result<f64, String> {
            let f = rec.get(k).unwrap_or("");
            f.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    format!(
                        "bands.csv line {}: column {}: {f:?} is not a finite number",
                        line + 2,
                        header[k]
                    )
                })
        };
        bands.time_s.push(num(0)?);
        for (k, &(si, pi)) in slot.iter().enumerate() {
            bands.series[si].values[pi].push(num(k + 1)?);
        }
    }
    bands.check().map_err(|e| format!("bands.csv: {e}"))?;
    Ok(bands)
}

/// `bands.parquet`: the columns of `bands.csv`, DOUBLE, required, one row group.
pub fn bands_parquet(b: &Bands) -> Result<Vec<u8>, String> {
    b.check()?;
    let mut names = vec!["time_s".to_string()];
    names.extend(b.columns());
    let mut cols: Vec<&[f64]> = vec![&b.time_s];
    cols.extend(b.column_values());
    doubles_parquet("bands", &names, &cols).map_err(|e| format!("bands.parquet: {e}"))
}

fn doubles_parquet(schema: &str, names: &[String], cols: &[&[f64]]) -> parquet::errors::Result<Vec<u8>> {
    use parquet::basic::{Repetition, Type as Physical};
    use parquet::data_type::DoubleType;
    use parquet::file::properties::WriterProperties;
    use parquet::file::writer::SerializedFileWriter;
    use parquet::schema::types::Type;
    use std::sync::Arc;

    let fields = names
        .iter()
        .map(|n| {
            Type::primitive_type_builder(n, Physical::DOUBLE)
                .with_repetition(Repetition::REQUIRED)
                .build()
                .map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let schema = Arc::new(Type::group_type_builder(schema).with_fields(fields).build()?);
    let props = Arc::new(WriterProperties::builder().build());
    let mut w = SerializedFileWriter::new(Vec::new(), schema, props)?;
    let mut rg = w.next_row_group()?;
    let mut c = 0;
    while let Some(mut col) = rg.next_column()? {
        col.typed::<DoubleType>().write_batch(cols[c], None, None)?;
        col.close()?;
        c += 1;
    }
    rg.close()?;
    w.into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn sample_bands() -> Bands {
        Bands {
            time_s: vec![0.0, 0.5, 1.0 / 3.0 + 10.0],
            percentiles: vec![5.0, 50.0, 97.5],
            series: vec![
                BandSeries {
                    name: "sump".into(),
                    unit: "°C".into(),
                    values: vec![
                        vec![20.0, 21.5, 30.1],
                        vec![20.0, 22.0, 31.0],
                        vec![20.0, 22.5, 33.3],
                    ],
                },
                BandSeries {
                    name: "p_2 wall".into(),
                    unit: "°C".into(),
                    values: vec![
                        vec![20.0, 20.1, 25.0],
                        vec![20.0, 20.2, 26.0],
                        vec![20.0, 20.3, 1.0 / 7.0],
                    ],
                },
            ],
        }
    }

    #[test]
    fn bands_csv_round_trips_exactly() {
        let b = sample_bands();
        let text = write_bands_csv(&b).unwrap();
        let head = text.lines().next().unwrap();
        assert_eq!(
            head,
            "time_s,temp_p05_sump_c,temp_p50_sump_c,temp_p97.5_sump_c,temp_p05_p_2 wall_c,temp_p50_p_2 wall_c,temp_p97.5_p_2 wall_c"
        );
        assert_eq!(read_bands_csv(&text).unwrap(), b);
    }

    #[test]
    fn non_finite_or_ragged_bands_are_refused() {
        let mut b = sample_bands();
        b.series[1].values[2][1] = f64::NAN;
        let e = write_bands_csv(&b).unwrap_err();
        assert!(e.contains("series p_2 wall p97.5 at time 0.5 s is NaN"), "{e}");
        let mut b = sample_bands();
        b.series[0].values[0].pop();
        assert!(write_bands_csv(&b).unwrap_err().contains("2 values for 3 times"));
        let e = read_bands_csv("time_s,temp_p05_sump_c\n0,NaN\n").unwrap_err();
        assert!(e.contains("line 2"), "{e}");
        let e = read_bands_csv("time_s,temp_p05_sump_c,temp_p50_oil_c\n0,1,2\n").unwrap_err();
        assert!(e.contains("percentiles of the first"), "{e}");
    }

    #[test]
    fn bands_parquet_holds_the_csv_columns() {
        use parquet::file::reader::{FileReader, SerializedFileReader};
        let b = sample_bands();
        let pq = bands_parquet(&b).unwrap();
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("b.parquet"), pq).unwrap();
        let f = std::fs::File::open(d.path().join("b.parquet")).unwrap();
        let r = SerializedFileReader::new(f).unwrap();
        assert_eq!(r.metadata().file_metadata().num_rows(), 3);
        let names: Vec<String> = r
            .metadata()
            .file_metadata()
            .schema_descr()
            .columns()
            .iter()
            .map(|c| c.name().to_string())
            .collect();
        let mut want = vec!["time_s".to_string()];
        want.extend(b.columns());
        assert_eq!(names, want);
        let last = r.get_row_iter(None).unwrap().last().unwrap().unwrap().to_string();
        assert!(
            last.contains(&format!("temp_p97.5_p_2 wall_c: {}", 1.0 / 7.0)),
            "{last}"
        );
    }

    pub(crate) fn sample_summary() -> UqSummary {
        UqSummary {
            model: "AT6".into(),
            cycle_or_point: "wltc".into(),
            samples: 1000,
            method: "saltelli".into(),
            seed: 42,
            inputs: vec![UqInput {
                path: "lubrication.oil_level_mm".into(),
                distribution: "normal(mean 40, sd 2)".into(),
                mean: 40.0,
                p05: 36.7,
                p95: 43.3,
            }],
            percentiles: vec![5.0, 50.0, 95.0],
            exceedance: vec![ExceedanceRow {
                quantity: "temp_max".into(),
                node: "sump".into(),
                limit_c: 120.0,
                count: 3,
                n: 1000,
                probability: 0.003,
                lo: 0.001,
                hi: 0.0088,
                confidence: 0.95,
                interval: "wilson".into(),
            }],
            sobol: vec![SobolRow {
                output: "temp_max_sump_c".into(),
                input: "lubrication.oil_level_mm".into(),
                first: 0.4,
                first_lo: 0.35,
                first_hi: 0.45,
                total: 0.5,
                total_lo: 0.45,
                total_hi: 0.55,
            }],
            energy: vec![EnergyBand {
                source: "churning".into(),
                p: vec![(5.0, 1.0e5), (50.0, 1.2e5), (95.0, 1.0 / 3.0)],
            }],
            scalars: vec![ScalarBand {
                name: "temp_max_sump_c".into(),
                mean: 98.0,
                p: vec![(5.0, 90.0), (50.0, 98.0), (95.0, 107.0)],
            }],
            failed_samples: 0,
            notes: vec!["bands are conditional on the input distributions".into()],
        }
    }

    #[test]
    fn summary_json_round_trips_and_refuses_nan() {
        let s = sample_summary();
        let text = s.to_json().unwrap();
        assert_eq!(UqSummary::from_json(&text).unwrap(), s);
        let mut bad = s.clone();
        bad.sobol[0].total_hi = f64::INFINITY;
        let e = bad.to_json().unwrap_err();
        assert!(
            e.contains("sobol[temp_max_sump_c / lubrication.oil_level_mm].total_hi is inf"),
            "{e}"
        );
    }
}
