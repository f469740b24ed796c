//! The vehicle: the model file's `[vehicle]` section ([`VehicleSpec`], serde, units in the keys),
//! its validation into a checked [`Vehicle`] (SI inside), and the longitudinal dynamics
//! (road load, mean traction force and power over an interval with linear speed).
//!
//! Physics (physics.md §9) \[std\]: wheel force F_w = m_eff·a + F_road(v), with
//! m_eff = m·(1 + rotating_mass_factor) and F_road = F0 + F1·v + F2·v² (coast-down form), or
//! F_road = m·g·c_rr·cos θ + ½·ρ_air·c_d·A·v² (physical form), plus m·g·sin θ on a grade θ.
//! Wheel torque T_w = r_w·F_w, gearbox output torque T_out = T_w / i_final.

use super::error::{CycleError, CycleErrorKind};
use super::gears::GearTable;
use super::parse::{KMH, RPM};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Standard gravity, m/s².
pub const G: f64 = 9.806_65;

fn default_rotating_mass_factor() -> f64 {
    0.05
}
fn default_standstill_kmh() -> f64 {
    0.1
}
fn default_min_hold_s() -> f64 {
    2.0
}

/// What the gearbox transmits when the wheels demand negative torque (braking / coasting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Overrun {
    /// The service brakes take all negative demand; the gearbox transmits zero torque (it still
    /// spins with the wheels, so drag losses remain). Default.
    #[default]
    Zero,
    /// The negative torque passes through the gearbox (engine braking / recuperation).
    Transmit,
}

/// `[vehicle.road_load]`: either the coast-down coefficients (`f0_n`, `f1_n_per_mps`,
/// `f2_n_per_mps2`) or the physical parameters (`drag_coefficient`, `frontal_area_m2`,
/// `rolling_resistance`, `air_density_kg_m3`), not both.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RoadLoadSpec {
    /// Coast-down F0, N.
    #[serde(default)]
    pub f0_n: Option<f64>,
    /// Coast-down F1, N/(m/s) (default 0; may be slightly negative in fitted data).
    #[serde(default)]
    pub f1_n_per_mps: Option<f64>,
    /// Coast-down F2, N/(m/s)².
    #[serde(default)]
    pub f2_n_per_mps2: Option<f64>,
    /// Aerodynamic drag coefficient c_d.
    #[serde(default)]
    pub drag_coefficient: Option<f64>,
    /// Frontal area A, m².
    #[serde(default)]
    pub frontal_area_m2: Option<f64>,
    /// Rolling-resistance coefficient c_rr.
    #[serde(default)]
    pub rolling_resistance: Option<f64>,
    /// Air density, kg/m³ (default 1.2).
    #[serde(default)]
    pub air_density_kg_m3: Option<f64>,
}

/// `[vehicle.shift]`: shift strategy on gearbox input speed with hysteresis.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftSpec {
    /// Forward gear-state names, lowest (launch) gear first.
    pub gears: Vec<String>,
    /// `upshift_rpm[i]`: shift `gears[i]` → `gears[i+1]` when the input speed exceeds it (n−1 values).
    pub upshift_rpm: Vec<f64>,
    /// `downshift_rpm[i]`: shift `gears[i+1]` → `gears[i]` when the input speed falls below it.
    pub downshift_rpm: Vec<f64>,
    /// Minimum time in a gear before the next shift, s (default 2).
    #[serde(default = "default_min_hold_s")]
    pub min_hold_s: f64,
}

/// The model file's `[vehicle]` section as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleSpec {
    /// Test mass, kg.
    pub mass_kg: f64,
    /// Rotating-mass factor: m_eff = m·(1 + factor) (default 0.05).
    #[serde(default = "default_rotating_mass_factor")]
    pub rotating_mass_factor: f64,
    /// Dynamic wheel radius, m.
    pub wheel_radius_m: f64,
    /// Final drive (axle) ratio, gearbox output speed / wheel speed.
    pub final_drive_ratio: f64,
    /// Road load.
    pub road_load: RoadLoadSpec,
    /// Constant road grade, % (rise/run·100; default 0).
    #[serde(default)]
    pub grade_percent: f64,
    /// Negative wheel demand: `"zero"` (default, service brakes) or `"transmit"`.
    #[serde(default)]
    pub overrun: Overrun,
    /// An interval is standstill when the speed at both its ends is below this, km/h (default 0.1).
    #[serde(default = "default_standstill_kmh")]
    pub standstill_below_kmh: f64,
    /// Shift strategy (needed for vehicle cycles without a gear column, unless the gearbox has a
    /// single gear state).
    #[serde(default)]
    pub shift: Option<ShiftSpec>,
}

/// One problem in the `[vehicle]` section (same shape as the model layer's problems).
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleProblem {
    /// Key path, e.g. `vehicle.shift.upshift_rpm[2]`.
    pub path: String,
    /// The offending value as written.
    pub value: String,
    /// What is allowed.
    pub allowed: String,
}

impl fmt::Display for VehicleProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.value.is_empty() {
            write!(f, "{}: {}", self.path, self.allowed)
        } else {
            write!(f, "{} = {}: {}", self.path, self.value, self.allowed)
        }
    }
}

/// Road load in coast-down form (grade folded into `f0`): F = f0 + f1·v + f2·v².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadLoad {
    /// N.
    pub f0: f64,
    /// N/(m/s).
    pub f1: f64,
    /// N/(m/s)².
    pub f2: f64,
}

impl RoadLoad {
    /// Force at speed `v` (m/s), N.
    pub fn force(&self, v: f64) -> f64 {
        self.f0 + self.f1 * v + self.f2 * v * v
    }
}

/// Checked shift strategy (SI). Gear names are bound to gear-table indices at schedule time.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftStrategy {
    /// Forward gear-state names, launch gear first.
    pub gears: Vec<String>,
    /// Upshift input speeds, rad/s (n−1).
    pub upshift: Vec<f64>,
    /// Downshift input speeds, rad/s (n−1).
    pub downshift: Vec<f64>,
    /// Minimum hold time, s.
    pub min_hold: f64,
}

/// A checked vehicle, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Mass, kg.
    pub mass: f64,
    /// Effective (translational + rotating) mass, kg.
    pub effective_mass: f64,
    /// Wheel radius, m.
    pub wheel_radius: f64,
    /// Final drive ratio (−).
    pub final_drive_ratio: f64,
    /// Road load incl. grade.
    pub road_load: RoadLoad,
    /// Overrun policy.
    pub overrun: Overrun,
    /// Standstill threshold, m/s.
    pub standstill_speed: f64,
    /// Shift strategy, if configured.
    pub shift: Option<ShiftStrategy>,
}

/// Mean traction demand over an interval with linear speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Demand {
    /// Mean speed (v0+v1)/2, m/s.
    pub mean_speed: f64,
    /// Acceleration, m/s².
    pub acceleration: f64,
    /// Mean wheel force, N.
    pub mean_force: f64,
    /// Mean wheel (= loss-free gearbox output) power, W.
    pub mean_power: f64,
}

impl Vehicle {
    /// Mean demand over [t0, t0+dt] with the speed linear from `v0` to `v1` (m/s) \[derived\]:
    /// a = (v1−v0)/dt; mean(v) = (v0+v1)/2; mean(v²) = (v0²+v0·v1+v1²)/3;
    /// mean(v³) = (v0+v1)(v0²+v1²)/4 (exact integrals of the powers of a linear function).
    /// mean force = m_eff·a + f0 + f1·mean(v) + f2·mean(v²);
    /// mean power = m_eff·a·mean(v) + f0·mean(v) + f1·mean(v²) + f2·mean(v³),
    /// so that Σ mean_power·dt is the exact traction energy of the piecewise-linear trace.
    /// Precondition: dt > 0.
    pub fn demand(&self, v0: f64, v1: f64, dt: f64) -> Demand {
        let a = (v1 - v0) / dt;
        let m1 = 0.5 * (v0 + v1);
        let m2 = (v0 * v0 + v0 * v1 + v1 * v1) / 3.0;
        let m3 = 0.25 * (v0 + v1) * (v0 * v0 + v1 * v1);
        let RoadLoad { f0, f1, f2 } = self.road_load;
        let me = self.effective_mass;
        Demand {
            mean_speed: m1,
            acceleration: a,
            mean_force: me * a + f0 + f1 * m1 + f2 * m2,
            mean_power: me * a * m1 + f0 * m1 + f1 * m2 + f2 * m3,
        }
    }

    /// Gearbox output speed at vehicle speed `v` (m/s), rad/s: v·i_final/r_w.
    pub fn output_speed(&self, v: f64) -> f64 {
        v * self.final_drive_ratio / self.wheel_radius
    }
}

impl VehicleSpec {
    /// Deserialize the `[vehicle]` table (as the model layer keeps it) into a spec.
    pub fn from_table(table: &toml::Table) -> Result<VehicleSpec, Vec<VehicleProblem>> {
        toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| {
                vec![VehicleProblem {
                    path: "vehicle".into(),
                    value: String::new(),
                    allowed: e.message().to_string(),
                }]
            })
    }

    /// Check every value and turn the spec into a [`Vehicle`] (SI), or list every problem.
    /// `gears` gives the model's gear states and their ratios ω_in/ω_out (used for the shift
    /// gear names and the hysteresis checks).
    pub fn validate(&self, gears: &GearTable) -> Result<Vehicle, Vec<VehicleProblem>> {
        let mut p = Check::default();
        p.range("vehicle.mass_kg", self.mass_kg, 1.0, 1e5, "kg");
        p.range(
            "vehicle.rotating_mass_factor",
            self.rotating_mass_factor,
            0.0,
            1.0,
            "",
        );
        p.range("vehicle.wheel_radius_m", self.wheel_radius_m, 0.1, 1.0, "m");
        p.range("vehicle.final_drive_ratio", self.final_drive_ratio, 1.0, 20.0, "");
        p.range("vehicle.grade_percent", self.grade_percent, -30.0, 30.0, "%");
        p.range(
            "vehicle.standstill_below_kmh",
            self.standstill_below_kmh,
            0.0,
            10.0,
            "km/h",
        );

        let road = self.road_load(&mut p);
        let shift = self.shift.as_ref().map(|s| check_shift(s, gears, &mut p));

        if !p.list.is_empty() {
            return Err(p.list);
        }
        let theta = (self.grade_percent / 100.0).atan();
        let mut road_load = road.unwrap_or(RoadLoad {
            f0: 0.0,
            f1: 0.0,
            f2: 0.0,
        });
        road_load.f0 += self.mass_kg * G * theta.sin();
        Ok(Vehicle {
            mass: self.mass_kg,
            effective_mass: self.mass_kg * (1.0 + self.rotating_mass_factor),
            wheel_radius: self.wheel_radius_m,
            final_drive_ratio: self.final_drive_ratio,
            road_load,
            overrun: self.overrun,
            standstill_speed: self.standstill_below_kmh * KMH,
            shift: shift.flatten(),
        })
    }

    /// Road load without grade (rolling resistance gets cos θ).
    fn road_load(&self, p: &mut Check) -> Option<RoadLoad> {
        let r = &self.road_load;
        let coast = [r.f0_n, r.f1_n_per_mps, r.f2_n_per_mps2]
            .iter()
            .any(Option::is_some);
        let phys = [
            r.drag_coefficient,
            r.frontal_area_m2,
            r.rolling_resistance,
            r.air_density_kg_m3,
        ]
        .iter()
        .any(Option::is_some);
        const BOTH: &str = "give either f0_n, f1_n_per_mps, f2_n_per_mps2 (coast-down) or drag_coefficient, \
                            frontal_area_m2, rolling_resistance[, air_density_kg_m3] (physical)";
        match (coast, phys) {
            (true, true) => {
                p.push("vehicle.road_load", "", format!("both forms given: {BOTH}"));
                None
            }
            (false, false) => {
                p.push("vehicle.road_load", "", format!("empty: {BOTH}"));
                None
            }
            (true, false) => {
                let f0 = p.required("vehicle.road_load.f0_n", r.f0_n, 0.0, 1e5, "N");
                let f1 = p.range(
                    "vehicle.road_load.f1_n_per_mps",
                    r.f1_n_per_mps.unwrap_or(0.0),
                    -1e3,
                    1e3,
                    "N/(m/s)",
                );
                let f2 = p.required(
                    "vehicle.road_load.f2_n_per_mps2",
                    r.f2_n_per_mps2,
                    0.0,
                    1e2,
                    "N/(m/s)^2",
                );
                let rl = RoadLoad {
                    f0: f0?,
                    f1: f1?,
                    f2: f2?,
                };
                // F(v) ≥ 0 on 0..70 m/s: check the ends and the vertex.
                let vmax = 70.0;
                let mut vs = vec![0.0, vmax];
                if rl.f2 > 0.0 {
                    vs.push((-rl.f1 / (2.0 * rl.f2)).clamp(0.0, vmax));
                }
                if vs.iter().any(|&v| rl.force(v) < 0.0) {
                    p.push(
                        "vehicle.road_load",
                        format!("f0 = {}, f1 = {}, f2 = {}", rl.f0, rl.f1, rl.f2),
                        "the road load must be >= 0 N for 0..252 km/h",
                    );
                    return None;
                }
                Some(rl)
            }
            (false, true) => {
                let cd = p.required(
                    "vehicle.road_load.drag_coefficient",
                    r.drag_coefficient,
                    0.0,
                    2.0,
                    "",
                );
                let a = p.required(
                    "vehicle.road_load.frontal_area_m2",
                    r.frontal_area_m2,
                    0.0,
                    20.0,
                    "m^2",
                );
                let crr = p.required(
                    "vehicle.road_load.rolling_resistance",
                    r.rolling_resistance,
                    0.0,
                    0.1,
                    "",
                );
                let rho = p.range(
                    "vehicle.road_load.air_density_kg_m3",
                    r.air_density_kg_m3.unwrap_or(1.2),
                    0.5,
                    2.0,
                    "kg/m^3",
                );
                let cos = (self.grade_percent / 100.0).atan().cos();
                Some(RoadLoad {
                    f0: self.mass_kg * G * crr? * cos,
                    f1: 0.0,
                    f2: 0.5 * rho? * cd? * a?,
                })
            }
        }
    }
}

fn check_shift(s: &ShiftSpec, gears: &GearTable, p: &mut Check) -> Option<ShiftStrategy> {
    let n = s.gears.len();
    let before = p.list.len();
    if n == 0 {
        p.push(
            "vehicle.shift.gears",
            "[]",
            "list at least one forward gear state",
        );
    }
    let mut ratios = Vec::with_capacity(n);
    for (i, g) in s.gears.iter().enumerate() {
        let path = format!("vehicle.shift.gears[{i}]");
        if s.gears[..i].contains(g) {
            p.push(&path, g, "listed twice");
        }
        match gears.index_of(g) {
            None => p.push(
                &path,
                g,
                format!("not a gear state of the model ({})", gears.names().join(", ")),
            ),
            Some(k) => {
                let r = gears.states[k].1;
                if !(r.is_finite() && r > 0.0) {
                    p.push(
                        &path,
                        g,
                        format!("a forward gear needs a positive ratio, this state has {r}"),
                    );
                } else if let Some(&prev) = ratios.last() {
                    if r >= prev {
                        p.push(
                            &path,
                            g,
                            format!("ratios must decrease from gear to gear ({r} after {prev})"),
                        );
                    }
                }
                ratios.push(r);
            }
        }
    }
    for (key, v) in [
        ("upshift_rpm", &s.upshift_rpm),
        ("downshift_rpm", &s.downshift_rpm),
    ] {
        if v.len() != n.saturating_sub(1) {
            p.push(
                format!("vehicle.shift.{key}"),
                format!("{} values", v.len()),
                format!("needs {} values (one per gear pair)", n.saturating_sub(1)),
            );
        }
        for (i, &x) in v.iter().enumerate() {
            p.range(&format!("vehicle.shift.{key}[{i}]"), x, 1.0, 30_000.0, "rpm");
        }
    }
    p.range("vehicle.shift.min_hold_s", s.min_hold_s, 0.0, 60.0, "s");
    if p.list.len() > before {
        return None;
    }
    // Pairwise hysteresis checks (all inputs valid here).
    let (up, down) = (&s.upshift_rpm, &s.downshift_rpm);
    for i in 0..n - 1 {
        if down[i] >= up[i] {
            p.push(
                format!("vehicle.shift.downshift_rpm[{i}]"),
                down[i],
                format!("must be below upshift_rpm[{i}] = {}", up[i]),
            );
        }
        // After the upshift i → i+1 at up[i] the input speed drops to up[i]·r(i+1)/r(i); it must
        // stay above down[i], else the box shifts straight back (equivalently: after the
        // downshift i+1 → i at down[i] the input speed down[i]·r(i)/r(i+1) stays below up[i]).
        let after = up[i] * ratios[i + 1] / ratios[i];
        if after <= down[i] {
            p.push(
                format!("vehicle.shift.downshift_rpm[{i}]"),
                down[i],
                format!(
                    "must be below {after:.0} rpm: after the upshift at upshift_rpm[{i}] = {} the input speed \
                     falls to {after:.0} rpm and would shift straight back",
                    up[i]
                ),
            );
        }
        // Output-speed (vehicle-speed) thresholds must increase with the gear.
        if i + 1 < n - 1 {
            for (key, v, r) in [
                ("upshift_rpm", up, (ratios[i], ratios[i + 1])),
                ("downshift_rpm", down, (ratios[i + 1], ratios[i + 2])),
            ] {
                let (w0, w1) = (v[i] / r.0, v[i + 1] / r.1);
                if w1 <= w0 {
                    p.push(
                        format!("vehicle.shift.{key}[{}]", i + 1),
                        v[i + 1],
                        format!(
                            "the output speed at this threshold ({w1:.0} rpm) must exceed the previous one ({w0:.0} rpm)"
                        ),
                    );
                }
            }
        }
    }
    Some(ShiftStrategy {
        gears: s.gears.clone(),
        upshift: up.iter().map(|x| x * RPM).collect(),
        downshift: down.iter().map(|x| x * RPM).collect(),
        min_hold: s.min_hold_s,
    })
}

/// Collects problems.
#[derive(Default)]
struct Check {
    list: Vec<VehicleProblem>,
}

impl Check {
    fn push(&mut self, path: impl Into<String>, value: impl fmt::Display, allowed: impl Into<String>) {
        self.list.push(VehicleProblem {
            path: path.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        });
    }

    /// `v` finite and within [lo, hi].
    fn range(&mut self, path: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Option<f64> {
        if v.is_finite() && (lo..=hi).contains(&v) {
            Some(v)
        } else {
            let unit = if unit.is_empty() {
                String::new()
            } else {
                format!(" {unit}")
            };
            self.push(path, v, format!("must lie in [{lo}, {hi}]{unit}"));
            None
        }
    }

    fn required(&mut self, path: &str, v: Option<f64>, lo: f64, hi: f64, unit: &str) -> Option<f64> {
        match v {
            Some(v) => self.range(path, v, lo, hi, unit),
            None => {
                self.push(path, "", "missing");
                None
            }
        }
    }
}

/// Convert vehicle problems into one cycle error (for callers that only want a message).
pub fn problems_to_error(source: &str, problems: &[VehicleProblem]) -> CycleError {
    let msgs: Vec<String> = problems.iter().map(ToString::to_string).collect();
    CycleError::new(CycleErrorKind::Config, source, msgs.join("; "))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The 6-speed AT sedan of the docs (ZF 6HP26 ratios).
    pub(crate) fn at6_gears() -> GearTable {
        GearTable::new(
            [
                ("1", 4.171),
                ("2", 2.340),
                ("3", 1.521),
                ("4", 1.143),
                ("5", 0.867),
                ("6", 0.691),
                ("R", -3.403),
            ]
            .iter()
            .map(|(n, r)| (n.to_string(), *r))
            .collect(),
        )
    }

    pub(crate) const AT6_TOML: &str = r#"
[vehicle]
mass_kg = 1900.0
rotating_mass_factor = 0.05
wheel_radius_m = 0.33
final_drive_ratio = 3.2
road_load = { f0_n = 160.0, f1_n_per_mps = 1.2, f2_n_per_mps2 = 0.42 }
[vehicle.shift]
gears = ["1", "2", "3", "4", "5", "6"]
upshift_rpm = [2200.0, 2100.0, 2000.0, 1900.0, 1800.0]
downshift_rpm = [1100.0, 1150.0, 1200.0, 1250.0, 1300.0]
min_hold_s = 2.0
"#;

    #[derive(Deserialize)]
    struct File {
        vehicle: VehicleSpec,
    }

    pub(crate) fn spec(text: &str) -> VehicleSpec {
        toml::from_str::<File>(text).unwrap().vehicle
    }

    pub(crate) fn at6() -> Vehicle {
        spec(AT6_TOML).validate(&at6_gears()).unwrap()
    }

    #[test]
    fn example_vehicle_validates_with_si_values() {
        let v = at6();
        assert_relative_eq!(v.effective_mass, 1995.0, epsilon = 1e-9);
        assert_relative_eq!(v.standstill_speed, 0.1 / 3.6, epsilon = 1e-15);
        assert_eq!(v.overrun, Overrun::Zero);
        let s = v.shift.unwrap();
        assert_relative_eq!(
            s.upshift[0],
            2200.0 * std::f64::consts::PI / 30.0,
            epsilon = 1e-12
        );
        assert_eq!(s.gears.len(), 6);
    }

    #[test]
    fn from_table_matches_from_str_and_rejects_unknown_keys() {
        let t: toml::Table = toml::from_str(AT6_TOML).unwrap();
        let vt = t["vehicle"].as_table().unwrap();
        assert_eq!(VehicleSpec::from_table(vt).unwrap(), spec(AT6_TOML));
        let mut bad = vt.clone();
        bad.insert("mass".into(), toml::Value::Float(1.0));
        let e = VehicleSpec::from_table(&bad).unwrap_err();
        assert!(e[0].allowed.contains("mass"), "{}", e[0]);
    }

    #[test]
    fn physical_road_load_and_grade() {
        let s = spec(
            "[vehicle]\nmass_kg = 1000.0\nwheel_radius_m = 0.3\nfinal_drive_ratio = 4.0\ngrade_percent = 10.0\n\
             road_load = { drag_coefficient = 0.3, frontal_area_m2 = 2.0, rolling_resistance = 0.01 }\n",
        );
        let v = s.validate(&GearTable::new(vec![("1".into(), 1.0)])).unwrap();
        let th = 0.1f64.atan();
        assert_relative_eq!(
            v.road_load.f0,
            1000.0 * G * (0.01 * th.cos() + th.sin()),
            epsilon = 1e-9
        );
        assert_relative_eq!(v.road_load.f2, 0.5 * 1.2 * 0.3 * 2.0, epsilon = 1e-12);
        assert_relative_eq!(v.road_load.f1, 0.0);
        assert_relative_eq!(v.effective_mass, 1050.0, epsilon = 1e-9);
    }

    #[test]
    fn demand_means_match_quadrature() {
        let v = at6();
        let (v0, v1, dt) = (3.0, 7.5, 1.0);
        let d = v.demand(v0, v1, dt);
        // midpoint rule with many points
        let n = 20_000;
        let (mut f, mut pw) = (0.0, 0.0);
        for k in 0..n {
            let s = (k as f64 + 0.5) / n as f64;
            let vs = v0 + (v1 - v0) * s;
            let force = v.effective_mass * (v1 - v0) / dt + v.road_load.force(vs);
            f += force / n as f64;
            pw += force * vs / n as f64;
        }
        assert_relative_eq!(d.mean_force, f, max_relative = 1e-8);
        assert_relative_eq!(d.mean_power, pw, max_relative = 1e-8);
        assert_relative_eq!(d.mean_speed, 5.25);
        // power-consistent force vs mean force (documented difference)
        let dv = v1 - v0;
        let diff = d.mean_power / d.mean_speed - d.mean_force;
        let want = v.road_load.f1 * dv * dv / (12.0 * d.mean_speed) + v.road_load.f2 * dv * dv / 6.0;
        assert_relative_eq!(diff, want, max_relative = 1e-9);
    }

    fn paths(e: &[VehicleProblem]) -> Vec<&str> {
        e.iter().map(|p| p.path.as_str()).collect()
    }

    #[test]
    fn every_problem_is_reported() {
        let s = spec(
            r#"[vehicle]
mass_kg = -5.0
wheel_radius_m = 1.5
final_drive_ratio = 0.5
standstill_below_kmh = -1.0
road_load = { f0_n = 100.0, drag_coefficient = 0.3 }
[vehicle.shift]
gears = ["1", "2", "X", "4"]
upshift_rpm = [2000.0, 2000.0]
downshift_rpm = [1000.0, 1000.0, 1000.0]
min_hold_s = -1.0
"#,
        );
        let e = s.validate(&at6_gears()).unwrap_err();
        let ps = paths(&e);
        for want in [
            "vehicle.mass_kg",
            "vehicle.wheel_radius_m",
            "vehicle.final_drive_ratio",
            "vehicle.standstill_below_kmh",
            "vehicle.road_load",
            "vehicle.shift.gears[2]",
            "vehicle.shift.upshift_rpm",
            "vehicle.shift.min_hold_s",
        ] {
            assert!(ps.contains(&want), "{want} missing from {ps:?}");
        }
        assert!(
            !ps.contains(&"vehicle.shift.downshift_rpm"),
            "3 values for 4 gears is right: {ps:?}"
        );
        let x = e.iter().find(|p| p.path == "vehicle.shift.gears[2]").unwrap();
        assert_eq!(x.value, "X");
        assert!(x.allowed.contains("1, 2, 3, 4, 5, 6, R"), "{x}");
    }

    #[test]
    fn hysteresis_problems() {
        let mut s = spec(AT6_TOML);
        let sh = s.shift.as_mut().unwrap();
        sh.downshift_rpm[0] = 2300.0; // above its upshift
        sh.downshift_rpm[2] = 1600.0; // below up but above up[2]·r3/r2 = 1503 → would shift back
        sh.upshift_rpm[4] = 1400.0; // output speed 1400/0.867 < 1900/1.143: not increasing
        let e = s.validate(&at6_gears()).unwrap_err();
        let ps = paths(&e);
        assert!(
            ps.iter()
                .filter(|p| **p == "vehicle.shift.downshift_rpm[0]")
                .count()
                >= 1,
            "{ps:?}"
        );
        let d2: Vec<_> = e
            .iter()
            .filter(|p| p.path == "vehicle.shift.downshift_rpm[2]")
            .collect();
        assert_eq!(d2.len(), 1, "{e:?}");
        assert!(d2[0].allowed.contains("shift straight back"), "{}", d2[0]);
        assert!(ps.contains(&"vehicle.shift.upshift_rpm[4]"), "{ps:?}");
        // the valid example has no problem at all
        assert!(spec(AT6_TOML).validate(&at6_gears()).is_ok());
    }

    #[test]
    fn shift_gears_must_be_forward_and_descending() {
        let mut s = spec(AT6_TOML);
        let sh = s.shift.as_mut().unwrap();
        sh.gears = vec![
            "2".into(),
            "1".into(),
            "R".into(),
            "4".into(),
            "5".into(),
            "5".into(),
        ];
        let e = s.validate(&at6_gears()).unwrap_err();
        let ps = paths(&e);
        for want in [
            "vehicle.shift.gears[1]",
            "vehicle.shift.gears[2]",
            "vehicle.shift.gears[5]",
        ] {
            assert!(ps.contains(&want), "{want}: {ps:?}");
        }
    }

    #[test]
    fn problems_display_and_join() {
        let p = VehicleProblem {
            path: "vehicle.mass_kg".into(),
            value: "-5".into(),
            allowed: "must be > 0".into(),
        };
        assert_eq!(p.to_string(), "vehicle.mass_kg = -5: must be > 0");
        let e = problems_to_error("m.toml", &[p.clone(), p]);
        assert_eq!(e.kind, CycleErrorKind::Config);
        assert_eq!(
            e.to_string(),
            "m.toml: vehicle.mass_kg = -5: must be > 0; vehicle.mass_kg = -5: must be > 0"
        );
    }

    #[test]
    fn negative_coast_down_load_is_rejected() {
        let s = spec(
            "[vehicle]\nmass_kg = 1000.0\nwheel_radius_m = 0.3\nfinal_drive_ratio = 4.0\n\
             road_load = { f0_n = 10.0, f1_n_per_mps = -5.0, f2_n_per_mps2 = 0.1 }\n",
        );
        let e = s.validate(&GearTable::new(vec![("1".into(), 1.0)])).unwrap_err();
        assert_eq!(paths(&e), vec!["vehicle.road_load"]);
        let s = spec(
            "[vehicle]\nmass_kg = 1000.0\nwheel_radius_m = 0.3\nfinal_drive_ratio = 4.0\n\
             road_load = { f1_n_per_mps = 5.0 }\n",
        );
        let e = s.validate(&GearTable::new(vec![("1".into(), 1.0)])).unwrap_err();
        assert_eq!(
            paths(&e),
            vec!["vehicle.road_load.f0_n", "vehicle.road_load.f2_n_per_mps2"]
        );
    }
}
