//! The model-file sections: one file per section, holding its serde struct(s) and its checks.

pub mod launch;
pub mod vehicle;
