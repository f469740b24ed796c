//! Per-source values in reports: one key or column per loss source of [`Source::ALL`], so a new
//! source appears in every output without touching the writers.

use serde::de::{Deserialize, Deserializer};
use serde::ser::{Serialize, SerializeMap, Serializer};

use crate::scene::{PerSource, Source};

/// Per-source values serialised as a map `{"<source><suffix>": value, …}` in the order of
/// [`Source::ALL`], with `"total<suffix>"` last when `total` is set.
#[derive(Debug, Clone, Copy, Default)]
pub struct SourceValues {
    /// Values indexed by [`Source::index`].
    pub values: PerSource,
    /// Key suffix (`"_w"`, or `""` for energies in J).
    pub suffix: &'static str,
    /// Append the sum under `total<suffix>`.
    pub total: bool,
    /// Key prefix (`"loss_"` for the flat keys of docs/outputs.md, or `""`).
    pub prefix: &'static str,
}

impl SourceValues {
    /// Values with key suffix `suffix`, with or without a total.
    pub fn new(values: PerSource, suffix: &'static str, total: bool) -> SourceValues {
        SourceValues {
            values,
            suffix,
            total,
            prefix: "",
        }
    }

    /// The same values serialised with keys `<prefix><source><suffix>` (e.g. `loss_churning_w`).
    pub fn prefixed(self, prefix: &'static str) -> SourceValues {
        SourceValues { prefix, ..self }
    }

    /// Value of source `s`.
    pub fn get(&self, s: Source) -> f64 {
        self.values[s.index()]
    }

    /// Sum over the sources.
    pub fn sum(&self) -> f64 {
        self.values.iter().sum()
    }

    /// `name value unit, …` for text summaries, sources with a zero value left out.
    pub fn text(&self, scale: f64, unit: &str, digits: usize) -> String {
        Source::ALL
            .iter()
            .filter(|s| self.get(**s) != 0.0 || s.index() < 3)
            .map(|s| format!("{} {:.digits$} {unit}", s.as_str(), self.get(*s) * scale))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Read back as `summary.json` writes it (`energy_lost_j`: keys `<source>` and `total`, no
/// prefix or suffix): a source the file has no key for (one added after the file was written)
/// reads as 0; `total` is the sum again (the writer writes the sum); other keys are ignored.
impl<'de> Deserialize<'de> for SourceValues {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let map = std::collections::BTreeMap::<String, Option<f64>>::deserialize(d)?;
        let mut values = [0.0; crate::scene::N_SOURCES];
        for s in Source::ALL {
            values[s.index()] = map.get(s.as_str()).copied().flatten().unwrap_or(0.0);
        }
        Ok(SourceValues::new(values, "", map.contains_key("total")))
    }
}

impl Serialize for SourceValues {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        let mut m = ser.serialize_map(Some(Source::ALL.len() + usize::from(self.total)))?;
        for s in Source::ALL {
            m.serialize_entry(
                &format!("{}{}{}", self.prefix, s.as_str(), self.suffix),
                &self.get(s),
            )?;
        }
        if self.total {
            m.serialize_entry(&format!("{}total{}", self.prefix, self.suffix), &self.sum())?;
        }
        m.end()
    }
}

/// CSV header fragment `loss_<source>_w,…` (no leading or trailing comma).
pub fn csv_columns() -> String {
    Source::ALL.map(|s| format!("loss_{}_w", s.as_str())).join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_follow_the_source_list() {
        let mut v = [0.0; crate::scene::N_SOURCES];
        v[Source::Sliding.index()] = 2.0;
        v[Source::Bearing.index()] = 1.0;
        let j = serde_json::to_value(SourceValues::new(v, "_w", true)).unwrap();
        assert_eq!(j["sliding_w"], 2.0);
        assert_eq!(j["bearing_w"], 1.0);
        assert_eq!(j["total_w"], 3.0);
        assert_eq!(j.as_object().unwrap().len(), Source::ALL.len() + 1);
        assert!(csv_columns().starts_with("loss_churning_w,loss_pocketing_w,loss_sliding_w,loss_bearing_w"));
        let j = serde_json::to_value(SourceValues::new(v, "_w", true).prefixed("loss_")).unwrap();
        assert_eq!(
            (j["loss_sliding_w"].as_f64(), j["loss_total_w"].as_f64()),
            (Some(2.0), Some(3.0))
        );
    }
}
