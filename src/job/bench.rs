//! `bench`: the work-precision study of one model over one cycle: every solver over a range of
//! tolerances against a two-method 1e-12 reference.

use serde::{Deserialize, Serialize};

pub use crate::report::bench::{BenchResult, BenchRow, DefaultOnFront, Reference};
use crate::solve::transient::{Method, DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL};
use crate::solve::work_precision::{pareto, reference, sweep, to_csv};

use super::limits;
use super::run::{method, prepare, RunOptions};
use super::{JobError, Model};

/// Options of a work-precision study (`geartherm bench`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BenchOptions {
    /// Bundled cycle name or a CSV file.
    pub cycle: String,
    /// Repeats per point (median wall time).
    pub repeats: usize,
    /// Tightest tolerance of the sweep (1e-3 … this, one per decade).
    pub min_rtol: f64,
    /// Solver names.
    pub solvers: Vec<String>,
    /// Step budget per run (an explicit solver on a stiff network stops there and is reported).
    pub max_steps: usize,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            cycle: "wltc".into(),
            repeats: 3,
            min_rtol: 1e-10,
            solvers: ["bdf", "esdirk34", "tr-bdf2", "ros3", "tsit45"]
                .map(String::from)
                .to_vec(),
            max_steps: 2_000_000,
        }
    }
}

impl BenchOptions {
    /// Every check of the options; the solvers parsed.
    pub fn check(&self) -> Result<Vec<Method>, JobError> {
        limits::REPEATS.check(self.repeats as f64)?;
        limits::MIN_RTOL.check(self.min_rtol)?;
        limits::MAX_STEPS.check(self.max_steps as f64)?;
        if self.solvers.is_empty() {
            return Err(JobError::option(
                "solvers",
                "",
                "one or more solver names",
                "solvers: none given".into(),
            ));
        }
        self.solvers.iter().map(|s| method(s.trim())).collect()
    }

    /// The tolerances of the sweep: 1e-3, 1e-4, … down to `min_rtol`.
    pub fn rtols(&self) -> Vec<f64> {
        let mut rtols = Vec::new();
        let mut r = 1e-3;
        while r >= self.min_rtol * 0.999 {
            rtols.push(r);
            r /= 10.0;
        }
        rtols
    }
}

impl BenchResult {
    /// The files of a bench directory: `bench.csv` and `bench.json`.
    pub fn files(&self) -> Result<Vec<(&'static str, Vec<u8>)>, JobError> {
        let json = serde_json::to_vec_pretty(self)
            .map_err(|e| JobError::numerical(format!("cannot serialise bench.json: {e}")))?;
        Ok(vec![
            ("bench.csv", to_csv(&self.rows).into_bytes()),
            ("bench.json", json),
        ])
    }
}

/// Run the study on the problem `run` solves by default (same scene pruning and outputs).
/// `on_reference` sees the reference once it is computed, `on_row` each row as it is measured.
pub fn bench(
    m: &Model,
    o: &BenchOptions,
    on_reference: &mut dyn FnMut(&Reference),
    on_row: &mut dyn FnMut(&BenchRow),
) -> Result<BenchResult, JobError> {
    let methods = o.check()?;
    let run = RunOptions {
        cycle: o.cycle.clone(),
        max_steps: o.max_steps,
        ..RunOptions::default()
    };
    let p = prepare(m, &run)?;
    let (refr, info) = reference(&p.scene, &p.segs, 1e-12)
        .map_err(|e| JobError::numerical(format!("{}: reference solution failed: {e}", m.label())))?;
    on_reference(&info);
    let rows = sweep(
        &p.scene,
        &p.segs,
        &refr,
        &methods,
        &o.rtols(),
        o.repeats,
        o.max_steps,
        on_row,
    );
    let front = pareto(&rows);
    let default_on_front = rows.iter().zip(&front).any(|(r, f)| r.default && *f);
    let implicit: Vec<BenchRow> = rows
        .iter()
        .filter(|r| Method::parse(&r.solver).is_some_and(|m| m.is_implicit()))
        .cloned()
        .collect();
    let on_implicit = implicit
        .iter()
        .zip(pareto(&implicit))
        .any(|(r, f)| r.default && f);
    Ok(BenchResult {
        model: m.gearbox.name.clone(),
        cycle: p.cycle.name.clone(),
        reference: info,
        default: DefaultOnFront {
            solver: DEFAULT_METHOD.name().to_string(),
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            on_pareto_front: default_on_front,
            on_implicit_pareto_front: on_implicit,
        },
        rows,
        pareto: front,
        nodes: p.scene.nodes(),
        items: p.scene.items(),
        samples: p.segs.len(),
    })
}
