//! The oil catalogue `models/oils.toml`, compiled into the binary so a model file can name an oil
//! without any other file present.

use serde::Deserialize;

/// The catalogue text (kept in the repository as `models/oils.toml`, with each oil's source).
pub const OILS_TOML: &str = include_str!("../../models/oils.toml");

/// One catalogue entry (units in the keys).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CatalogueOil {
    /// Short key, e.g. `fva_3a`.
    pub key: String,
    /// Full name.
    pub name: String,
    /// Other names the oil's sources use for it (e.g. the FEUP/INEGI group's oil codes).
    #[serde(default)]
    pub aliases: Vec<String>,
    /// ν at 40 °C, cSt.
    pub nu40_cst: f64,
    /// ν at 100 °C, cSt.
    pub nu100_cst: f64,
    /// Density at 15 °C, kg/m³.
    pub rho15_kg_m3: f64,
    /// α_T, 1/K.
    pub thermal_expansion_per_k: f64,
    /// True when the source gave no density and a value was assumed.
    #[serde(default)]
    pub density_assumed: bool,
    /// Why the density is what it is, when assumed.
    #[serde(default)]
    pub density_note: Option<String>,
    /// Base stock (absent: not stated by the source).
    #[serde(default)]
    pub base: Option<crate::physics::oil::BaseOil>,
    /// Lubricant factor X_L measured for this oil.
    #[serde(default)]
    pub lubricant_factor: Option<f64>,
    /// Where the X_L comes from (required with `lubricant_factor`).
    #[serde(default)]
    pub lubricant_factor_source: Option<String>,
    /// Fitted SKF (μ_bl, μ_EHL) of roller bearings in this oil.
    #[serde(default)]
    pub bearing_mu_roller: Option<[f64; 2]>,
    /// Fitted SKF (μ_bl, μ_EHL) of ball bearings in this oil.
    #[serde(default)]
    pub bearing_mu_ball: Option<[f64; 2]>,
    /// Where the bearing μ come from.
    #[serde(default)]
    pub bearing_mu_source: Option<String>,
    /// Where the data come from.
    pub source: String,
}

#[derive(Deserialize)]
struct CatalogueFile {
    oil: Vec<CatalogueOil>,
}

/// All catalogue oils.
pub fn oils() -> Vec<CatalogueOil> {
    parsed().to_vec()
}

/// The catalogue, parsed once per process. The embedded file is checked by a unit test, so a
/// parse failure here is a build defect, reported as an empty catalogue rather than a panic.
fn parsed() -> &'static [CatalogueOil] {
    static OILS: std::sync::OnceLock<Vec<CatalogueOil>> = std::sync::OnceLock::new();
    OILS.get_or_init(|| {
        toml::from_str::<CatalogueFile>(OILS_TOML)
            .map(|c| c.oil)
            .unwrap_or_default()
    })
}

/// Find an oil by key, alias or name (case-insensitive; a name prefix up to its first parenthesis,
/// e.g. "FVA 3A reference oil", also matches).
pub fn find(name: &str) -> Option<CatalogueOil> {
    let want = name.trim().to_lowercase();
    parsed()
        .iter()
        .find(|o| {
            o.key.to_lowercase() == want
                || o.aliases.iter().any(|a| a.to_lowercase() == want)
                || o.name.to_lowercase() == want
                || o.name
                    .split('(')
                    .next()
                    .is_some_and(|short| short.trim().to_lowercase() == want)
        })
        .cloned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_parses_and_has_every_oil() {
        let all: Vec<CatalogueOil> = toml::from_str::<CatalogueFile>(OILS_TOML).unwrap().oil;
        assert_eq!(all.len(), 27);
        for o in &all {
            assert!(o.nu40_cst > o.nu100_cst && o.nu100_cst > 0.0, "{}", o.key);
            assert!((700.0..1100.0).contains(&o.rho15_kg_m3), "{}", o.key);
            assert!(!o.source.is_empty());
            // a measured X_L carries its source
            assert_eq!(
                o.lubricant_factor.is_some(),
                o.lubricant_factor_source.is_some(),
                "{}",
                o.key
            );
        }
        // the FZG group's tested oils, by GEARpie's names, with their fitted X_L
        for (k, xl) in [
            ("m100", 0.846),
            ("m320", 0.846),
            ("e320", 0.65),
            ("g320", 0.585),
            ("p150", 0.65),
            ("p320", 0.65),
            ("prp", 0.65),
        ] {
            assert_eq!(find(k).and_then(|o| o.lubricant_factor), Some(xl), "{k}");
        }
        // the FEUP/INEGI group's oil codes name the catalogue oils they are
        for (code, key) in [
            ("MINR", "m320"),
            ("PAOR", "p320"),
            ("ESTR", "e320"),
            ("PAGD", "g320"),
            ("MINE", "mine"),
            ("p150", "p150"),
        ] {
            assert_eq!(find(code).map(|o| o.key), Some(key.to_string()), "{code}");
        }
        // MINE: its source's μ pairs, and no fitted X_L (the code's is its base class's)
        let mine = find("MINE").unwrap();
        assert_eq!(mine.bearing_mu_roller, Some([0.0435, 0.0078]));
        assert_eq!(mine.bearing_mu_ball, Some([0.044, 0.027]));
        assert!(mine.lubricant_factor.is_none());
        // every key and alias names one oil only
        let mut names: Vec<String> = all
            .iter()
            .flat_map(|o| {
                std::iter::once(o.key.to_lowercase()).chain(o.aliases.iter().map(|a| a.to_lowercase()))
            })
            .collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n);
        assert!(find("w211").is_some() && find("W326").is_some());
        assert!(find("FVA 3A reference oil").is_some());
        assert!(find("no such oil").is_none());
    }
}
