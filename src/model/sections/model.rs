//! `[model]`: identification of the gearbox.

use serde::{Deserialize, Serialize};

use crate::model::problems::Problems;

/// `[model]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelMeta {
    /// Display name.
    pub name: String,
    /// Free text: where the data come from and what is assumed.
    #[serde(default)]
    pub description: Option<String>,
}

/// The display name must not be empty.
pub(crate) fn validate_meta(m: &ModelMeta, problems: &mut Problems) {
    if m.name.trim().is_empty() {
        problems.push("model.name", "\"\"", "must not be empty");
    }
}
