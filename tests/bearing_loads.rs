//! Bearing reactions from the gear forces close the static balance of every shaft and planet.

use geartherm::model;
use geartherm::model::gearbox::GearMount;
use geartherm::scene::bearing_loads::{balance_residual, mesh_forces, state_loads, Body, StateLoads};

fn load(path: &str) -> model::Gearbox {
    model::load(std::path::Path::new(path)).unwrap()
}

/// Loads for input torque `t` (the per-unit loads scaled: both power-flow directions).
fn scaled(l: &StateLoads, t: f64) -> StateLoads {
    let s = |f: [f64; 3]| [f[0] * t, f[1] * t, f[2] * t];
    StateLoads {
        applied: l
            .applied
            .iter()
            .map(|(b, p)| {
                let mut p = *p;
                p.force = s(p.force);
                (*b, p)
            })
            .collect(),
        reactions: l
            .reactions
            .iter()
            .map(|p| {
                let mut p = *p;
                p.force = s(p.force);
                p
            })
            .collect(),
        pin_moments: l.pin_moments.iter().map(|(b, m)| (*b, s(*m))).collect(),
    }
}

#[test]
fn every_shaft_and_planet_of_the_at6_balances_in_every_state_and_direction() {
    let gb = load("models/at6_lepelletier.toml");
    assert!(gb.bearings.len() >= 10);
    for si in 0..gb.gear_states.len() {
        let unit = state_loads(&gb, si);
        for t in [250.0, -250.0] {
            let l = scaled(&unit, t);
            let r = balance_residual(&gb, &l);
            assert!(
                r < 1e-9 * t.abs(),
                "state {} T {t}: residual {r}",
                gb.gear_states[si].name
            );
        }
        // A planet turns freely on its pin: its mesh torques about its own axis cancel (checks
        // the directions and signs of the mesh forces).
        for (g, gear) in gb.gears.iter().enumerate() {
            if let GearMount::Planet { .. } = gear.mount {
                let tz: f64 = unit
                    .applied
                    .iter()
                    .filter(|(b, _)| *b == Body::Planet(g))
                    .map(|(_, p)| p.at[0] * p.force[1] - p.at[1] * p.force[0])
                    .sum();
                assert!(
                    tz.abs() < 1e-9,
                    "state {} planet {}: torque {tz}",
                    gb.gear_states[si].name,
                    gear.name
                );
            }
        }
    }
}

#[test]
fn equally_spaced_planets_leave_no_radial_load_on_the_central_members() {
    // The N copies of a central gear's mesh force, rotated by 2πk/N, sum to zero transversely:
    // the basis of giving central members only the axial mesh forces.
    let gb = load("models/at6_lepelletier.toml");
    for si in 0..gb.gear_states.len() {
        for (m, pair) in gb.meshes.iter().zip(mesh_forces(&gb, si)) {
            let Some(set) = m.set else { continue };
            let n = gb.planetary_sets[set].planets;
            for f in pair {
                let (mut sx, mut sy) = (0.0, 0.0);
                for k in 0..n {
                    let a = 2.0 * std::f64::consts::PI * f64::from(k) / f64::from(n);
                    sx += a.cos() * f.force[0] - a.sin() * f.force[1];
                    sy += a.sin() * f.force[0] + a.cos() * f.force[1];
                }
                assert!(
                    sx.hypot(sy) < 1e-9 * (1.0 + f.force[0].hypot(f.force[1])),
                    "{}",
                    m.name
                );
            }
        }
    }
}

#[test]
fn fixed_axis_pairs_balance_and_split_by_the_lever_rule() {
    for path in [
        "models/fzg_c.toml",
        "models/helical_stage.toml",
        "models/pt6_spur_pair.toml",
    ] {
        let gb = load(path);
        let l = state_loads(&gb, 0);
        assert!(balance_residual(&gb, &l) < 1e-9, "{path}");
        // Gear midway between symmetric bearings, spur: each bearing takes half the force.
        if path.contains("fzg") {
            let (a, b) = (l.reactions[0].force, l.reactions[1].force);
            assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
            let f = l
                .applied
                .iter()
                .find(|(b, _)| *b == Body::Member(0))
                .unwrap()
                .1
                .force;
            assert!((2.0 * a[0] + f[0]).abs() < 1e-12 && (2.0 * a[1] + f[1]).abs() < 1e-12);
        }
    }
}
