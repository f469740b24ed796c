//! Large networks: the AT6 housing meshed into 50 patches (`[thermal.wall_mesh]`) over the WLTC,
//! with the sparse LU (faer) and the dense one (nalgebra).

#[path = "common/wall.rs"]
mod wall;

use geartherm::model::wall_mesh::{mesh_wall, WallMeshSpec};
use geartherm::model::Problems;
use geartherm::solve::transient::{energy_balance, integrate, LinearAlgebra, TransientOptions};

fn opts(la: LinearAlgebra) -> TransientOptions {
    TransientOptions {
        record_losses: false,
        linear_algebra: la,
        ..TransientOptions::default()
    }
}

#[test]
fn fifty_patch_wall_runs_the_wltc_sparse_with_the_energy_balance_closed() {
    let (around, along) = wall::grid(50);
    let gb = wall::at6_with(&wall::mesh_toml(around, along, Some(0.3), 100.0));
    let (scene, segs) = wall::wltc_scene(&gb);
    assert_eq!(scene.nodes(), 5 - 1 + 50);
    let sparse = integrate(&scene, &segs, &opts(LinearAlgebra::Sparse), &mut |_, _| {}).unwrap();
    assert!(sparse.stats.sparse);
    let b = energy_balance(&scene, &sparse);
    assert!(b.relative < 1e-9, "energy balance {b:?}");
    assert!(b.lost > 1e5, "the AT6 loses > 100 kJ over a WLTC: {b:?}");

    // The sump pool wets the first 3 of 10 columns: those patches run warmer than the dry ones
    // while the oil heats the case (mid-cycle), the last dry column the coolest.
    let names = &scene.thermal().names;
    let col_mean = |y: &[f64], i: usize| -> f64 {
        let v: Vec<f64> = (0..along)
            .map(|j| {
                y[names
                    .iter()
                    .position(|n| *n == format!("housing_{i}_{j}"))
                    .unwrap()]
            })
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let mid = &sparse.states[sparse.states.len() / 2];
    let (wet, dry) = (col_mean(mid, 1), col_mean(mid, 6));
    assert!(wet > dry + 0.05, "wetted column {wet} K, dry column {dry} K");

    // The dense LU gives the same trajectory (only the linear algebra differs).
    let dense = integrate(&scene, &segs, &opts(LinearAlgebra::Dense), &mut |_, _| {}).unwrap();
    assert!(!dense.stats.sparse);
    let n = scene.nodes();
    let mut worst = 0.0f64;
    for (a, b) in sparse.states.iter().zip(&dense.states) {
        for i in 0..n {
            worst = worst.max((a[i] - b[i]).abs());
        }
    }
    assert!(worst < 1e-6, "sparse vs dense: {worst} K");
}

#[test]
fn evenly_split_mesh_reproduces_the_lumped_housing() {
    // Every link and heat input split evenly: each patch sees the lumped node's equation per unit
    // capacity, so the patches stay equal to the lumped housing whatever the wall conducts.
    let lumped = wall::at6_with("");
    let meshed = wall::at6_with(&wall::mesh_toml(5, 4, None, 100.0));
    let (s0, segs) = wall::wltc_scene(&lumped);
    let (s1, _) = wall::wltc_scene(&meshed);
    let o = opts(LinearAlgebra::Auto);
    let a = integrate(&s0, &segs, &o, &mut |_, _| {}).unwrap();
    let b = integrate(&s1, &segs, &o, &mut |_, _| {}).unwrap();
    let h0 = s0.thermal().names.iter().position(|n| n == "housing").unwrap();
    let oil = s0.thermal().oil;
    assert_eq!(oil, s1.thermal().oil);
    let mut worst = 0.0f64;
    for (ya, yb) in a.states.iter().zip(&b.states) {
        worst = worst.max((ya[oil] - yb[oil]).abs());
        for (i, name) in s1.thermal().names.iter().enumerate() {
            if name.starts_with("housing_") {
                worst = worst.max((ya[h0] - yb[i]).abs());
            }
        }
    }
    // Integration error of the default tolerance (the error norms differ: 24 vs 5 nodes).
    assert!(worst < 2e-3, "meshed vs lumped: {worst} K");
    let e0 = energy_balance(&s0, &a);
    let e1 = energy_balance(&s1, &b);
    assert!((e0.lost - e1.lost).abs() < 1e-4 * e0.lost, "{e0:?} {e1:?}");
}

#[test]
fn wall_mesh_errors_name_the_key() {
    let gb = wall::at6_with("");
    let net = gb.thermal.clone().unwrap();
    let spec = |node: &str, around: usize| WallMeshSpec {
        node: node.into(),
        around,
        along: 2,
        circumference_m: 1.0,
        length_m: 0.5,
        thickness_mm: 5.0,
        conductivity_w_per_mk: 100.0,
        oil_wetted_fraction: None,
    };
    for (s, path, what) in [
        (spec("sump", 2), "thermal.wall_mesh.node", "oil node"),
        (spec("nowhere", 2), "thermal.wall_mesh.node", "unknown node"),
        (spec("housing", 0), "thermal.wall_mesh.around", "must lie in"),
    ] {
        let mut p = Problems::default();
        let out = mesh_wall(net.clone(), &s, &mut p);
        let list = p.into_vec();
        assert!(
            list.iter().any(|x| x.path == path && x.allowed.contains(what)),
            "{list:?}"
        );
        assert_eq!(out.nodes.len(), net.nodes.len(), "unchanged on error");
    }
    // Through the model file: the same error with the file's key path.
    let path = std::path::Path::new("models/at6_lepelletier.toml");
    let text = std::fs::read_to_string(path).unwrap() + &wall::mesh_toml(4, 2, Some(1.5), 100.0);
    match geartherm::model::from_str(&text, path) {
        Err(geartherm::model::ModelError::Invalid { problems, .. }) => assert!(
            problems
                .iter()
                .any(|p| p.path == "thermal.wall_mesh.oil_wetted_fraction"),
            "{problems:?}"
        ),
        other => panic!("expected an invalid model, got {other:?}"),
    }
}

#[test]
fn assembled_jacobian_equals_the_jacobian_vector_products() {
    // The 50-patch AT6 (conduction, convection tables, radiation, the thermostat cooler, rotating
    // parts in oil), away from the initial state, at a mid-cycle sample.
    let (around, along) = wall::grid(50);
    let gb = wall::at6_with(&wall::mesh_toml(around, along, Some(0.3), 100.0));
    let (scene, segs) = wall::wltc_scene(&gb);
    let mut work = scene.work(segs[900].inputs);
    let mut y = scene.initial_state(None);
    for (i, t) in y.iter_mut().take(scene.nodes()).enumerate() {
        *t += 40.0 + 0.37 * i as f64;
    }
    let pattern = scene.jacobian_pattern();
    let mut vals = vec![0.0; pattern.len()];
    scene.jacobian_values(300.0, &y, &mut work, &mut vals);
    let n = scene.n_states();
    let mut dense = vec![0.0; n * n];
    for (&(r, c), v) in pattern.iter().zip(&vals) {
        dense[r + c * n] += v;
    }
    let (mut v, mut col) = (vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    for j in 0..n {
        v.iter_mut().for_each(|x| *x = 0.0);
        v[j] = 1.0;
        scene.jvp(300.0, &y, &v, &mut work, &mut col);
        // Relative to the column's largest entry (sums in another order round differently).
        let scale = (0..n)
            .map(|i| dense[i + j * n].abs().max(col[i].abs()))
            .fold(f64::MIN_POSITIVE, f64::max);
        for i in 0..n {
            worst = worst.max((dense[i + j * n] - col[i]).abs() / scale);
        }
    }
    assert!(worst < 1e-12, "assembled vs products: {worst}");
}
