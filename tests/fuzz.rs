//! Property-based fuzzing (proptest) of the input parsers: the model parser and validator and
//! the cycle parser never panic on mutated or random text; what they accept satisfies the
//! documented limits. Bounded for CI: a fixed number of cases per property (override with
//! `PROPTEST_CASES`), seconds in total in release mode.
//!
//! The override parser (`model/overrides.rs`): random `PATH = VALUE` texts and
//! hostile values at real key paths never panic, and a model accepted with overrides has plain
//! part names and compiles.

use std::path::Path;

use geartherm::cycle::parse::{
    MAX_INPUT_SPEED_RPM, MAX_INPUT_TORQUE_NM, MAX_TIME_S, MAX_VEHICLE_SPEED_KMH, MIN_TIME_STEP_S, RPM,
};
use geartherm::cycle::DriveCycle;
use proptest::prelude::*;

const MODELS: [&str; 4] = [
    include_str!("../models/fzg_c.toml"),
    include_str!("../models/at6_lepelletier.toml"),
    include_str!("../models/helical_stage.toml"),
    include_str!("../models/pt6_spur_pair.toml"),
];

/// Hostile numbers: extremes, non-finite spellings, signs, near-limits.
fn hostile_number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("0".to_string()),
        Just("-0.0".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("1e-308".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("\"x\"".to_string()),
        Just("[]".to_string()),
        Just("{}".to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        (-1e6f64..1e6).prop_map(|v| format!("{v}")),
        any::<i64>().prop_map(|v| v.to_string()),
    ]
}

/// Mutate one `key = value` line of a model: replace its value, delete the line, or duplicate it.
fn mutated_model() -> impl Strategy<Value = String> {
    (
        0..MODELS.len(),
        any::<prop::sample::Index>(),
        0u8..3,
        hostile_number(),
    )
        .prop_map(|(m, idx, op, num)| {
            let lines: Vec<&str> = MODELS[m].lines().collect();
            let candidates: Vec<usize> = lines
                .iter()
                .enumerate()
                .filter(|(_, l)| l.contains('=') && !l.trim_start().starts_with('#'))
                .map(|(i, _)| i)
                .collect();
            let k = candidates[idx.index(candidates.len())];
            let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            match op {
                0 => {
                    let key = out[k].split('=').next().unwrap_or("").to_string();
                    out[k] = format!("{key}= {num}");
                }
                1 => {
                    out.remove(k);
                }
                _ => {
                    let dup = out[k].clone();
                    out.insert(k, dup);
                }
            }
            out.join("\n")
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, failure_persistence: None, ..ProptestConfig::default() })]

    /// The model parser and validator never panic; an accepted model has plain part names and
    /// compiles into a scene without panicking.
    #[test]
    fn model_parser_and_validator_never_panic(text in mutated_model()) {
        if let Ok(gb) = geartherm::model::from_str(&text, Path::new("fuzz.toml")) {
            for n in gb.gears.iter().map(|g| g.name.as_str()).chain(gb.gear_states.iter().map(|s| s.name.as_str())) {
                prop_assert!(geartherm::model::parse::is_plain_name(n), "{n:?}");
            }
            let _ = geartherm::scene::Scene::compile(&gb);
        }
    }

    /// Random bytes as a model file never panic.
    #[test]
    fn model_parser_survives_random_text(text in "\\PC{0,400}") {
        let _ = geartherm::model::from_str(&text, Path::new("fuzz.toml"));
    }

    /// The cycle parser never panics on random rows, and what it accepts is within the limits:
    /// times increasing by at least MIN_TIME_STEP_S, speeds and torques bounded.
    #[test]
    fn cycle_parser_accepts_only_bounded_cycles(
        rig in any::<bool>(),
        rows in prop::collection::vec((hostile_number(), hostile_number(), hostile_number()), 0..12),
    ) {
        let mut text = String::from(if rig { "time_s,input_speed_rpm,input_torque_nm,gear\n" } else { "time_s,speed_kmh\n" });
        for (t, a, b) in &rows {
            if rig {
                text.push_str(&format!("{t},{a},{b},1\n"));
            } else {
                text.push_str(&format!("{t},{a}\n"));
            }
        }
        if let Ok(c) = DriveCycle::parse(&text, "fuzz.csv") {
            prop_assert!(c.rows.len() >= 2);
            for w in c.rows.windows(2) {
                prop_assert!(w[1].time >= w[0].time + MIN_TIME_STEP_S);
            }
            for r in &c.rows {
                prop_assert!((0.0..=MAX_TIME_S).contains(&r.time));
                prop_assert!(r.vehicle_speed * 3.6 <= MAX_VEHICLE_SPEED_KMH * (1.0 + 1e-12));
                prop_assert!(r.input_speed <= MAX_INPUT_SPEED_RPM * RPM * (1.0 + 1e-12));
                prop_assert!(r.input_torque.abs() <= MAX_INPUT_TORQUE_NM);
            }
        }
    }

    /// Random text as a cycle never panics.
    #[test]
    fn cycle_parser_survives_random_text(text in "\\PC{0,400}") {
        let _ = DriveCycle::parse(&text, "fuzz.csv");
    }

    /// Random override texts never panic the override parser.
    #[test]
    fn override_parser_survives_random_text(text in "\\PC{0,80}") {
        let _ = text.parse::<geartherm::model::Override>();
    }

    /// Hostile values at real key paths of the bundled models never panic the parser, the
    /// validator or the scene compile; an accepted model has plain part names.
    #[test]
    fn overrides_at_real_paths_never_panic(
        m in 0..MODELS.len(),
        path in prop_oneof![
            Just("lubrication.oil_level_mm"),
            Just("gears[0].face_width_mm"),
            Just("gears[1].teeth"),
            Just("gears[0].name"),
            Just("oil.catalogue"),
            Just("thermal.nodes[0].mass_kg"),
            Just("losses.friction"),
            Just("vehicle.mass_kg"),
            Just("gears[99].teeth"),
        ],
        value in prop_oneof![hostile_number(), Just("\"a\\nb,c\\\"d\"".to_string()), Just("\"fva_3a\"".to_string())],
    ) {
        if let Ok(ov) = format!("{path} = {value}").parse::<geartherm::model::Override>() {
            if let Ok(gb) = geartherm::model::from_str_with(MODELS[m], Path::new("fuzz.toml"), &[ov]) {
                for n in gb.gears.iter().map(|g| g.name.as_str()) {
                    prop_assert!(geartherm::model::parse::is_plain_name(n), "{n:?}");
                }
                let _ = geartherm::scene::Scene::compile(&gb);
            }
        }
    }
}
