//! Reports: text/JSON summaries and (later) CSV and PNG outputs.
pub mod info;
pub mod losses;
