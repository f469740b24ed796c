//! Uncertainty quantification: input distributions sampled by a quasi-random plan, run as a
//! study, summarised by percentile bands, exceedance probabilities and Sobol' indices.

pub mod stats;
