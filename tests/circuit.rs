//! The lubrication circuit: the AT6 lubricated as built (advection links, pocketing from the
//! delivered oil, no "unknown density" warning) closes its energy balance over a WLTC; steady state
//! equals a long transient with advection links; the assembled Jacobian (advection links included)
//! matches finite differences of the right-hand side; bad `[circuit]` keys are named.

use std::path::Path;
use std::process::Command;

use geartherm::model;
use geartherm::scene::{Inputs, Scene, Source};
use geartherm::solve::equilibrium::equilibrium;
use geartherm::solve::steady::SteadyOptions;
use geartherm::solve::transient::{integrate, Method, Segment, TransientOptions};

const AT6: &str = "models/at6_lepelletier.toml";

fn at6() -> (model::Gearbox, Scene) {
    let gb = model::load(Path::new(AT6)).unwrap();
    let sc = Scene::compile(&gb).unwrap();
    (gb, sc)
}

#[test]
fn the_at6_has_advection_links_and_fed_meshes() {
    let (gb, sc) = at6();
    // PS1 and RAV feeds (their set nodes), five packs and the output bearings (shafts_clutches).
    assert_eq!(sc.thermal().advection_link_count(), 8);
    assert_eq!(gb.circuit.consumers.len(), 8);
    for s in [Source::Pocketing, Source::Fling, Source::Windage] {
        assert!(sc.losses().items.iter().any(|i| i.source == s), "{s:?}");
    }
    // every external planet mesh is fed, none is left out for an unknown density
    assert!(sc.losses().warnings.iter().all(|w| !w.range.contains("unknown")));
    let pocketing = sc
        .losses()
        .items
        .iter()
        .filter(|i| i.source == Source::Pocketing)
        .count();
    assert_eq!(pocketing, 4);
}

#[test]
fn at6_wltc_with_advection_closes_the_energy_balance_and_pockets_delivered_oil() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("at6");
    let out = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args([
            "run",
            AT6,
            "--cycle",
            "wltc",
            "--out",
            dir.to_str().unwrap(),
            "--quiet",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("unknown"), "{stderr}");
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    let bal = s["energy_balance_relative"].as_f64().unwrap();
    let e = &s["energy_lost_j"];
    let (pocketing, fling) = (e["pocketing"].as_f64().unwrap(), e["fling"].as_f64().unwrap());
    println!(
        "AT6 WLTC with the circuit: balance {bal:.2e}, pocketing {:.3} kJ, fling {:.3} kJ, windage {:.4} kJ, clutch drag {:.1} kJ",
        pocketing / 1e3,
        fling / 1e3,
        e["windage"].as_f64().unwrap() / 1e3,
        e["clutch_drag"].as_f64().unwrap() / 1e3
    );
    assert!(bal <= 1e-9, "balance {bal}");
    assert!(pocketing > 0.0 && fling > 0.0);
    assert!(e["windage"].as_f64().unwrap() > 0.0);
    let warnings = s["warnings"].to_string();
    assert!(!warnings.contains("unknown"), "{warnings}");
}

#[test]
fn steady_state_equals_a_long_transient_with_advection_links() {
    let (gb, sc) = at6();
    assert!(sc.thermal().advection_link_count() > 0);
    for gear in ["1", "4"] {
        let inp = Inputs {
            state: gb.state_index(gear).unwrap(),
            input_speed: 2400.0 * std::f64::consts::PI / 30.0,
            input_torque: 150.0,
            vehicle_speed: 15.0,
        };
        let eq = equilibrium(&sc, inp, None, &SteadyOptions::default()).unwrap();
        let segs: Vec<Segment> = (0..60)
            .map(|k| Segment {
                t0: k as f64 * 3600.0,
                t1: (k + 1) as f64 * 3600.0,
                inputs: inp,
            })
            .collect();
        let o = TransientOptions {
            method: Method::Bdf,
            rtol: 1e-12,
            atol: 1e-12,
            ..TransientOptions::default()
        };
        let traj = integrate(&sc, &segs, &o, &mut |_, _| {}).unwrap();
        let last = traj.states.last().unwrap();
        let oil = sc.thermal().oil;
        let start_gap = (traj.states[0][oil] - eq.solution.temperatures[oil]).abs();
        assert!(start_gap > 1.0);
        let worst = eq
            .solution
            .temperatures
            .iter()
            .zip(last)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "AT6 gear {gear}, 2400 rpm, 150 N·m, with advection: oil {:.4} °C, |steady − transient(60 h)| max {worst:.2e} K",
            eq.solution.temperatures[oil] - 273.15
        );
        assert!(worst < 1e-6, "gear {gear}: {worst}");
    }
}

#[test]
fn jacobian_with_advection_links_matches_finite_differences_of_the_rhs() {
    let (gb, sc) = at6();
    let inp = Inputs {
        state: gb.state_index("2").unwrap(),
        input_speed: 2000.0 * std::f64::consts::PI / 30.0,
        input_torque: 120.0,
        vehicle_speed: 12.0,
    };
    let mut work = sc.work(inp);
    let mut y = sc.initial_state(None);
    for (i, t) in y.iter_mut().take(sc.nodes()).enumerate() {
        *t += 30.0 + 4.0 * i as f64;
    }
    let pattern = sc.jacobian_pattern();
    let mut vals = vec![0.0; pattern.len()];
    sc.jacobian_values(100.0, &y, &mut work, &mut vals);
    let n = sc.n_states();
    let mut dense = vec![0.0; n * n];
    for (&(r, c), v) in pattern.iter().zip(&vals) {
        dense[r + c * n] += v;
    }
    let (mut f1, mut f0) = (vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    for j in 0..sc.nodes() {
        let h = 1e-3;
        let mut yp = y.clone();
        yp[j] += h;
        sc.rhs(100.0, &yp, &mut work, &mut f1);
        yp[j] -= 2.0 * h;
        sc.rhs(100.0, &yp, &mut work, &mut f0);
        for i in 0..sc.nodes() {
            let fd = (f1[i] - f0[i]) / (2.0 * h);
            let scale = dense[i + j * n].abs().max(fd.abs()).max(1e-6);
            worst = worst.max((dense[i + j * n] - fd).abs() / scale);
        }
    }
    // the oil column is itself a forward difference (step 1e-4 K): agreement to its truncation
    assert!(worst < 1e-3, "assembled Jacobian vs central differences: {worst}");
}

#[test]
fn circuit_mistakes_are_named_at_their_key_paths() {
    let text = std::fs::read_to_string(AT6).unwrap();
    let bad = text
        .replace(
            "share = 0.25                  # about a quarter",
            "share = 1.5 # about a quarter",
        )
        .replace("target = \"RAV\"", "target = \"RAVX\"")
        .replace(
            "kind = \"bearing\"\ntarget = \"output_a\"\nshare = 0.1",
            "kind = \"bearing\"\ntarget = \"output_a\"\norifice_mm = 2.0",
        );
    let err = model::from_str(&bad, Path::new(AT6)).unwrap_err().report();
    for want in [
        "circuit.sources[0].share",
        "circuit.consumers[1].target",
        "circuit.consumers[7].discharge_coefficient",
        "circuit.sources[0]",
    ] {
        assert!(err.contains(want), "{want} missing in\n{err}");
    }
    assert!(err.contains("RAVX") && err.contains("PS1"), "{err}");
}

#[test]
fn an_electric_pump_through_orifices_feeds_a_jet_whose_impulse_is_the_momentum_balance() {
    use geartherm::scene::{LossScene, OperatingPoint};
    let path = Path::new("models/fzg_c.toml");
    let text = std::fs::read_to_string(path).unwrap()
        + r#"
[circuit]
[[circuit.sources]]
name = "e_pump"
kind = "electric_pump"
flow = { input_rpm = [0.0, 3000.0], l_per_min = [1.0, 4.0] }
pressure_bar = 2.0
efficiency = 0.5

[[circuit.consumers]]
name = "jet"
kind = "jet"
target = "pinion/wheel"
orifice_mm = 1.0
discharge_coefficient = 0.7
jet_angle_deg = 180.0

[[circuit.consumers]]
name = "spill"
kind = "mesh"
target = "pinion/wheel"
orifice_mm = 3.0
discharge_coefficient = 0.7
"#;
    let gb = model::from_str(&text, path).unwrap();
    let sc = LossScene::compile(&gb).unwrap();
    let oil = gb.oil.properties(353.15);
    let w = 1500.0 * std::f64::consts::PI / 30.0;
    let op = OperatingPoint {
        state: 0,
        input_speed: w,
        input_torque: 100.0,
        oil,
    };
    let mut out = vec![0.0; sc.len()];
    sc.evaluate(&op, &mut out);
    let at = |s: Source, n: &str| {
        let k = sc
            .items
            .iter()
            .position(|i| i.source == s && i.name == n)
            .unwrap();
        out[k]
    };
    // 2.5 L/min at 1500 rpm; the orifices (1 : 9 in C_d A) would pass more at 2 bar, so they
    // share the supply 1 : 9.
    let supply = 2.5e-3 / 60.0;
    let q_jet = supply / 10.0;
    let free = 0.7 * std::f64::consts::PI * 0.25e-6 * (2.0 * 2e5 / oil.rho).sqrt();
    assert!(free > q_jet);
    let m = &gb.meshes[0];
    let speeds = gb.gear_speeds(0);
    let v_p = speeds[m.gear1].relative.abs() * w * m.geometry.r_w1;
    // The source runs short, so the line pressure is the one the delivered flow implies: the
    // orifice law at p_d passes q_jet, p_d = 2 bar · (q_jet/free)²; the jet leaves at √(2p_d/ρ).
    let p_d = 2e5 * (q_jet / free).powi(2);
    let v_j = (2.0 * p_d / oil.rho).sqrt();
    assert!((v_j / (q_jet / (0.7 * std::f64::consts::PI * 0.25e-6)) - 1.0).abs() < 1e-12);
    let expect = oil.rho * q_jet * v_p * (v_p + v_j);
    let nominal = oil.rho * q_jet * v_p * (v_p + (2.0 * 2e5 / oil.rho).sqrt());
    let jet = at(Source::Jet, "jet");
    assert!((jet / expect - 1.0).abs() < 1e-12, "{jet} vs {expect}");
    // the electric pump's drive: Q p_d / η
    let drive = at(Source::Pump, "e_pump");
    assert!((drive - supply * p_d / 0.5).abs() < 1e-9 * drive);
    println!(
        "delivered {:.3} of the orifices' flow at 2 bar: line {:.0} Pa; jet {jet:.4} W (at the nominal pressure {nominal:.4} W), \
         pump drive {drive:.4} W (at the nominal pressure {:.4} W)",
        supply / (10.0 * free),
        p_d,
        supply * 2e5 / 0.5
    );
    assert!(sc.items.iter().any(|i| i.name == "e_pump" && i.engine_side));
}

#[test]
fn the_advection_links_carry_the_oil_nodes_specific_heat() {
    // Same sump capacity (7.6 kg × 2000 J/kgK), c_p doubled: every advection conductance ṁ c_p
    // doubles, so the fed set node settles closer to the oil; with c_p as a constant it would not
    // move at all.
    let gap = |ovs: &[&str]| {
        let ovs: Vec<model::Override> = ovs.iter().map(|s| s.parse().unwrap()).collect();
        let gb = model::load_with(Path::new(AT6), &ovs).unwrap();
        let sc = Scene::compile(&gb).unwrap();
        let inp = Inputs {
            state: gb.state_index("4").unwrap(),
            input_speed: 2400.0 * std::f64::consts::PI / 30.0,
            input_torque: 150.0,
            vehicle_speed: 15.0,
        };
        let eq = equilibrium(&sc, inp, None, &SteadyOptions::default()).unwrap();
        let t = &eq.solution.temperatures;
        let set = sc.thermal().names.iter().position(|n| n == "ravigneaux").unwrap();
        t[set] - t[sc.thermal().oil]
    };
    let base = gap(&[]);
    let doubled = gap(&[
        "thermal.nodes[\"sump\"].mass_kg = 3.8",
        "thermal.nodes[\"sump\"].cp_j_per_kgk = 4000.0",
    ]);
    println!("ravigneaux − oil: {base:.4} K at c_p 2000, {doubled:.4} K at c_p 4000");
    assert!(
        base > 0.0 && doubled > 0.0 && doubled < 0.9 * base,
        "{base} {doubled}"
    );
}

#[test]
fn an_electric_pump_cannot_take_the_pumps_item_name() {
    // An electric pump named `pump` beside a [pump] would give two items pump:pump.
    let text = std::fs::read_to_string(AT6).unwrap()
        + "\n[[circuit.sources]]\nname = \"pump\"\nkind = \"electric_pump\"\npressure_bar = 2.0\n\
           efficiency = 0.5\nflow = { input_rpm = [0.0, 6000.0], l_per_min = [1.0, 2.0] }\n";
    let err = model::from_str(&text, Path::new(AT6)).unwrap_err().report();
    assert!(err.contains(".name") && err.contains("pump:pump"), "{err}");
}

#[test]
fn a_circuit_needs_the_oil_nodes_specific_heat() {
    // The advection links carry the oil node's c_p; a sump given by its capacity alone has none.
    let text = std::fs::read_to_string(AT6).unwrap().replace(
        "mass_kg = 7.6                 # 9 L ATF at 845 kg/m³ (the whole fill mixes through the pump)\ncp_j_per_kgk = 2000.0",
        "capacity_j_per_k = 15200.0",
    );
    assert!(text.contains("capacity_j_per_k = 15200.0"));
    let err = model::from_str(&text, Path::new(AT6)).unwrap_err().report();
    assert!(
        err.contains("thermal.nodes[0]") && err.contains("cp_j_per_kgk"),
        "{err}"
    );
    // Without the [circuit] the same sump is accepted.
    let cut = text.find("\n[circuit]").unwrap();
    assert!(model::from_str(&text[..cut], Path::new(AT6)).is_ok());
}
