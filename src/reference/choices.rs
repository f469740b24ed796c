//! The quantity a case compares and the model choices it is evaluated with.
//!
//! A choice is a set of keys written over the case's model file before it is compiled:
//! `[losses]` keys, or `bearings.<key>` written into every `[[bearings]]` entry (the friction
//! model of a bearing is chosen per entry in a model file).

use crate::scene::Source;

/// The loss quantity a case compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Mesh friction.
    Sliding,
    /// Churning.
    Churning,
    /// Pocketing.
    Pocketing,
    /// Rolling-bearing friction.
    Bearing,
    /// Lip-seal friction.
    Seal,
    /// Open wet-clutch drag.
    ClutchDrag,
    /// Oil-pump drive power.
    Pump,
    /// Torque-converter slip loss.
    Converter,
    /// Efficiency 1 − ΣP_loss/P_in over the case's `sources` (all by default).
    Efficiency,
}

/// Label and keys of one model choice.
pub type Choice = (&'static str, Vec<(&'static str, toml::Value)>);

fn s(v: &str) -> toml::Value {
    toml::Value::String(v.into())
}

fn off(k: &'static str) -> (&'static str, toml::Value) {
    (k, s("off"))
}

/// The gear-loss sources off: a case on a bearing, seal or automatic item sees it alone.
fn gear_losses_off() -> Vec<(&'static str, toml::Value)> {
    vec![off("churning"), off("pocketing"), off("sliding")]
}

impl Quantity {
    /// Source of the loss items compared (`None`: efficiency, every source of the case).
    pub fn source(self) -> Option<Source> {
        Some(match self {
            Quantity::Sliding => Source::Sliding,
            Quantity::Churning => Source::Churning,
            Quantity::Pocketing => Source::Pocketing,
            Quantity::Bearing => Source::Bearing,
            Quantity::Seal => Source::Seal,
            Quantity::ClutchDrag => Source::ClutchDrag,
            Quantity::Pump => Source::Pump,
            Quantity::Converter => Source::Converter,
            Quantity::Efficiency => return None,
        })
    }

    /// Name.
    pub fn as_str(self) -> &'static str {
        match self.source() {
            Some(src) => src.as_str(),
            None => "efficiency",
        }
    }

    /// Every applicable model choice (label, keys); the other gear-loss sources are off.
    pub fn choices(self) -> Vec<Choice> {
        match self {
            Quantity::Sliding => sliding_choices(),
            Quantity::Churning => ["changenet", "seetharaman", "stavytskyi"]
                .into_iter()
                .map(|m| (m, vec![off("sliding"), off("pocketing"), ("churning", s(m))]))
                .collect(),
            Quantity::Pocketing => vec![(
                "pocketing",
                vec![off("churning"), off("sliding"), ("pocketing", s("on"))],
            )],
            Quantity::Bearing => ["palmgren", "skf"]
                .into_iter()
                .map(|m| {
                    let mut k = gear_losses_off();
                    k.push(("bearings.model", s(m)));
                    (m, k)
                })
                .collect(),
            Quantity::Seal | Quantity::ClutchDrag | Quantity::Pump | Quantity::Converter => {
                vec![("default", gear_losses_off())]
            }
            Quantity::Efficiency => efficiency_choices(),
        }
    }
}

fn sliding_choices() -> Vec<Choice> {
    // Every key explicit, so a label means the same whatever the defaults are.
    let det = |f: &'static str, ls: &'static str, hd: &'static str| {
        vec![
            off("churning"),
            off("pocketing"),
            ("sliding", s("detailed")),
            ("friction", s(f)),
            ("load_sharing", s(ls)),
            ("helical_distribution", s(hd)),
        ]
    };
    vec![
        // The model file as it is: every sliding default, the oil's X_L.
        ("default", vec![off("churning"), off("pocketing")]),
        ("iso_tc60", det("iso_tc60", "uniform", "uniform")),
        ("benedict_kelley", det("benedict_kelley", "uniform", "uniform")),
        ("schlenk", det("schlenk", "uniform", "uniform")),
        ("schlenk 33:67", det("schlenk", "33:67", "uniform")),
        ("schlenk ramp", det("schlenk", "ramp", "uniform")),
        (
            "schlenk niemann_richer",
            det("schlenk", "uniform", "niemann_richer"),
        ),
        (
            "iso14179",
            vec![off("churning"), off("pocketing"), ("sliding", s("iso14179"))],
        ),
    ]
}

/// The whole gearbox with its defaults, and with each other friction law and churning model.
fn efficiency_choices() -> Vec<Choice> {
    vec![
        ("default", vec![]),
        ("friction iso_tc60", vec![("friction", s("iso_tc60"))]),
        (
            "friction benedict_kelley",
            vec![("friction", s("benedict_kelley"))],
        ),
        ("churning seetharaman", vec![("churning", s("seetharaman"))]),
        ("churning stavytskyi", vec![("churning", s("stavytskyi"))]),
    ]
}

/// The choices of `q`, restricted to `only` (labels) when given.
pub fn select(q: Quantity, only: Option<&[String]>) -> Result<Vec<Choice>, String> {
    let all = q.choices();
    let Some(only) = only else {
        return Ok(all);
    };
    if let Some(bad) = only.iter().find(|o| !all.iter().any(|(l, _)| l == o)) {
        return Err(format!(
            "models: \"{bad}\" is not a {} model choice (allowed: {})",
            q.as_str(),
            all.iter().map(|(l, _)| *l).collect::<Vec<_>>().join(", ")
        ));
    }
    Ok(all
        .into_iter()
        .filter(|(l, _)| only.iter().any(|o| o == l))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_loss_source_has_a_quantity_with_choices() {
        for src in Source::ALL {
            let q: Quantity = toml::Value::String(src.as_str().into())
                .try_into()
                .unwrap_or_else(|e| panic!("{}: {e}", src.as_str()));
            assert_eq!(q.source(), Some(src));
            assert!(!q.choices().is_empty());
        }
        assert_eq!(Quantity::Efficiency.source(), None);
    }

    #[test]
    fn select_restricts_and_names_an_unknown_label() {
        let v = select(Quantity::Bearing, Some(&["palmgren".to_string()])).unwrap();
        assert_eq!(v.len(), 1);
        let e = select(Quantity::Bearing, Some(&["timken".to_string()])).unwrap_err();
        assert!(e.contains("timken") && e.contains("palmgren, skf"), "{e}");
    }
}
