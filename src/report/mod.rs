//! Reports: text/JSON summaries, run outputs (CSV, JSON) and PNG plots.
pub mod bearing_info;
pub mod bench;
pub mod calibration;
pub mod files;
pub mod info;
pub mod losses;
pub mod map;
pub mod plots;
pub mod run;
pub mod sources;
pub mod spread;
pub mod stats_de;
pub mod study;
pub mod timeseries;
pub mod uq;
pub mod validation;
pub mod zip;
