//! Scene compile: from a checked model (and a scenario) to flat, precomputed structures the
//! solvers evaluate without strings, maps or allocation.
pub mod automatic;
pub mod bearing_loads;
pub mod churn_sample;
pub mod circuit;
pub mod controls;
pub mod element_losses;
pub mod gear_losses;
pub mod items;
pub mod losses;
pub mod planet_churning;
pub mod ranges;
pub mod sample_cache;
mod sliding_memo;
pub mod spread;
pub mod spread_eval;
pub mod system;
pub mod thermal;
pub mod usage;
pub mod warning;

pub use losses::{
    sum_by_source, DefaultHeat, LossItem, LossScene, Needs, OperatingPoint, PerSource, SampleTerms,
    SceneError, Skipped, Source, N_SOURCES,
};
pub use ranges::{RangeLog, RangeWarning};
pub use sample_cache::SampleCache;
pub use spread::SpreadScene;
pub use spread_eval::{ItemSpread, ModelEnergy, ModelValue, SourceSpread, SpreadWork};
pub use system::{Inputs, RhsFailure, Scene, Work};
