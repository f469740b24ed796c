//! Scene compile: from a checked model (and a scenario) to flat, precomputed structures the
//! solvers evaluate without strings, maps or allocation.
pub mod losses;
pub mod planet_churning;
pub mod ranges;
pub mod system;
pub mod thermal;

pub use losses::{LossItem, LossScene, Needs, OperatingPoint, SampleTerms, SceneError, Skipped, Source};
pub use ranges::{RangeLog, RangeWarning};
pub use system::{Inputs, RhsFailure, Scene, Work};
