//! `[oil]`: a catalogue entry or inline viscosities and density, checked into an [`Oil`].

use serde::{Deserialize, Serialize};

use super::common::q;
use crate::model::catalogue;
use crate::model::choice::choice;
use crate::model::problems::Problems;
use crate::physics::oil::{BaseOil, Oil, WaltherVariant, ALPHA_T_MINERAL, CST};

/// `[oil]` as written: either a catalogue name or inline data.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OilSpec {
    /// Name of an oil in `models/oils.toml` (the catalogue compiled into the binary).
    #[serde(default)]
    pub catalogue: Option<String>,
    /// Display name for an inline oil.
    #[serde(default)]
    pub name: Option<String>,
    /// Kinematic viscosity at 40 °C, cSt (mm²/s).
    #[serde(default)]
    pub nu40_cst: Option<f64>,
    /// Kinematic viscosity at 100 °C, cSt.
    #[serde(default)]
    pub nu100_cst: Option<f64>,
    /// Density at 15 °C, kg/m³.
    #[serde(default)]
    pub rho15_kg_m3: Option<f64>,
    /// Volumetric thermal expansion α_T, 1/K (default −6.5e−4, mineral).
    #[serde(default)]
    pub thermal_expansion_per_k: Option<f64>,
    /// Walther constant: `astm_d341` (0.7, default), `c06` (0.6, seed 001), `c08` (0.8, DIN 51563).
    #[serde(default, deserialize_with = "crate::model::choice::optional")]
    pub walther: Option<WaltherVariant>,
    /// Base stock (`mineral`, `pao`, `ester`, `pag`, ...): sets the default lubricant factor.
    #[serde(default, deserialize_with = "crate::model::choice::optional")]
    pub base: Option<BaseOil>,
    /// Lubricant factor X_L measured for this oil (default: the base's standard value).
    #[serde(default)]
    pub lubricant_factor: Option<f64>,
}

choice!(@names WaltherVariant {
    AstmD341 = "astm_d341",
    C06 = "c06",
    C08 = "c08",
});
choice!(@names BaseOil {
    Mineral = "mineral",
    Pao = "pao",
    Ester = "ester",
    Pag = "pag",
    PagWaterSoluble = "pag_water_soluble",
    PhosphateEster = "phosphate_ester",
    TractionFluid = "traction_fluid",
});

/// Check `[oil]` and build the oil.
pub(crate) fn validate_oil(o: &OilSpec, problems: &mut Problems) -> Option<Oil> {
    let variant = o.walther.unwrap_or(WaltherVariant::AstmD341);
    let inline = o.nu40_cst.is_some() || o.nu100_cst.is_some() || o.rho15_kg_m3.is_some();
    let (name, nu40, nu100, rho15, alpha, base, x_l) = match (&o.catalogue, inline) {
        (Some(_), true) => {
            problems.push(
                "oil",
                "",
                "give either oil.catalogue or inline nu40_cst/nu100_cst/rho15_kg_m3, not both",
            );
            return None;
        }
        (Some(c), false) => match catalogue::find(c) {
            Some(e) => (
                e.name,
                e.nu40_cst,
                e.nu100_cst,
                e.rho15_kg_m3,
                o.thermal_expansion_per_k.unwrap_or(e.thermal_expansion_per_k),
                o.base.or(e.base),
                o.lubricant_factor.or(e.lubricant_factor),
            ),
            None => {
                let keys: Vec<String> = catalogue::oils().into_iter().map(|e| e.key).collect();
                problems.push(
                    "oil.catalogue",
                    q(c),
                    format!("unknown oil; catalogue keys: {}", keys.join(", ")),
                );
                return None;
            }
        },
        (None, _) => {
            let mut miss = false;
            for (k, v) in [
                ("nu40_cst", o.nu40_cst),
                ("nu100_cst", o.nu100_cst),
                ("rho15_kg_m3", o.rho15_kg_m3),
            ] {
                if v.is_none() {
                    problems.push(
                        format!("oil.{k}"),
                        "",
                        "required for an inline oil (or give oil.catalogue)",
                    );
                    miss = true;
                }
            }
            if miss {
                return None;
            }
            (
                o.name.clone().unwrap_or_else(|| "inline oil".into()),
                o.nu40_cst.unwrap_or_default(),
                o.nu100_cst.unwrap_or_default(),
                o.rho15_kg_m3.unwrap_or_default(),
                o.thermal_expansion_per_k.unwrap_or(ALPHA_T_MINERAL),
                o.base,
                o.lubricant_factor,
            )
        }
    };
    let mut ok = problems.in_range("oil.nu40_cst", nu40, 1.0, 10000.0, " cSt");
    ok &= problems.in_range("oil.nu100_cst", nu100, 0.5, 1000.0, " cSt");
    ok &= problems.in_range("oil.rho15_kg_m3", rho15, 600.0, 1200.0, " kg/m3");
    ok &= problems.in_range("oil.thermal_expansion_per_k", alpha, -2e-3, 0.0, " 1/K");
    if let Some(x) = o.lubricant_factor {
        ok &= problems.in_range("oil.lubricant_factor", x, 0.3, 2.0, "");
    }
    if ok && nu40 <= nu100 {
        problems.push(
            "oil.nu100_cst",
            nu100,
            format!("must be less than nu40_cst = {nu40} (oils thin as they warm)"),
        );
        ok = false;
    }
    if !ok {
        return None;
    }
    match Oil::new(name, variant, nu40 * CST, nu100 * CST, rho15, alpha) {
        Ok(oil) => Some(oil.with_lubricant(base, x_l)),
        Err(e) => {
            problems.push("oil", "", e.to_string());
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::choice::Choice;

    /// The model file names an oil's base as the oil catalogue does.
    #[test]
    fn base_names_are_the_physics_names() {
        assert_eq!(BaseOil::NAMES.len(), BaseOil::ALL.len());
        for b in BaseOil::ALL {
            assert_eq!(b.name(), b.as_str());
        }
    }
}
