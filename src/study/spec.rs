//! The study file (`STUDY.toml`; the Python binding sends the same structure as JSON).
//!
//! ```toml
//! [study]
//! name = "at6_wltc"
//! model = "../models/at6_lepelletier.toml"   # relative to the study file
//!
//! [job]
//! kind = "run"                # run | steady | map
//! cycles = ["wltc"]           # run: one or more cycles (bundled names or CSV files)
//!
//! [sampling]
//! plan = "lhs"                # grid | lhs | list
//! cases = 1000                # lhs: number of samples
//! seed = 7
//!
//! [[parameters]]
//! path = "lubrication.oil_level_mm"
//! range = [40.0, 80.0]        # continuous: lhs samples it, grid takes `levels` points
//!
//! [[parameters]]
//! path = "oil.catalogue"
//! values = ["dexron_vi_atf", "fva_3a"]
//!
//! [[parameters]]
//! path = 'thermal.links["housing-air"].h_table.h_w_per_m2k'
//! scale = [0.5, 2.0]          # multiply the model's value (number or array) by a factor
//!
//! [outputs]
//! per_case = false            # timeseries.csv + summary.json per case under cases/<id>/
//! pareto = ["energy_total_j", "temp_max_sump_c"]   # both minimised
//! effects = ["energy_total_j", "cycle_efficiency", "temp_max_sump_c"]
//! ```

use serde::{Deserialize, Serialize};

use crate::job::{RunOptions, SteadyOptions};

/// The whole study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Name and base model.
    pub study: Meta,
    /// What each case solves.
    pub job: JobSpec,
    /// How parameter values are combined into cases.
    #[serde(default)]
    pub sampling: Sampling,
    /// The parameters (none with an `[uncertainty]` plan: its inputs are the parameters).
    #[serde(default)]
    pub parameters: Vec<ParamSpec>,
    /// Uncertain inputs (distributions on key paths) sampled by the `qmc` and `saltelli` plans.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<crate::model::uncertainty::UncertaintySpec>,
    /// Outputs beyond the table.
    #[serde(default)]
    pub outputs: OutputSpec,
}

/// `[study]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Meta {
    /// Study name.
    pub name: String,
    /// Base model file, relative to the study file (ignored when the model text is given).
    #[serde(default)]
    pub model: String,
}

/// `[job]`: the problem every sample is solved on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum JobSpec {
    /// Drive-cycle transients: one case per sample and cycle.
    Run {
        /// Cycles.
        cycles: Vec<String>,
        /// Run options besides the cycle (solver, tolerances, initial and ambient temperature).
        #[serde(default)]
        options: Option<RunOptions>,
    },
    /// Equilibria at operating points: one case per sample and point.
    Steady {
        /// The points.
        points: Vec<SteadyOptions>,
    },
    /// Equilibria over a speed × torque grid in one gear: one case per sample and grid point.
    Map {
        /// Gear-state name.
        gear: String,
        /// Input speeds, rpm.
        speed_rpm: Vec<f64>,
        /// Input torques, N·m.
        torque_nm: Vec<f64>,
        /// Vehicle speed for h(v) links, km/h.
        #[serde(default)]
        vehicle_speed_kmh: f64,
    },
}

/// Sampling plans.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Plan {
    /// Full factorial: every combination (ranges at `levels` points).
    #[default]
    Grid,
    /// Latin hypercube of `cases` samples (seeded, deterministic).
    Lhs,
    /// Explicit list: parameter i of case k is `values[k]` (all lists of equal length).
    List,
    /// `cases` quasi-random samples of the `[uncertainty]` inputs (scrambled Sobol' points
    /// through each input's inverse CDF).
    Qmc,
    /// Saltelli's design for Sobol indices of the `[uncertainty]` inputs: `cases` base points,
    /// `cases`·(d + 2) samples.
    Saltelli,
}

/// `[sampling]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sampling {
    /// Plan.
    #[serde(default)]
    pub plan: Plan,
    /// Samples (lhs, qmc; the base points of saltelli).
    #[serde(default)]
    pub cases: Option<usize>,
    /// Seed (lhs, qmc, saltelli).
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_seed() -> u64 {
    1
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            plan: Plan::Grid,
            cases: None,
            seed: default_seed(),
        }
    }
}

/// One parameter: a key path and exactly one of `values`, `range` or `scale`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamSpec {
    /// Key path in the model (see [`crate::model::overrides`]).
    pub path: String,
    /// Discrete values (numbers or strings).
    #[serde(default)]
    pub values: Option<Vec<super::ParamValue>>,
    /// Continuous range [lo, hi].
    #[serde(default)]
    pub range: Option<[f64; 2]>,
    /// Factor range [lo, hi] multiplying the model's value (a number or an array of numbers).
    #[serde(default)]
    pub scale: Option<[f64; 2]>,
    /// Grid points of a range or scale (default 3).
    #[serde(default)]
    pub levels: Option<usize>,
    /// With `values`: the values are factors multiplying the model's value, as a scale's.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub factors: bool,
}

/// `[outputs]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Per-case `timeseries.csv` + `summary.json` (run) or `steady.json` (steady, map).
    #[serde(default)]
    pub per_case: bool,
    /// Two outputs for the Pareto front (both minimised).
    #[serde(default)]
    pub pareto: Option<[String; 2]>,
    /// Outputs shown in the main-effects figure.
    #[serde(default)]
    pub effects: Option<Vec<String>>,
}
