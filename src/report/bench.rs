//! The outputs of a work-precision study (`geartherm bench`), one type per file, written by
//! `bench` and read back by `report DIR` with the same types: `bench.csv` (one
//! [`BenchRow`] per solver and tolerance, `solve::work_precision::to_csv`) and `bench.json`
//! ([`BenchResult`]).

use serde::{Deserialize, Serialize};

pub use crate::solve::work_precision::{BenchRow, Reference};

/// What the study found (`bench.json`). Read back with `#[serde(default)]`: a key an earlier
/// version did not write reads as its default. The rows are the table of `bench.csv`: `bench.json`
/// repeats them for a reader of that file alone (a failed row's numbers as `null`), and the
/// reader takes them from `bench.csv` (`report::plots::data::read_bench`).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct BenchResult {
    /// Model name.
    pub model: String,
    /// Cycle name.
    pub cycle: String,
    /// The reference and its self-check.
    pub reference: Reference,
    /// The product's default and whether it is on the Pareto fronts.
    pub default: DefaultOnFront,
    /// Every (solver, tolerance) point.
    #[serde(skip_deserializing)]
    pub rows: Vec<BenchRow>,
    /// Whether each row is on the Pareto front of (wall time, max error).
    pub pareto: Vec<bool>,
    /// Nodes of the network.
    pub nodes: usize,
    /// Loss items.
    pub items: usize,
    /// Cycle samples.
    pub samples: usize,
}

/// The default setting and the fronts it lies on.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct DefaultOnFront {
    /// Default solver.
    pub solver: String,
    /// Default relative tolerance.
    pub rtol: f64,
    /// Default absolute tolerance, K.
    pub atol: f64,
    /// On the front among all solvers.
    pub on_pareto_front: bool,
    /// On the front among the implicit solvers (the default must handle stiff networks).
    pub on_implicit_pareto_front: bool,
}
