//! The AT6's ATF cooler behind a thermostatic bypass valve (the variant of
//! validation/at6_bypass_valve/atf_bypass_valve.toml): a valve on a two-way exchanger throttles
//! the cooling direction only. While the coolant is warmer than the ATF the exchanger heats the
//! ATF at its full share, as the bundled model's thermostat lets it: over the WLTC's first
//! 600 s from 23 °C (ATF below the coolant and below the valve's 75 °C) both models give the
//! same temperatures. From a warm start the valve throttles, its share stays within [0, 1], and
//! the energy balance stays closed.

use geartherm::model;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::solve::transient::{energy_balance, integrate, Method, Segment, TransientOptions};

#[path = "common/wall.rs"]
mod wall;
use wall::wltc_scene;

/// The variant's model text: the bypass-valve block in place of the `atf_cooler` block.
fn variant() -> model::Gearbox {
    let path = std::path::Path::new("models/at6_lepelletier.toml");
    let base = std::fs::read_to_string(path).unwrap();
    let block = std::fs::read_to_string("validation/at6_bypass_valve/atf_bypass_valve.toml").unwrap();
    let start = base.find("[[thermal.coolers]]\nname = \"atf_cooler\"").unwrap();
    let tail = &base[start..];
    let end = start + tail.find("thermostat = {").unwrap();
    let end = end + base[end..].find('\n').unwrap() + 1;
    let text = format!("{}{}{}", &base[..start], block, &base[end..]);
    model::from_str(&text, path).unwrap()
}

fn opts(initial: Option<f64>) -> TransientOptions {
    TransientOptions {
        method: Method::Ros3,
        rtol: 1e-10,
        atol: 1e-10,
        initial_temp: initial,
        ..TransientOptions::default()
    }
}

#[test]
fn the_valve_leaves_the_warm_up_heating_alone() {
    let base = model::load(std::path::Path::new("models/at6_lepelletier.toml")).unwrap();
    let (s0, segs) = wltc_scene(&base);
    let (s1, _) = wltc_scene(&variant());
    assert_eq!(s1.thermal().controls.len(), 1);
    let first: Vec<Segment> = segs.iter().filter(|s| s.t1 <= 600.0).copied().collect();
    let a = integrate(&s0, &first, &opts(None), &mut |_, _| {}).unwrap();
    let b = integrate(&s1, &first, &opts(None), &mut |_, _| {}).unwrap();
    let sump = s0.thermal().names.iter().position(|n| n == "sump").unwrap();
    let mut worst: f64 = 0.0;
    let mut sump_max: f64 = f64::MIN;
    for (ya, yb) in a.states.iter().zip(&b.states) {
        for i in 0..s0.nodes() {
            worst = worst.max((ya[i] - yb[i]).abs());
        }
        sump_max = sump_max.max(ya[sump] - KELVIN_OFFSET);
    }
    let moved = {
        let y = b.states.last().unwrap();
        y[s1.control_row_index()]
    };
    println!(
        "WLTC 0–600 s from 23 °C: ATF max {sump_max:.3} °C; thermostat vs bypass valve worst {worst:.3e} K; \
         heat through the exchanger {:.1} kJ (negative: into the ATF)",
        moved / 1e3
    );
    assert!(
        sump_max < 75.0,
        "the valve stays closed over this stretch: {sump_max}"
    );
    assert!(
        worst < 1e-6,
        "the warm-up heating must not depend on the valve: {worst} K"
    );
    assert!(moved < -1e4, "the exchanger heats the ATF: {moved} J");
}

#[test]
fn from_a_warm_start_the_valve_throttles_within_its_limits() {
    let (s1, segs) = wltc_scene(&variant());
    let traj = integrate(&s1, &segs, &opts(Some(80.0 + KELVIN_OFFSET)), &mut |_, _| {}).unwrap();
    let (lo, hi) = traj
        .controls
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), c| (a.min(c[0]), b.max(c[0])));
    let bal = energy_balance(&s1, &traj);
    println!(
        "WLTC from 80 °C with the bypass valve: share {lo:.4}–{hi:.4}, switches {:?}, balance {:.2e}",
        traj.switches, bal.relative
    );
    assert!((0.0..=1.0).contains(&lo) && (0.0..=1.0).contains(&hi));
    assert!(hi > lo, "the valve must move");
    assert!(bal.relative < 1e-9);
}
