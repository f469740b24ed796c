//! Power-loss models: churning (per gear), pocketing (per mesh), sliding (per mesh).
pub mod churning;
pub mod pocketing;
pub mod sliding;
