//! The bearing catalogue `models/bearings.toml` (compiled into the binary): dimensions, C0 and
//! the SKF series constants of each bearing, with their sources.

use serde::{Deserialize, Serialize};

/// The catalogue text (kept in the repository as `models/bearings.toml` with each value's source).
pub const BEARINGS_TOML: &str = include_str!("../../models/bearings.toml");

/// Bearing type.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum BearingType {
    /// Deep-groove ball bearing.
    DeepGrooveBall,
    /// Single-row angular-contact ball bearing.
    AngularContactBall,
    /// Four-point-contact ball bearing (QJ).
    FourPointContactBall,
    /// Cylindrical roller bearing with cage.
    CylindricalRoller,
    /// Tapered roller bearing.
    TaperedRoller,
    /// Needle roller bearing.
    NeedleRoller,
}

impl BearingType {
    /// Palmgren factors (f0 oil bath, f1, load factors of P1 = max(F_r, a·F_a + r·F_r)) of this
    /// type. Source: thermca `bearing.heat_loss` (Palmgren model after \[Jun10\], load formulas
    /// after \[Sch13\]), github.com/thermca (see docs/physics.md §Bearings); f1 "for 10 % dynamic
    /// load".
    pub fn palmgren_defaults(self) -> (f64, f64, f64, f64) {
        match self {
            BearingType::DeepGrooveBall => (2.0, 0.00022, 3.3, -0.1),
            BearingType::AngularContactBall => (3.3, 0.00046, 1.0, -0.1),
            BearingType::FourPointContactBall => (6.0, 0.00046, 1.5, 3.6),
            BearingType::TaperedRoller => (6.0, 0.00040, 0.0, 1.0),
            BearingType::CylindricalRoller => (3.0, 0.00030, 0.0, 1.0),
            BearingType::NeedleRoller => (12.0, 0.00200, 0.0, 1.0),
        }
    }

    /// True for the types the SKF model covers here (their table rows were found; needle roller
    /// bearings have no row in any source found).
    pub fn has_skf(self) -> bool {
        !matches!(self, BearingType::NeedleRoller)
    }

    /// Roller (line-contact) type: μ_EHL and the drag form differ from ball bearings.
    pub fn is_roller(self) -> bool {
        matches!(
            self,
            BearingType::CylindricalRoller | BearingType::TaperedRoller | BearingType::NeedleRoller
        )
    }
}

/// SKF constants of a bearing series in the catalogue.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeriesEntry {
    /// Series key (e.g. `"62"`).
    pub series: String,
    /// Bearing type the row applies to.
    #[serde(rename = "type")]
    pub kind: BearingType,
    /// R1, R2, R3 (R3 angular and four-point contact only), S1, S2, S3.
    pub r1: f64,
    /// R2 (0 where the form has none: cylindrical roller).
    #[serde(default)]
    pub r2: f64,
    /// R3.
    #[serde(default)]
    pub r3: f64,
    /// S1.
    pub s1: f64,
    /// S2.
    pub s2: f64,
    /// S3 (angular and four-point contact only).
    #[serde(default)]
    pub s3: f64,
    /// K_z.
    pub k_z: f64,
    /// K_L (roller bearings' drag term; 0 for ball bearings).
    #[serde(default)]
    pub k_l: f64,
    /// Source.
    pub source: String,
}

/// One catalogue bearing.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CatalogueBearing {
    /// Designation (e.g. `"6206"`, `"NJ 406"`).
    pub designation: String,
    /// Type.
    #[serde(rename = "type")]
    pub kind: BearingType,
    /// SKF series key (types with an SKF row).
    #[serde(default)]
    pub series: Option<String>,
    /// Bore d, mm.
    pub d_mm: f64,
    /// Outside diameter D, mm.
    pub outside_mm: f64,
    /// Width B, mm.
    pub b_mm: f64,
    /// Basic static load rating C0, kN.
    pub c0_kn: f64,
    /// Rows of rolling elements (default 1).
    #[serde(default)]
    pub rows: Option<f64>,
    /// Axial load factor Y (tapered roller bearings: required by the SKF form).
    #[serde(default)]
    pub y: Option<f64>,
    /// Source of the dimensions and C0.
    pub source: String,
}

#[derive(Deserialize)]
struct CatalogueFile {
    series: Vec<SeriesEntry>,
    bearing: Vec<CatalogueBearing>,
}

/// All catalogue series and bearings, parsed once per process (a parse failure is a build defect
/// caught by a unit test; reported as an empty catalogue).
pub fn catalogue() -> (&'static [SeriesEntry], &'static [CatalogueBearing]) {
    static PARSED: std::sync::OnceLock<(Vec<SeriesEntry>, Vec<CatalogueBearing>)> =
        std::sync::OnceLock::new();
    let (s, b) = PARSED.get_or_init(|| {
        toml::from_str::<CatalogueFile>(BEARINGS_TOML)
            .map(|c| (c.series, c.bearing))
            .unwrap_or_default()
    });
    (s, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_parses_and_every_entry_is_sourced() {
        let c: CatalogueFile = toml::from_str(BEARINGS_TOML).unwrap();
        assert!(!c.series.is_empty() && !c.bearing.is_empty());
        for s in &c.series {
            assert!(
                s.r1 > 0.0 && s.s1 > 0.0 && s.k_z > 0.0 && !s.source.is_empty(),
                "{}",
                s.series
            );
            assert!(s.kind.has_skf(), "{}: no SKF form for {:?}", s.series, s.kind);
            // Roller rows carry K_L (drag); the angular forms carry R3 and S3.
            assert_eq!(s.kind.is_roller(), s.k_l > 0.0, "{}", s.series);
            if matches!(
                s.kind,
                BearingType::AngularContactBall | BearingType::FourPointContactBall
            ) {
                assert!(s.r3 > 0.0 && s.s3 > 0.0, "{}", s.series);
            }
        }
        for b in &c.bearing {
            assert!(
                b.d_mm > 0.0 && b.outside_mm > b.d_mm && b.c0_kn > 0.0,
                "{}",
                b.designation
            );
            assert!(!b.source.is_empty());
            if let Some(s) = &b.series {
                assert!(
                    c.series.iter().any(|x| &x.series == s && x.kind == b.kind),
                    "{}",
                    b.designation
                );
            }
            if b.kind == BearingType::TaperedRoller {
                assert!(b.y.is_some_and(|y| y > 0.0), "{}: Y", b.designation);
            }
        }
        let mut names: Vec<&str> = c.bearing.iter().map(|b| b.designation.as_str()).collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(n, names.len(), "duplicate designation");
    }
}
