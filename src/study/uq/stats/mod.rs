//! The estimators of an uncertainty study: pure numerics, no I/O.
//!
//! - [`dist`]: input distributions (check, quantile, CDF, mean, support), Φ and Φ⁻¹ (in the
//!   model layer, whose `[uncertainty]` checks use them);
//! - [`lowdisc`]: Sobol' points (Joe–Kuo direction numbers, optional Owen scrambling);
//! - [`correlation`]: correlation checks, Iman–Conover rank correlation, Gaussian copula;
//! - [`sobol`]: the Saltelli design and first-order (Saltelli 2010) / total (Jansen 1999)
//!   indices with bootstrap intervals;
//! - [`quantiles`]: percentiles, exceedance probabilities with Wilson intervals, bands over time.

pub mod correlation;
pub use crate::model::uncertainty::dist;
pub mod estimate;
pub mod lowdisc;
pub mod quantiles;
mod rng;
pub mod sobol;

pub use dist::{normal_cdf, normal_quantile, DistError, Distribution};
pub use estimate::Estimate;
pub use lowdisc::sobol_points;
pub use quantiles::{exceedance, percentiles, BandAccumulator};
pub use rng::{mix64, Rng};
pub use sobol::{saltelli_rows, sobol_indices, SobolIndices};
