//! Uncertainty quantification: input distributions sampled by a quasi-random plan, run as a
//! study, summarised by percentile bands, exceedance probabilities and Sobol' indices.
//!
//! - [`plan`]: the sampling plan of the inputs checked by the model layer
//!   ([`crate::model::uncertainty`]: the `[uncertainty]` section as written, its checks);
//! - [`run`]: the options of `geartherm uq` / `Model.uq` and the study underneath;
//! - [`estimate`], [`output`]: bands, exceedance probabilities, Sobol indices, the files;
//! - [`stats`]: the estimators (pure numerics).

pub mod estimate;
pub mod output;
pub mod plan;
pub mod run;
pub mod stats;
