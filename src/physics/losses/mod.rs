//! Power-loss models: churning (per gear), pocketing (per mesh), sliding (per mesh), rolling
//! bearings and shaft seals, and the automatic transmission's own losses: open clutch drag, oil
//! pump, torque converter; windage of gears above the oil; the impulse of lubricating jets and the
//! oil flung through planet carriers.
pub mod bearings;
pub mod churning;
pub mod clutch_drag;
pub mod converter;
pub mod curve;
pub mod fling;
pub mod jet;
pub mod pocketing;
pub mod pump;
pub mod seals;
pub mod sliding;
pub mod windage;
