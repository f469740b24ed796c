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
    let items = &scene.losses().items;
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
    let oil = scene.thermal().oil_properties(40.0 + KELVIN_OFFSET);
    let w3 = &gb.gear_states[third].solution.speeds;
    let m = |n: &str| gb.members.iter().position(|x| x.name == n).unwrap();
    for (e, slip) in [
        ("C", w3[m("large_sun")].abs()),
        ("D", w3[m("rav_carrier")].abs()),
        ("E", (w3[m("input")] - w3[m("rav_carrier")]).abs()),
    ] {
        let mut pack = gb.clutch_packs.iter().find(|c| c.name == e).unwrap().pack;
        // the circuit feeds every AT6 pack: its flow replaces the pack's own
        let feed = gb
            .circuit
            .consumers
            .iter()
            .position(|c| c.name == format!("{e}_feed"))
            .unwrap();
        pack.oil_flow = scene.losses().circuit.flow(feed, &work.terms.circuit, oil.rho).0;
        assert!(pack.oil_flow > 0.0);
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
    let oil = scene.thermal().oil;
    for (k, it) in items.iter().enumerate() {
        if matches!(it.source, Source::ClutchDrag | Source::Pump | Source::Converter) {
            assert_eq!(scene.thermal().heat[k], vec![(oil, 1.0)], "{}", it.name);
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
            .losses()
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

fn run_summary_and_rows(
    model: &str,
    dir: &std::path::Path,
) -> (serde_json::Value, Vec<String>, Vec<Vec<String>>) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args([
            "run",
            model,
            "--cycle",
            "wltc",
            "--out",
            dir.to_str().unwrap(),
            "--quiet",
        ])
        .output()
        .expect("binary runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s = serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    (s, header, rows)
}

#[test]
fn a_run_with_a_launch_device_writes_the_engine_side() {
    let tmp = tempfile::tempdir().unwrap();
    let (s, header, rows) = run_summary_and_rows("models/at6_lepelletier.toml", &tmp.path().join("at6"));
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    let (c_in, c_eng, c_tq, c_lu) = (
        col("input_speed_rpm"),
        col("engine_speed_rpm"),
        col("engine_torque_nm"),
        col("lockup"),
    );
    assert_eq!(c_eng, col("output_power_w") + 1);
    let num = |r: &Vec<String>, c: usize| r[c].parse::<f64>().unwrap();
    let (mut locked, mut idle_stall) = (0, 0);
    for r in &rows {
        let (w_in, w_e, lu) = (num(r, c_in), num(r, c_eng), &r[c_lu]);
        // the engine never runs below idle and never slower than the turbine
        assert!(w_e >= 750.0 - 1e-9 && w_e >= w_in - 1e-9, "{w_e} {w_in}");
        assert!(num(r, c_tq).is_finite());
        if lu == "1" {
            // controlled lock-up slip 20 rpm
            assert!((w_e - w_in - 20.0).abs() < 1e-9, "{w_e} {w_in}");
            locked += 1;
        } else {
            assert_eq!(lu, "0");
        }
        if w_in == 0.0 {
            assert_eq!(w_e, 750.0);
            idle_stall += 1;
        }
    }
    assert!(locked > 100 && idle_stall > 100, "{locked} {idle_stall}");
    // the launch summary splits the converter energy without losing any of it
    let l = &s["launch"];
    let split = l["converter_standstill_j"].as_f64().unwrap() + l["converter_driving_j"].as_f64().unwrap();
    let conv = s["energy_lost_j"]["converter"].as_f64().unwrap();
    assert!((split - conv).abs() <= 1e-6 * conv, "{split} vs {conv}");
    assert!(l["lockup_time_s"].as_f64().unwrap() > 0.0 && l["standstill_time_s"].as_f64().unwrap() > 0.0);
    let max = rows.iter().map(|r| num(r, c_eng)).fold(0.0, f64::max);
    assert_eq!(l["engine_speed_max_rpm"].as_f64().unwrap(), max);
    // The published efficiency range of a conventional automatic, 90–95 % (Sean Bennett 2011, as
    // quoted in Table 1 of the KTH/AVL thesis on churning losses in a 6-speed automatic, seed
    // 000_c58c7d89730efd30): the AT6's energy-weighted WLTC efficiency from 23 °C, converter
    // included. Not adjusted to it (docs/validation.md).
    let eta = s["cycle_efficiency"].as_f64().unwrap();
    assert!((0.90..=0.95).contains(&eta), "cycle efficiency {eta}");

    // without a launch device: no engine columns, no launch key
    let (s, header, _) = run_summary_and_rows("models/pt6_spur_pair.toml", &tmp.path().join("pt6"));
    assert!(!header.iter().any(|h| h.starts_with("engine_") || h == "lockup"));
    assert!(s.get("launch").is_none());
}

/// CO2MPAS default gear-box loss for gearboxes with a torque converter (JRCSTU/CO2MPAS-TA commit
/// b946f2555411c3eb3efc9bad94cef55e733d4194: `defaults.py` get_gear_box_efficiency_constants
/// PARAMS[True] and gear_box_temperature_references (40, 80) °C; `core/model/physical/gear_box`
/// calculate_gear_box_powers_in_hot), evaluated outside this repository for an engine maximum
/// torque of 450 N·m (the top of the AT6's line-pressure table, its design input torque): loss
/// W at (oil °C, input rpm, loss-free input torque N·m). The converter is not part of it.
const CO2MPAS_B946F25: [(f64, f64, f64, f64); 8] = [
    (40.0, 1500.0, 50.0, 1071.534570753748),
    (40.0, 1500.0, 150.0, 1570.3809830522496),
    (40.0, 2500.0, 50.0, 2223.698169471673),
    (40.0, 2500.0, 150.0, 3055.1088566358403),
    (80.0, 1500.0, 50.0, 828.0839287059845),
    (80.0, 1500.0, 150.0, 1158.984126701398),
    (80.0, 2500.0, 50.0, 1716.543574587444),
    (80.0, 2500.0, 150.0, 2268.0439045798053),
];

/// AT6 loss (W) without the converter at one point, oil and bodies at `t_c`.
fn at6_gearbox_loss(
    gb: &geartherm::model::Gearbox,
    scene: &geartherm::scene::Scene,
    gear: &str,
    rpm: f64,
    tq: f64,
    t_c: f64,
) -> (f64, [f64; 3]) {
    let inputs = Inputs {
        state: gb.state_index(gear).unwrap(),
        input_speed: rpm * RPM,
        input_torque: tq,
        vehicle_speed: 0.0,
    };
    let mut work = scene.work(inputs);
    let y = scene.initial_state(Some(t_c + KELVIN_OFFSET));
    scene.evaluate_losses(&y, &mut work);
    let mut by = [0.0; 3]; // gears+bearings+seals, clutch drag, pump
    let mut total = 0.0;
    for (it, q) in scene.losses().items.iter().zip(&work.q) {
        match it.source {
            Source::Converter => continue,
            Source::ClutchDrag => by[1] += q,
            Source::Pump => by[2] += q,
            _ => by[0] += q,
        }
        total += q;
    }
    (total, by)
}

#[test]
fn at6_gearbox_loss_against_the_co2mpas_default_for_automatics() {
    // A plausibility comparison with a peer's published default, not a validation: CO2MPAS's
    // constants are one generic law for every automatic (fitted by the JRC; no gear, no
    // transmission design), the AT6's parts are assumed (model file); the AT6 is never adjusted
    // to this source. The band stated before the comparison, AT6/CO2MPAS within 0.5…2, holds at
    // every point. What this test holds is the difference as docs/validation.md states it: warm
    // (80 °C) the AT6 loses less than the peer (0.5…0.85×), at 40 °C about as much or more
    // (0.95…1.6×: its packs' lubrication follows the pump speed through the [circuit], so the
    // open packs in 40 °C oil drag 1.0–2.0 kW), and its loss grows far more from 80 to 40 °C than
    // the peer's (clutch drag ∝ μ).
    let (gb, scene) = scene_of("models/at6_lepelletier.toml");
    for gear in ["3", "4", "6"] {
        // rows 0..4 at 40 °C, rows 4..8 the same points at 80 °C
        for (cold, hot) in CO2MPAS_B946F25[..4].iter().zip(&CO2MPAS_B946F25[4..]) {
            let (_, rpm, tq, peer_cold) = *cold;
            let peer_hot = hot.3;
            let (ours_cold, by_c) = at6_gearbox_loss(&gb, &scene, gear, rpm, tq, 40.0);
            let (ours_hot, by_h) = at6_gearbox_loss(&gb, &scene, gear, rpm, tq, 80.0);
            let (rc, rh) = (ours_cold / peer_cold, ours_hot / peer_hot);
            println!(
                    "gear {gear} {rpm} rpm {tq} N·m: 40 °C AT6 {ours_cold:.0} W (gears+bearings+seals {:.0}, drag {:.0}, pump {:.0}) vs {peer_cold:.0} W = {rc:.2}; 80 °C AT6 {ours_hot:.0} W (gears+bearings+seals {:.0}, drag {:.0}, pump {:.0}) vs {peer_hot:.0} W = {rh:.2}",
                    by_c[0], by_c[1], by_c[2], by_h[0], by_h[1], by_h[2]
                );
            let at = format!("gear {gear}, {rpm} rpm, {tq} N·m");
            assert!((0.5..=0.85).contains(&rh), "{at}, 80 °C: {rh}");
            assert!((0.9..=1.6).contains(&rc), "{at}, 40 °C: {rc}");
            // the AT6's warm-to-cold growth exceeds the peer's, by its clutch drag
            assert!(ours_cold / ours_hot > 1.5 * peer_cold / peer_hot, "{at}");
            assert!(by_c[1] > by_c[0] + by_c[2], "{at}: drag dominates at 40 °C");
        }
    }
}

/// Oil (sump) temperature, °C, of a run's timeseries at the last row with time ≤ `t`.
fn sump_at(header: &[String], rows: &[Vec<String>], t: f64) -> f64 {
    let c_t = header.iter().position(|h| h == "time_s").unwrap();
    let c_s = header.iter().position(|h| h == "temp_sump_c").unwrap();
    rows.iter()
        .take_while(|r| r[c_t].parse::<f64>().unwrap() <= t)
        .last()
        .map(|r| r[c_s].parse().unwrap())
        .unwrap()
}

#[test]
fn at6_warms_within_the_oem_diagnostic_limits_from_a_cold_start() {
    // Published bounds a healthy automatic must meet, from the OEMs' P0711 ("transmission fluid
    // temperature sensor performance") set conditions: Hyundai/Kia (gds-manuals.ru, 2016,
    // "Low Stuck": engine > 1500 rpm in D, fluid above −10 °C, 800 s elapsed, fault if the fluid is
    // still below 20 °C) and GM (2010 Pontiac G3: fault if the fluid stays below 15 °C for 10 min
    // at 40 km/h or more). Our bench is the WLTC from −7 °C (the cold WLTP temperature), a
    // gentler drive than either condition; the AT6 is not adjusted to these bounds.
    let text = std::fs::read_to_string("models/at6_lepelletier.toml").unwrap();
    let cold = text.replace(
        "series = [[0.0, 23.0], [300.0, 70.0], [600.0, 85.0]",
        "series = [[0.0, -7.0], [300.0, 61.1], [600.0, 82.8]",
    );
    assert_ne!(cold, text, "the coolant curve of the model file moved");
    let tmp = tempfile::tempdir().unwrap();
    let model = tmp.path().join("at6_m7.toml");
    std::fs::write(&model, cold).unwrap();
    let dir = tmp.path().join("m7");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--cycle",
            "wltc",
            "--out",
            dir.to_str().unwrap(),
            "--quiet",
        ])
        .args(["--initial-temp-c", "-7", "--ambient-c", "-7"])
        .output()
        .expect("binary runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    let (t600, t800) = (sump_at(&header, &rows, 600.0), sump_at(&header, &rows, 800.0));
    println!("AT6 WLTC from −7 °C: sump {t600:.1} °C at 600 s, {t800:.1} °C at 800 s");
    assert!(t800 >= 20.0, "Hyundai/Kia P0711: {t800} °C at 800 s");
    assert!(t600 >= 15.0, "GM P0711: {t600} °C at 600 s");
}
