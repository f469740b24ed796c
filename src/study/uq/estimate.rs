//! The estimates of a finished uncertainty study from its case rows: percentile bands of every
//! series over time, percentiles of the scalar outputs, exceedance probabilities of the limits
//! with their intervals, Sobol indices with bootstrap intervals (Saltelli's design).
//!
//! Which rows count: every `ok` case of a quasi-random plan; of Saltelli's design the rows of A
//! and B (2N independent samples of the inputs; the mixed rows A_B^(i) serve the indices only).
//! Cases refused by the model (`invalid`) or failed are counted and left out of bands and
//! probabilities; Sobol indices need every case of the design and are not computed otherwise.

use crate::report::study::CaseRow;

use super::plan::Design;
use super::run::{Uq, UqJob};
use super::stats::{exceedance, percentiles, sobol_indices, BandAccumulator, Estimate, SobolIndices};

/// Percentile bands of one series: `[percentile][time]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Series name (`temp_sump_c`, `energy_churning_j`).
    pub name: String,
    /// Values per percentile per grid time.
    pub values: Vec<Vec<f64>>,
}

/// Percentiles, mean and standard deviation of one scalar output across the samples.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarStats {
    /// Output column.
    pub name: String,
    /// Per asked percentile.
    pub percentiles: Vec<f64>,
    /// Mean.
    pub mean: f64,
    /// Standard deviation (divisor n − 1).
    pub sd: f64,
}

/// The exceedance probability of one limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Exceedance {
    /// Node.
    pub node: String,
    /// Limit, °C.
    pub limit_c: f64,
    /// The output compared (`temp_max_sump_c`).
    pub output: String,
    /// Samples above the limit.
    pub count: usize,
    /// Samples.
    pub n: usize,
    /// Probability with its interval.
    pub probability: Estimate,
}

/// Sobol indices of one output.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivity {
    /// Output column.
    pub output: String,
    /// Indices per input (in the order of the study's inputs).
    pub indices: SobolIndices,
}

/// Everything estimated.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimates {
    /// Cases solved ok, refused by the model (`invalid`), failed.
    pub counts: (usize, usize, usize),
    /// Samples the bands and probabilities use.
    pub used: usize,
    /// Bands (run jobs).
    pub bands: Vec<Band>,
    /// Scalar outputs.
    pub scalars: Vec<ScalarStats>,
    /// Loss energy per source and in total over the cycle (run jobs), J.
    pub energy: Vec<ScalarStats>,
    /// Limits.
    pub exceedance: Vec<Exceedance>,
    /// Sobol indices (Saltelli's design with every case ok).
    pub sobol: Vec<Sensitivity>,
    /// Why the Sobol indices are missing, when asked and missing.
    pub sobol_missing: Option<String>,
}

/// The scalar outputs summarised: the highest (run) or steady temperature of every node and the
/// total loss energy (power), then every other energy (loss) per source.
pub fn scalar_outputs(uq: &Uq) -> Vec<String> {
    let steady = matches!(uq.job_kind, UqJob::Steady(_));
    let mut v: Vec<String> = uq
        .nodes
        .iter()
        .map(|n| {
            if steady {
                format!("temp_{n}_c")
            } else {
                format!("temp_max_{n}_c")
            }
        })
        .collect();
    v.push(if steady {
        "loss_total_w".into()
    } else {
        "energy_total_j".into()
    });
    v
}

/// The run's loss energy columns: per source, then the total.
pub fn energy_outputs() -> Vec<String> {
    let mut v: Vec<String> = crate::scene::Source::ALL
        .iter()
        .map(|s| format!("energy_{}_j", s.as_str()))
        .collect();
    v.push("energy_total_j".into());
    v
}

/// The column of a node's limit.
pub fn limit_output(uq: &Uq, node: &str) -> String {
    match uq.job_kind {
        UqJob::Steady(_) => format!("temp_{node}_c"),
        UqJob::Run(_) => format!("temp_max_{node}_c"),
    }
}

fn output(row: &CaseRow, name: &str) -> Option<f64> {
    row.outputs
        .iter()
        .find(|(n, _)| n == name)
        .and_then(|(_, v)| *v)
        .filter(|v| v.is_finite())
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

fn bands(uq: &Uq, used: &[&CaseRow]) -> Result<Vec<Band>, String> {
    let mut out = Vec::with_capacity(uq.series_names.len());
    for (j, name) in uq.series_names.iter().enumerate() {
        let mut acc = BandAccumulator::new(uq.times_s.len());
        for r in used {
            let s = r.series.as_ref().and_then(|s| s.get(j)).ok_or_else(|| {
                format!(
                    "case {}: no series in its journal row (journaled by another version?)",
                    r.case
                )
            })?;
            acc.push(s).map_err(|e| format!("case {}, {name}: {e}", r.case))?;
        }
        out.push(Band {
            name: name.clone(),
            values: acc.bands(&uq.options.percentiles)?,
        });
    }
    Ok(out)
}

fn sobol(uq: &Uq, rows: &[CaseRow], outputs: &[String]) -> Result<Vec<Sensitivity>, String> {
    let Design::Saltelli { n, d } = uq.design else {
        return Ok(Vec::new());
    };
    let mut by_sample: Vec<Option<&CaseRow>> = vec![None; n * (d + 2)];
    for r in rows {
        if let Some(slot) = by_sample.get_mut(r.sample) {
            *slot = Some(r);
        }
    }
    let mut out = Vec::new();
    for name in outputs {
        let y: Option<Vec<f64>> = by_sample
            .iter()
            .map(|r| r.and_then(|r| output(r, name)))
            .collect();
        let y = y.ok_or_else(|| {
            let missing = by_sample
                .iter()
                .filter(|r| !r.is_some_and(|r| output(r, name).is_some()))
                .count();
            format!(
                "{missing} of {} cases of the design have no {name} (failed, refused or not solved)",
                n * (d + 2)
            )
        })?;
        let indices = sobol_indices(&y, n, d, uq.options.bootstrap, uq.options.confidence, uq.seed)?;
        out.push(Sensitivity {
            output: name.clone(),
            indices,
        });
    }
    Ok(out)
}

/// Estimate everything from the study's rows (any order).
pub fn estimate(uq: &Uq, rows: &[CaseRow]) -> Result<Estimates, String> {
    let ok: Vec<&CaseRow> = rows.iter().filter(|r| r.status == "ok").collect();
    let invalid = rows.iter().filter(|r| r.status == "invalid").count();
    let counts = (ok.len(), invalid, rows.len() - ok.len() - invalid);
    let used: Vec<&CaseRow> = ok
        .iter()
        .copied()
        .filter(|r| uq.design.is_draw(r.sample))
        .collect();
    if used.is_empty() {
        return Err(format!(
            "no sample was solved ({} refused by the model, {} failed): nothing to estimate",
            counts.1, counts.2
        ));
    }
    let bands = if uq.series_names.is_empty() {
        Vec::new()
    } else {
        bands(uq, &used)?
    };
    let outputs = scalar_outputs(uq);
    let stats = |name: &String| {
        let mut v: Vec<f64> = used.iter().filter_map(|r| output(r, name)).collect();
        let (mean, sd) = mean_sd(&v);
        ScalarStats {
            name: name.clone(),
            percentiles: percentiles(&mut v, &uq.options.percentiles),
            mean,
            sd,
        }
    };
    let scalars = outputs.iter().map(stats).collect();
    let energy = match uq.job_kind {
        UqJob::Run(_) => energy_outputs().iter().map(stats).collect(),
        UqJob::Steady(_) => Vec::new(),
    };
    let exceedance = uq
        .options
        .limits
        .iter()
        .map(|l| {
            let name = limit_output(uq, &l.node);
            let v: Vec<f64> = used.iter().filter_map(|r| output(r, &name)).collect();
            let count = v.iter().filter(|&&x| x > l.temp_c).count();
            Exceedance {
                node: l.node.clone(),
                limit_c: l.temp_c,
                output: name,
                count,
                n: v.len(),
                probability: exceedance(count, v.len(), uq.options.confidence),
            }
        })
        .collect();
    let (sobol, sobol_missing) = match sobol(uq, rows, &outputs) {
        Ok(s) => (s, None),
        Err(e) => (Vec::new(), Some(e)),
    };
    Ok(Estimates {
        counts,
        used: used.len(),
        bands,
        scalars,
        energy,
        exceedance,
        sobol,
        sobol_missing,
    })
}
