//! A warning of a compiled scene or a run: a loss model used outside the range it was fitted or
//! derived on, or a loss item whose value is not known ([`super::ranges`] gathers them over a
//! run).

use std::fmt;

/// One warning: an item, the range or condition, and what was seen.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RangeWarning {
    /// Loss item (e.g. "churning of gear wheel").
    pub item: String,
    /// The range left or the condition met.
    pub range: String,
    /// What was seen (quantity span, share of points).
    pub seen: String,
}

impl fmt::Display for RangeWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "warning: {}: {} ({})", self.item, self.range, self.seen)
    }
}

/// The warning for a mesh whose zone lies partly (wet share `wet` < 1) or wholly above the oil
/// while the model file gives no density for that part.
pub fn above_oil_warning(mesh: &str, wet: f64) -> RangeWarning {
    RangeWarning {
        item: format!("pocketing of mesh {mesh}"),
        range: "mesh zone above the oil: the density it pumps is unknown (no jet or splash flow, no carried-oil model); that share is not counted — set [losses] pocketing_mixture_density_kg_m3 to count it".into(),
        seen: format!("{:.0} % of the mesh zone above the oil", 100.0 * (1.0 - wet).clamp(0.0, 1.0)),
    }
}

/// One warning per bearing key that has no effect in its combination (the model's
/// `Bearing::ineffective`): the key path, why, and that the value is ignored.
pub fn ineffective_key_warnings(gb: &crate::model::Gearbox) -> Vec<RangeWarning> {
    gb.bearings
        .iter()
        .flat_map(|b| {
            b.ineffective.iter().map(move |(key, why)| RangeWarning {
                item: format!("bearing {}", b.name),
                range: format!("{key} has no effect: {why}"),
                seen: "the value given is ignored".into(),
            })
        })
        .collect()
}
