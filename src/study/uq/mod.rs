//! Uncertainty quantification: input distributions sampled by a quasi-random plan, run as a
//! study, summarised by percentile bands, exceedance probabilities and Sobol' indices.
//!
//! - [`spec`]: the uncertain inputs as written (`[uncertainty]` of a model or study file);
//! - [`plan`]: their checks against the model and the sampling plan;
//! - [`run`]: the options of `geartherm uq` / `Model.uq` and the study underneath;
//! - [`estimate`], [`output`]: bands, exceedance probabilities, Sobol indices, the files;
//! - [`stats`]: the estimators (pure numerics).

pub mod estimate;
pub mod output;
pub mod plan;
pub mod run;
pub mod spec;
pub mod stats;
