//! `[[thermal.coolers]]`: heat exchangers `Q = ε·C_min·x(T_hot)·(T_hot − T_cold)` with an optional
//! thermostat on the hot side; the capacity rate of a fixed-speed fan's air stream optionally
//! follows the air's density.

use crate::physics::units::c_to_k;
use serde::{Deserialize, Serialize};

use super::common::{temp_ok, NodeNames, NodeRef};
use crate::model::problems::Problems;

/// Thermostat: closed below `open_c`, fully open above `full_c`, smooth in between.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ThermostatSpec {
    /// Start of opening, °C.
    pub open_c: f64,
    /// Fully open, °C.
    pub full_c: f64,
}

/// `[[thermal.coolers]]` as written: a heat exchanger `Q = ε·C_min·x(T_hot)·(T_hot − T_cold)`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CoolerSpec {
    /// Display name.
    pub name: String,
    /// Node on the oil side (its temperature drives the thermostat).
    pub hot: String,
    /// Node on the coolant side (usually a boundary).
    pub cold: String,
    /// Effectiveness ε, 0..1.
    pub effectiveness: f64,
    /// Smaller capacity rate ṁ·c_p of the two streams, W/K.
    pub capacity_rate_w_per_k: f64,
    /// Optional thermostat on the hot side.
    #[serde(default)]
    pub thermostat: Option<ThermostatSpec>,
    /// Two-way exchanger (ATF warmer/cooler): while the cold side is warmer than the hot side
    /// the exchanger is fully open and heats the oil (the thermostat throttles only the cooling
    /// direction). Default false: a cooler that never heats.
    #[serde(default)]
    pub two_way: bool,
    /// An air cooler whose fan runs at a fixed speed: `capacity_rate_w_per_k` is the air
    /// stream's, stated at this air temperature (°C), and scales with the air's density as
    /// T_ref/T_cold (K) with the cold-side temperature at each evaluation
    /// ([`crate::physics::thermal::fixed_fan_density_factor`]). Absent: a fixed capacity rate.
    #[serde(default)]
    pub air_density_reference_c: Option<f64>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// A checked cooler.
#[derive(Debug, Clone)]
pub struct Cooler {
    /// Name.
    pub name: String,
    /// Hot (oil) side.
    pub hot: NodeRef,
    /// Cold side.
    pub cold: NodeRef,
    /// ε·C_min, W/K.
    pub conductance: f64,
    /// Thermostat (open, full) in K.
    pub thermostat: Option<(f64, f64)>,
    /// Heats the oil, fully open, while the cold side is the warmer one.
    pub two_way: bool,
    /// Air temperature (K) at which `conductance` holds for a fixed-speed fan's air stream; the
    /// conductance scales as this over the cold side's temperature. None: fixed.
    pub air_density_reference_k: Option<f64>,
}

/// Check every cooler: its two sides (the hot one a node with capacity), effectiveness, capacity
/// rate, thermostat.
pub(crate) fn check_coolers(
    specs: &[CoolerSpec],
    names: &NodeNames<'_>,
    problems: &mut Problems,
) -> Vec<Cooler> {
    let mut coolers = Vec::new();
    for (i, c) in specs.iter().enumerate() {
        let p = format!("thermal.coolers[{i}]");
        let hot = names.resolve(problems, &format!("{p}.hot"), &c.hot);
        let cold = names.resolve(problems, &format!("{p}.cold"), &c.cold);
        if c.hot == c.cold {
            problems.push(format!("{p}.cold"), &c.cold, "must differ from hot");
        }
        if matches!(hot, Some(NodeRef::Boundary(_))) {
            problems.push(
                format!("{p}.hot"),
                &c.hot,
                "the hot side must be a node with capacity",
            );
        }
        problems.in_range(&format!("{p}.effectiveness"), c.effectiveness, 0.0, 1.0, "");
        problems.in_range(
            &format!("{p}.capacity_rate_w_per_k"),
            c.capacity_rate_w_per_k,
            0.0,
            1e7,
            " W/K",
        );
        let thermostat = c.thermostat.as_ref().map(|t| thermostat(t, &p, problems));
        if let Some(t) = c.air_density_reference_c {
            temp_ok(problems, &format!("{p}.air_density_reference_c"), t);
        }
        if let (Some(hot), Some(cold)) = (hot, cold) {
            coolers.push(Cooler {
                name: c.name.clone(),
                hot,
                cold,
                conductance: c.effectiveness * c.capacity_rate_w_per_k,
                thermostat,
                two_way: c.two_way,
                air_density_reference_k: c.air_density_reference_c.map(c_to_k),
            });
        }
    }
    coolers
}

/// Thermostat (open, full) in K: both temperatures in range, fully open above the opening.
fn thermostat(t: &ThermostatSpec, p: &str, problems: &mut Problems) -> (f64, f64) {
    let ok = temp_ok(problems, &format!("{p}.thermostat.open_c"), t.open_c)
        & temp_ok(problems, &format!("{p}.thermostat.full_c"), t.full_c);
    if ok && t.full_c <= t.open_c {
        problems.push(format!("{p}.thermostat.full_c"), t.full_c, "must be above open_c");
    }
    (c_to_k(t.open_c), c_to_k(t.full_c))
}
