//! The loss sources: the kinds of loss item a gearbox has. The list lives at the model layer
//! because the model file names sources (heat rules `source = "…"`, items `"<source>:<name>"`);
//! the scene, solvers and reports index per-source arrays by it.

use super::choice::{choice, Choice};

/// Heat source kind. To add a source: add a variant here, to [`Source::ALL`] and to its
/// names (the `choice!` below), to the item names the model validation knows
/// (`model::thermal::LossItemNames`) and to the scene that compiles its items; per-source
/// arrays ([`PerSource`]), output columns (`<source>_w`), summary keys and heat-rule names
/// follow from this list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Source {
    /// Oil drag on an immersed gear (load-independent).
    Churning,
    /// Oil squeezed out of closing tooth spaces (load-independent).
    Pocketing,
    /// Mesh friction (load-dependent).
    Sliding,
    /// Rolling-bearing friction (SKF 2004 or Palmgren; load- and speed-dependent).
    Bearing,
    /// Radial lip-seal friction (speed-dependent).
    Seal,
    /// Drag of open wet clutches and brakes (slip- and viscosity-dependent).
    ClutchDrag,
    /// Oil-pump drive power (line pressure and pump speed).
    Pump,
    /// Torque-converter slip (engine side minus turbine side power).
    Converter,
}
choice!(Source {
    Churning = "churning",
    Pocketing = "pocketing",
    Sliding = "sliding",
    Bearing = "bearing",
    Seal = "seal",
    ClutchDrag = "clutch_drag",
    Pump = "pump",
    Converter = "converter",
});

/// Number of loss sources.
pub const N_SOURCES: usize = Source::ALL.len();

/// One value per source, indexed by [`Source::index`].
pub type PerSource = [f64; N_SOURCES];

impl Source {
    /// Every source in output order (the order of per-source arrays and columns).
    pub const ALL: [Source; 8] = [
        Source::Churning,
        Source::Pocketing,
        Source::Sliding,
        Source::Bearing,
        Source::Seal,
        Source::ClutchDrag,
        Source::Pump,
        Source::Converter,
    ];

    /// Position in per-source arrays (the order of [`Source::ALL`]).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name (output columns `<name>_w`, summary keys, heat rules `<name>:<item>`).
    pub fn as_str(self) -> &'static str {
        self.name()
    }

    /// The source named `s`.
    pub fn parse(s: &str) -> Option<Source> {
        Source::from_name(s)
    }

    /// The names of all sources, comma-separated (for error messages).
    pub fn names() -> String {
        Source::ALL.map(Source::as_str).join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_is_the_position_in_all_and_names_round_trip() {
        assert_eq!(Source::NAMES.len(), Source::ALL.len());
        for (k, s) in Source::ALL.into_iter().enumerate() {
            assert_eq!(s.index(), k);
            assert_eq!(Source::parse(s.as_str()), Some(s));
        }
        assert_eq!(Source::parse("windage"), None);
        // The model file reads a source by the same name (heat rules `source = "…"`).
        for s in Source::ALL {
            let v: Source = serde_json::from_value(serde_json::Value::from(s.as_str())).unwrap();
            assert_eq!(v, s);
        }
    }
}
