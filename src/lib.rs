//! geartherm: gearbox thermal simulator.
//!
//! Layers (an arrow = "may use"): `cli` (and the Python binding in `python/`) → `study` →
//! `report` → `reference` (reference cases of `geartherm validate`) / `solve` → `scene` →
//! `model` → `physics`.
//! `physics` is pure (SI units, no I/O); `model` reads and validates model files; the CLI lives in
//! `src/main.rs` and `src/cli/`.

pub mod cycle;
pub mod model;
pub mod physics;
pub mod reference;
pub mod report;
pub mod scene;
pub mod solve;
pub mod study;
