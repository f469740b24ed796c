//! Power-loss models: churning (per gear), pocketing (per mesh), sliding (per mesh), rolling
//! bearings and shaft seals.
pub mod bearings;
pub mod churning;
pub mod pocketing;
pub mod seals;
pub mod sliding;
