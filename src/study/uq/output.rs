//! An uncertainty study's outputs from its journaled rows: `uq.json` ([`UqSummary`]),
//! `bands.csv` / `bands.parquet` ([`Bands`], run jobs), the sample table `study.csv` /
//! `study.parquet` (one row per case: its sampled inputs and scalar outputs, as `geartherm
//! study` writes it), and with `report` the figures `bands.png` and `sensitivity.png`. The data
//! files are written together, all or nothing; the figures after them, all or nothing.

use std::path::Path;

use crate::job::JobError;
use crate::report::files::write_all_atomic;
use crate::report::study::{study_csv, study_parquet, CaseRow, Table};
use crate::report::uq::{
    bands_parquet, write_bands_csv, BandSeries, Bands, EnergyBand, ExceedanceRow, ScalarBand, SobolRow,
    UqInput, UqSummary,
};
use crate::study::runner;

use super::estimate::{estimate, Estimates, ScalarStats};
use super::plan::Design;
use super::run::{Uq, UqJob};

/// A finished uncertainty study.
pub struct UqOutcome {
    /// `uq.json`'s contents.
    pub summary: UqSummary,
    /// The bands (run jobs).
    pub bands: Option<Bands>,
    /// The estimates behind both.
    pub estimates: Estimates,
    /// The sample table.
    pub table: Table,
    /// Files written, in order (empty when nothing was written).
    pub files: Vec<String>,
}

fn pairs(ps: &[f64], s: &ScalarStats) -> Vec<(f64, f64)> {
    ps.iter().copied().zip(s.percentiles.iter().copied()).collect()
}

fn notes(uq: &Uq, e: &Estimates) -> Vec<String> {
    let mut n = vec![
        "Input uncertainty only: each band is the spread of the outputs over the sampled inputs. The spread \
         between loss models (model form) is not a probability and is not part of it."
            .to_string(),
        "Bands are percentiles across the samples at each time, not the trajectory of any one sample.".into(),
    ];
    let (_, invalid, failed) = e.counts;
    if invalid + failed > 0 {
        n.push(format!(
            "{invalid} samples refused by the model and {failed} failed were left out: the estimates describe the \
             inputs the model accepts and solves."
        ));
    }
    if let Some(m) = &e.sobol_missing {
        n.push(format!("Sobol indices not computed: {m}"));
    }
    for i in uq.inputs.iter().filter(|i| !i.note.is_empty()) {
        n.push(format!("{}: {} ({})", i.path, i.note, i.distribution));
    }
    n
}

/// The summary and the bands of the estimates.
pub fn summarise(uq: &Uq, e: &Estimates) -> (UqSummary, Option<Bands>) {
    let ps = &uq.options.percentiles;
    let steady = matches!(uq.job_kind, UqJob::Steady(_));
    let exceedance = e
        .exceedance
        .iter()
        .map(|x| ExceedanceRow {
            quantity: if steady { "temp".into() } else { "temp_max".into() },
            node: x.node.clone(),
            limit_c: x.limit_c,
            count: x.count,
            n: x.n,
            probability: x.probability.value,
            lo: x.probability.lo,
            hi: x.probability.hi,
            confidence: uq.options.confidence,
            interval: "wilson".into(),
        })
        .collect();
    let sobol = e
        .sobol
        .iter()
        .flat_map(|s| {
            uq.inputs.iter().enumerate().map(move |(i, inp)| SobolRow {
                output: s.output.clone(),
                input: inp.path.clone(),
                first: s.indices.first[i].value,
                first_lo: s.indices.first[i].lo,
                first_hi: s.indices.first[i].hi,
                total: s.indices.total[i].value,
                total_lo: s.indices.total[i].lo,
                total_hi: s.indices.total[i].hi,
            })
        })
        .collect();
    let energy = e
        .energy
        .iter()
        .map(|s| EnergyBand {
            source: s
                .name
                .trim_start_matches("energy_")
                .trim_end_matches("_j")
                .to_string(),
            p: pairs(ps, s),
        })
        .collect();
    let scalars = e
        .scalars
        .iter()
        .map(|s| ScalarBand {
            name: s.name.clone(),
            mean: s.mean,
            p: pairs(ps, s),
        })
        .collect();
    let summary = UqSummary {
        model: uq.model_name.clone(),
        cycle_or_point: uq.job().label(),
        samples: uq.study.samples.len(),
        method: match uq.design {
            Design::Qmc { .. } => "sobol-qmc".into(),
            Design::Saltelli { .. } => "saltelli".into(),
        },
        seed: uq.seed,
        inputs: uq
            .inputs
            .iter()
            .map(|i| UqInput {
                path: i.column.clone(),
                distribution: i.distribution.clone(),
                mean: i.mean,
                p05: i.p05,
                p95: i.p95,
            })
            .collect(),
        percentiles: ps.clone(),
        exceedance,
        sobol,
        energy,
        scalars,
        failed_samples: e.counts.1 + e.counts.2,
        notes: notes(uq, e),
    };
    let bands = (!e.bands.is_empty()).then(|| Bands {
        time_s: uq.times_s.clone(),
        percentiles: ps.clone(),
        series: e
            .bands
            .iter()
            .map(|b| {
                let (name, unit) = match b.name.strip_prefix("temp_") {
                    Some(n) => (n.trim_end_matches("_c"), "°C"),
                    None => (b.name.trim_start_matches("energy_").trim_end_matches("_j"), "J"),
                };
                BandSeries {
                    name: name.to_string(),
                    unit: unit.to_string(),
                    values: b.values.clone(),
                }
            })
            .collect(),
    });
    (summary, bands)
}

/// Estimate from `rows` and build the summary and bands (no file written).
pub fn outcome(uq: &Uq, rows: Vec<CaseRow>) -> Result<UqOutcome, JobError> {
    let table = runner::table(&uq.study, rows);
    let estimates = estimate(uq, &table.rows).map_err(JobError::numerical)?;
    let (summary, bands) = summarise(uq, &estimates);
    summary.check_finite().map_err(JobError::numerical)?;
    if let Some(b) = &bands {
        b.check().map_err(JobError::numerical)?;
    }
    Ok(UqOutcome {
        summary,
        bands,
        estimates,
        table,
        files: Vec::new(),
    })
}

/// Merge every journal of `dir` into the outputs (and the figures with `report`).
pub fn compact(uq: &Uq, dir: &Path, report: bool) -> Result<UqOutcome, JobError> {
    let done = crate::report::study::read_journals(dir, &uq.study.fingerprint)?;
    let mut o = outcome(uq, done.into_values().collect())?;
    let other = std::io::ErrorKind::Other;
    let io = |what: &'static str| move |e: String| JobError::io(format!("{what}: {e}"), other);
    let json = o.summary.to_json().map_err(JobError::numerical)?;
    let csv = study_csv(&o.table).map_err(|e| JobError::io(format!("study.csv: {e}"), other))?;
    let pq = study_parquet(&o.table).map_err(|e| JobError::io(format!("study.parquet: {e}"), other))?;
    let mut files: Vec<(&str, Vec<u8>)> = vec![("uq.json", json.into_bytes())];
    if let Some(b) = &o.bands {
        files.push((
            "bands.csv",
            write_bands_csv(b).map_err(io("bands.csv"))?.into_bytes(),
        ));
        files.push(("bands.parquet", bands_parquet(b).map_err(io("bands.parquet"))?));
    }
    files.push(("study.csv", csv));
    files.push(("study.parquet", pq));
    let named: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (*n, b.as_slice())).collect();
    write_all_atomic(dir, &named).map_err(|e| JobError::io(format!("{}: {e}", dir.display()), e.kind()))?;
    o.files = files.iter().map(|(n, _)| n.to_string()).collect();
    if report {
        // The band figure is of temperatures (the energies are in the files).
        let temps = o.bands.as_ref().map(|b| Bands {
            series: b.series.iter().filter(|s| s.unit == "°C").cloned().collect(),
            ..b.clone()
        });
        let figs = crate::report::plots::uq::render_uq(dir, &o.summary, temps.as_ref())?;
        o.files.extend(
            figs.iter()
                .filter_map(|p| p.file_name())
                .map(|n| n.to_string_lossy().into_owned()),
        );
    }
    Ok(o)
}
