//! `[vehicle]`, `[vehicle.road_load]` and `[vehicle.shift]`: the vehicle as written (units in the
//! keys) and its checks into a [`Vehicle`] in SI units, the form the cycle layer drives with
//! (longitudinal dynamics and shift rules: [`crate::cycle::vehicle`], [`crate::cycle::shift`]).

use serde::{Deserialize, Serialize};

use crate::cycle::parse::{KMH, RPM};
use crate::cycle::vehicle::G;
use crate::cycle::{GearTable, Overrun, RoadLoad, ShiftStrategy, Vehicle};
use crate::model::choice::choice;
use crate::model::problems::Problems;

fn default_rotating_mass_factor() -> f64 {
    0.05
}
fn default_standstill_kmh() -> f64 {
    0.1
}
fn default_min_hold_s() -> f64 {
    2.0
}

choice!(Overrun {
    Zero = "zero",
    Transmit = "transmit",
});

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

/// `[vehicle]` as written.
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

/// `v` finite and within [lo, hi] (`unit` after a space in the message), else a problem.
fn range(p: &mut Problems, path: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Option<f64> {
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    p.in_range(path, v, lo, hi, &unit).then_some(v)
}

/// A required value of one road-load form, in range.
fn required(p: &mut Problems, path: &str, v: Option<f64>, lo: f64, hi: f64, unit: &str) -> Option<f64> {
    match v {
        Some(v) => range(p, path, v, lo, hi, unit),
        None => {
            p.push(path, "", "missing");
            None
        }
    }
}

/// Check every value of `[vehicle]` and turn it into a [`Vehicle`] (SI), or record every
/// problem. `gears` gives the model's gear states and their ratios ω_in/ω_out (used for the
/// shift gear names and the hysteresis checks).
pub fn validate_vehicle(spec: &VehicleSpec, gears: &GearTable, p: &mut Problems) -> Option<Vehicle> {
    let start = p.len();
    range(p, "vehicle.mass_kg", spec.mass_kg, 1.0, 1e5, "kg");
    range(
        p,
        "vehicle.rotating_mass_factor",
        spec.rotating_mass_factor,
        0.0,
        1.0,
        "",
    );
    range(p, "vehicle.wheel_radius_m", spec.wheel_radius_m, 0.1, 1.0, "m");
    range(
        p,
        "vehicle.final_drive_ratio",
        spec.final_drive_ratio,
        1.0,
        20.0,
        "",
    );
    range(p, "vehicle.grade_percent", spec.grade_percent, -30.0, 30.0, "%");
    range(
        p,
        "vehicle.standstill_below_kmh",
        spec.standstill_below_kmh,
        0.0,
        10.0,
        "km/h",
    );

    let road = road_load(spec, p);
    let shift = spec.shift.as_ref().map(|s| check_shift(s, gears, p));

    if p.len() > start {
        return None;
    }
    let theta = (spec.grade_percent / 100.0).atan();
    let mut road_load = road.unwrap_or(RoadLoad {
        f0: 0.0,
        f1: 0.0,
        f2: 0.0,
    });
    road_load.f0 += spec.mass_kg * G * theta.sin();
    Some(Vehicle {
        mass: spec.mass_kg,
        effective_mass: spec.mass_kg * (1.0 + spec.rotating_mass_factor),
        wheel_radius: spec.wheel_radius_m,
        final_drive_ratio: spec.final_drive_ratio,
        road_load,
        overrun: spec.overrun,
        standstill_speed: spec.standstill_below_kmh * KMH,
        shift: shift.flatten(),
    })
}

/// `[vehicle.road_load]` without grade (rolling resistance gets cos θ).
fn road_load(spec: &VehicleSpec, p: &mut Problems) -> Option<RoadLoad> {
    let r = &spec.road_load;
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
        (true, false) => coast_down(r, p),
        (false, true) => physical(r, spec, p),
    }
}

/// The coast-down form F = f0 + f1·v + f2·v², which must stay ≥ 0 up to 252 km/h.
fn coast_down(r: &RoadLoadSpec, p: &mut Problems) -> Option<RoadLoad> {
    let f0 = required(p, "vehicle.road_load.f0_n", r.f0_n, 0.0, 1e5, "N");
    let f1 = range(
        p,
        "vehicle.road_load.f1_n_per_mps",
        r.f1_n_per_mps.unwrap_or(0.0),
        -1e3,
        1e3,
        "N/(m/s)",
    );
    let f2 = required(
        p,
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

/// The physical form m·g·c_rr·cos θ + ½·ρ_air·c_d·A·v².
fn physical(r: &RoadLoadSpec, spec: &VehicleSpec, p: &mut Problems) -> Option<RoadLoad> {
    let cd = required(
        p,
        "vehicle.road_load.drag_coefficient",
        r.drag_coefficient,
        0.0,
        2.0,
        "",
    );
    let a = required(
        p,
        "vehicle.road_load.frontal_area_m2",
        r.frontal_area_m2,
        0.0,
        20.0,
        "m^2",
    );
    let crr = required(
        p,
        "vehicle.road_load.rolling_resistance",
        r.rolling_resistance,
        0.0,
        0.1,
        "",
    );
    let rho = range(
        p,
        "vehicle.road_load.air_density_kg_m3",
        r.air_density_kg_m3.unwrap_or(1.2),
        0.5,
        2.0,
        "kg/m^3",
    );
    let cos = (spec.grade_percent / 100.0).atan().cos();
    Some(RoadLoad {
        f0: spec.mass_kg * G * crr? * cos,
        f1: 0.0,
        f2: 0.5 * rho? * cd? * a?,
    })
}

/// `[vehicle.shift]`: gear names and ratios, thresholds, then the hysteresis between them.
fn check_shift(s: &ShiftSpec, gears: &GearTable, p: &mut Problems) -> Option<ShiftStrategy> {
    let n = s.gears.len();
    let before = p.len();
    let ratios = shift_gear_ratios(s, gears, p);
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
            range(p, &format!("vehicle.shift.{key}[{i}]"), x, 1.0, 30_000.0, "rpm");
        }
    }
    range(p, "vehicle.shift.min_hold_s", s.min_hold_s, 0.0, 60.0, "s");
    if p.len() > before {
        return None;
    }
    check_hysteresis(s, &ratios, p);
    Some(ShiftStrategy {
        gears: s.gears.clone(),
        upshift: s.upshift_rpm.iter().map(|x| x * RPM).collect(),
        downshift: s.downshift_rpm.iter().map(|x| x * RPM).collect(),
        min_hold: s.min_hold_s,
    })
}

/// The ratio of each shift gear: forward gear states of the model, listed once, ratios falling.
fn shift_gear_ratios(s: &ShiftSpec, gears: &GearTable, p: &mut Problems) -> Vec<f64> {
    if s.gears.is_empty() {
        p.push(
            "vehicle.shift.gears",
            "[]",
            "list at least one forward gear state",
        );
    }
    let mut ratios = Vec::with_capacity(s.gears.len());
    for (i, g) in s.gears.iter().enumerate() {
        let path = format!("vehicle.shift.gears[{i}]");
        if s.gears[..i].contains(g) {
            p.push(&path, g, "listed twice");
        }
        let Some(k) = gears.index_of(g) else {
            p.push(
                &path,
                g,
                format!("not a gear state of the model ({})", gears.names().join(", ")),
            );
            continue;
        };
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
    ratios
}

/// Pairwise hysteresis checks (all inputs valid here): no shift lands beyond the threshold that
/// would shift straight back, and the output-speed thresholds rise with the gear.
fn check_hysteresis(s: &ShiftSpec, ratios: &[f64], p: &mut Problems) {
    let n = s.gears.len();
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
            check_rising(s, ratios, i, p);
        }
    }
}

/// The output speeds at the thresholds of gear pairs `i` and `i + 1` rise with the gear.
fn check_rising(s: &ShiftSpec, ratios: &[f64], i: usize, p: &mut Problems) {
    for (key, v, r) in [
        ("upshift_rpm", &s.upshift_rpm, (ratios[i], ratios[i + 1])),
        ("downshift_rpm", &s.downshift_rpm, (ratios[i + 1], ratios[i + 2])),
    ] {
        let (w0, w1) = (v[i] / r.0, v[i + 1] / r.1);
        if w1 <= w0 {
            p.push(
                format!("vehicle.shift.{key}[{}]", i + 1),
                v[i + 1],
                format!("the output speed at this threshold ({w1:.0} rpm) must exceed the previous one ({w0:.0} rpm)"),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycle::vehicle::tests::{at6, at6_gears};
    use crate::model::problems::Problem;
    use approx::assert_relative_eq;

    const AT6_TOML: &str = r#"
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

    fn spec(text: &str) -> VehicleSpec {
        toml::from_str::<File>(text).unwrap().vehicle
    }

    fn check(s: &VehicleSpec, gears: &GearTable) -> Result<Vehicle, Vec<Problem>> {
        let mut p = Problems::default();
        validate_vehicle(s, gears, &mut p).ok_or_else(|| p.into_vec())
    }

    fn one_gear() -> GearTable {
        GearTable::new(vec![("1".into(), 1.0)])
    }

    fn paths(e: &[Problem]) -> Vec<&str> {
        e.iter().map(|p| p.path.as_str()).collect()
    }

    #[test]
    fn example_vehicle_gives_the_cycle_layers_at6_exactly() {
        let v = check(&spec(AT6_TOML), &at6_gears()).unwrap();
        assert_eq!(v, at6());
        assert_relative_eq!(v.effective_mass, 1995.0, epsilon = 1e-9);
        assert_relative_eq!(v.standstill_speed, 0.1 / 3.6, epsilon = 1e-15);
        assert_eq!(v.overrun, Overrun::Zero);
        let s = v.shift.unwrap();
        assert_relative_eq!(
            s.upshift[0],
            crate::physics::units::rpm_to_rad_s(2200.0),
            epsilon = 1e-12
        );
        assert_eq!(s.gears.len(), 6);
    }

    #[test]
    fn physical_road_load_and_grade() {
        let s = spec(
            "[vehicle]\nmass_kg = 1000.0\nwheel_radius_m = 0.3\nfinal_drive_ratio = 4.0\ngrade_percent = 10.0\n\
             road_load = { drag_coefficient = 0.3, frontal_area_m2 = 2.0, rolling_resistance = 0.01 }\n",
        );
        let v = check(&s, &one_gear()).unwrap();
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
        let e = check(&s, &at6_gears()).unwrap_err();
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
        let m = e.iter().find(|p| p.path == "vehicle.mass_kg").unwrap();
        assert_eq!(m.to_string(), "vehicle.mass_kg = -5: must lie in [1, 100000] kg");
    }

    #[test]
    fn hysteresis_problems() {
        let mut s = spec(AT6_TOML);
        let sh = s.shift.as_mut().unwrap();
        sh.downshift_rpm[0] = 2300.0; // above its upshift
        sh.downshift_rpm[2] = 1600.0; // below up but above up[2]·r3/r2 = 1503 → would shift back
        sh.upshift_rpm[4] = 1400.0; // output speed 1400/0.867 < 1900/1.143: not increasing
        let e = check(&s, &at6_gears()).unwrap_err();
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
        assert!(check(&spec(AT6_TOML), &at6_gears()).is_ok());
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
        let e = check(&s, &at6_gears()).unwrap_err();
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
    fn negative_coast_down_load_is_rejected() {
        let s = spec(
            "[vehicle]\nmass_kg = 1000.0\nwheel_radius_m = 0.3\nfinal_drive_ratio = 4.0\n\
             road_load = { f0_n = 10.0, f1_n_per_mps = -5.0, f2_n_per_mps2 = 0.1 }\n",
        );
        let e = check(&s, &one_gear()).unwrap_err();
        assert_eq!(paths(&e), vec!["vehicle.road_load"]);
        let s = spec(
            "[vehicle]\nmass_kg = 1000.0\nwheel_radius_m = 0.3\nfinal_drive_ratio = 4.0\n\
             road_load = { f1_n_per_mps = 5.0 }\n",
        );
        let e = check(&s, &one_gear()).unwrap_err();
        assert_eq!(
            paths(&e),
            vec!["vehicle.road_load.f0_n", "vehicle.road_load.f2_n_per_mps2"]
        );
    }
}
