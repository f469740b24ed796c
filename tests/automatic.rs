//! The automatic transmission's own losses in a compiled scene: the two-way coolant heat
//! exchanger, the clutch-drag / pump / converter items of the AT6 and their per-state behaviour.

mod common;

use common::{fzg_with, scene_of, steady_inputs};
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Source};

const RPM: f64 = std::f64::consts::PI / 30.0;

fn exchanger(two_way: bool) -> String {
    format!(
        r#"
[thermal]
oil_node = "oil"
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 1500.0
initial_temp_c = 20.0
[[thermal.boundaries]]
name = "coolant"
temp_c = 80.0
[[thermal.coolers]]
name = "warmer"
hot = "oil"
cold = "coolant"
effectiveness = 0.5
capacity_rate_w_per_k = 100.0
two_way = {two_way}
thermostat = {{ open_c = 75.0, full_c = 85.0 }}
"#
    )
}

/// Heat into the oil node at oil temperature `t_c` (°C), gearbox at rest.
fn heat_into_oil(two_way: bool, t_c: f64) -> f64 {
    let scene = fzg_with(&exchanger(two_way));
    let mut work = scene.work(steady_inputs(0.0, 0.0));
    let mut y = scene.initial_state(Some(t_c + KELVIN_OFFSET));
    y[0] = t_c + KELVIN_OFFSET;
    let mut heat = vec![0.0; scene.nodes()];
    scene.net_heat(0.0, &y, &mut work, &mut heat);
    heat[0]
}

#[test]
fn two_way_exchanger_heats_cold_oil_and_cools_hot_oil_through_its_thermostat() {
    // cold oil, warm coolant: the two-way exchanger heats with ε·C·(T_c − T_oil) = 50·60 W; the
    // one-way cooler stays shut (thermostat closed below 75 °C)
    let q = heat_into_oil(true, 20.0);
    assert!((q - 50.0 * 60.0).abs() < 1e-9, "{q}");
    assert_eq!(heat_into_oil(false, 20.0), 0.0);
    // hot oil: both cool alike, fully open above 85 °C
    let (a, b) = (heat_into_oil(true, 95.0), heat_into_oil(false, 95.0));
    assert!((a - b).abs() < 1e-12 && (a + 50.0 * 15.0).abs() < 1e-9, "{a} {b}");
    // oil between coolant and the thermostat: no flow either way at 79 °C? the coolant (80 °C)
    // is warmer, so the two-way exchanger heats (1 K × 50 W/K)
    assert!((heat_into_oil(true, 79.0) - 50.0).abs() < 1e-9);
}

#[test]
fn at6_has_clutch_drag_pump_and_converter_items_that_heat_the_oil() {
    let (gb, scene) = scene_of("models/at6_lepelletier.toml");
    let items = &scene.losses.items;
    let names = |s: Source| -> Vec<&str> {
        items
            .iter()
            .filter(|i| i.source == s)
            .map(|i| i.name.as_str())
            .collect()
    };
    assert_eq!(names(Source::ClutchDrag), vec!["A", "B", "C", "D", "E"]);
    assert_eq!(names(Source::Pump), vec!["pump"]);
    assert_eq!(names(Source::Converter), vec!["converter"]);
    let third = gb.state_index("3").unwrap();
    let inputs = Inputs {
        state: third,
        input_speed: 2000.0 * RPM,
        input_torque: 100.0,
        vehicle_speed: 50.0 / 3.6,
    };
    let mut work = scene.work(inputs);
    let y = scene.initial_state(Some(40.0 + KELVIN_OFFSET));
    scene.evaluate_losses(&y, &mut work);
    let ix = |s: Source, n: &str| items.iter().position(|i| i.source == s && i.name == n).unwrap();
    // 3rd = A + B engaged: no drag in A and B; the open C, D, E drag as their packs at their
    // slips (|large sun|, |Ravigneaux carrier|, |input − carrier| per unit input speed)
    assert_eq!(
        (
            work.q[ix(Source::ClutchDrag, "A")],
            work.q[ix(Source::ClutchDrag, "B")]
        ),
        (0.0, 0.0)
    );
    let oil = scene.thermal.oil_properties(40.0 + KELVIN_OFFSET);
    let w3 = &gb.gear_states[third].solution.speeds;
    let m = |n: &str| gb.members.iter().position(|x| x.name == n).unwrap();
    for (e, slip) in [
        ("C", w3[m("large_sun")].abs()),
        ("D", w3[m("rav_carrier")].abs()),
        ("E", (w3[m("input")] - w3[m("rav_carrier")]).abs()),
    ] {
        let pack = gb.clutch_packs.iter().find(|c| c.name == e).unwrap().pack;
        let want = pack.drag(slip * 2000.0 * RPM, oil.mu, oil.rho).power;
        assert!(
            (work.q[ix(Source::ClutchDrag, e)] - want).abs() <= 1e-12 * want.max(1.0),
            "{e}"
        );
    }
    // E slips 685 rpm: below its critical slip at 40 °C, a full film
    assert!(work.q[ix(Source::ClutchDrag, "E")] > 10.0);
    // locked converter (3rd above 35 km/h) with 20 rpm slip: 100 N·m × 20 rpm
    assert!((work.q[ix(Source::Converter, "converter")] - 100.0 * 20.0 * RPM).abs() < 1e-9);
    // pump at engine speed 2020 rpm and the line pressure of 100 N·m (7 bar)
    let pump = 16e-6 * 7e5 / (2.0 * std::f64::consts::PI * 0.85) * 2020.0 * RPM;
    assert!((work.q[ix(Source::Pump, "pump")] - pump).abs() < 1e-9 * pump);
    // standstill in 1st: no gear or drag loss, the pump at idle and the converter stalled at idle
    let first = gb.state_index("1").unwrap();
    scene.set_inputs(
        Inputs {
            state: first,
            input_speed: 0.0,
            input_torque: 0.0,
            vehicle_speed: 0.0,
        },
        &mut work,
    );
    scene.evaluate_losses(&y, &mut work);
    let stall = (750.0f64 / 144.4).powi(2) * 750.0 * RPM;
    assert!((work.q[ix(Source::Converter, "converter")] - stall).abs() < 1e-9 * stall);
    assert!(work.q[ix(Source::Pump, "pump")] > 0.0);
    assert!(items
        .iter()
        .zip(&work.q)
        .filter(|(i, _)| i.source == Source::ClutchDrag)
        .all(|(_, w)| *w == 0.0));
    // all three default to the oil node
    let oil = scene.thermal.oil;
    for (k, it) in items.iter().enumerate() {
        if matches!(it.source, Source::ClutchDrag | Source::Pump | Source::Converter) {
            assert_eq!(scene.thermal.heat[k], vec![(oil, 1.0)], "{}", it.name);
        }
    }
}

#[test]
fn cold_oil_drags_more() {
    let (gb, scene) = scene_of("models/at6_lepelletier.toml");
    let inputs = Inputs {
        state: gb.state_index("2").unwrap(),
        input_speed: 1800.0 * RPM,
        input_torque: 80.0,
        vehicle_speed: 25.0 / 3.6,
    };
    let drag = |t_c: f64| {
        let mut work = scene.work(inputs);
        let y = scene.initial_state(Some(t_c + KELVIN_OFFSET));
        scene.evaluate_losses(&y, &mut work);
        scene
            .losses
            .items
            .iter()
            .zip(&work.q)
            .filter(|(i, _)| i.source == Source::ClutchDrag)
            .map(|(_, w)| w)
            .sum::<f64>()
    };
    let (cold, warm) = (drag(-7.0), drag(80.0));
    assert!(cold > 3.0 * warm, "{cold} W at −7 °C vs {warm} W at 80 °C");
}
