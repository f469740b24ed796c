//! The use-case layer: one options struct per job, every range check and every post-solve
//! check, a typed result and a typed error ([`JobError`]: invalid input, numerical failure,
//! I/O). Every job goes read → override → check → compile → solve → post-check → result,
//! written once here; the CLI, the study runner and the Python binding call these functions
//! and only convert arguments, drive progress, write outputs and print.
//!
//! | job | options | function | result |
//! |---|---|---|---|
//! | `losses` | [`LossesOptions`] | [`losses::losses`] | [`crate::report::losses::LossReport`] |
//! | `run` | [`RunOptions`] | [`run::run`] | [`RunResult`] |
//! | `steady` | [`SteadyOptions`] | [`steady::steady`] | [`SteadyResult`] |
//! | `map` | [`MapOptions`] | [`map::map`] | [`MapResult`] |
//! | `rating` | [`RatingOptions`] | [`rating::rating`] | [`RatingResult`] |
//! | `bench` | [`BenchOptions`] | [`bench::bench`] | [`BenchResult`] |
//! | `validate` | [`ValidateOptions`] | [`validate::validate`] | [`ValidateResult`] |
//!
//! Every job checks its result against the same envelope of states where its models hold
//! ([`envelope`]).
//!
//! A study case is a `run` or a `steady` job on a model with overrides; its stand-alone command
//! line is rendered from its options by [`command`].

pub mod bench;
pub mod calibrate;
pub mod command;
pub mod envelope;
pub mod error;
pub mod fmu;
pub mod limits;
pub mod losses;
pub mod map;
pub mod model;
pub mod options;
pub mod rating;
pub mod run;
pub mod series;
pub mod spread;
pub mod steady;
pub mod validate;

pub use bench::{BenchOptions, BenchResult};
pub use calibrate::{CalibrateOptions, CalibrateResult};
pub use error::{read_text, ErrorKind, JobError};
pub use losses::LossesOptions;
pub use map::{MapOptions, MapResult};
pub use model::{CheckReport, Model};
pub use rating::{RatingOptions, RatingResult};
pub use run::{RunOptions, RunResult};
pub use steady::{SteadyOptions, SteadyResult};
pub use validate::{ValidateOptions, ValidateResult};

/// A loss model used outside its fitted range (every job's results carry these).
pub use crate::scene::RangeWarning;
