//! Physics layer: pure functions and plain structs in SI units. No I/O, no TOML, no printing.
pub mod efficiency;
pub mod geometry;
pub mod kinematics;
pub mod losses;
pub mod lubrication;
pub mod oil;
pub mod thermal;
pub mod units;
