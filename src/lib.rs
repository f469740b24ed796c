//! geartherm: gearbox thermal simulator.
//!
//! Layers, each module using only those below it (docs/architecture.md draws them):
//!
//! | module | holds |
//! |---|---|
//! | [`study`] | design studies: study files, sampling plans, many jobs in parallel, journals |
//! | [`job`] | the use-case layer: one options struct per job, every range and post-solve check, typed results and errors |
//! | [`report`] | text, JSON, CSV, Parquet and PNG outputs; transactional output directories |
//! | [`reference`] | reference cases (peers, standards, measurements) and their comparison (`geartherm validate`) |
//! | [`solve`] | transient integration (ROS3, diffsol), steady equilibria, maps, work-precision |
//! | [`scene`] | the compile step: a checked model and a scenario become flat, precomputed arrays |
//! | [`cycle`] | drive and rig cycles, vehicle longitudinal dynamics, shift schedules |
//! | [`model`] | the model file: serde schema, key-path overrides, every check with its key path |
//! | [`physics`] | pure physics in SI units: oil, geometry, kinematics, losses, thermal links |
//!
//! The command-line front end lives in `src/cli/` (its entry point is [`cli_main`], which
//! `src/main.rs` and the Python package's `geartherm` console script call), the Python binding
//! in `python/`; both only convert arguments into [`job`] options, call the same functions and
//! print.

#![warn(missing_docs)]

#[cfg(feature = "cli")]
mod cli;
pub mod cycle;
pub mod job;
pub mod model;
pub mod physics;
pub mod reference;
pub mod report;
pub mod scene;
pub mod solve;
pub mod study;

#[cfg(feature = "cli")]
pub use cli::main as cli_main;
