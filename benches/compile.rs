//! Criterion benches of the scene compile (issue 15): the loss scene and the full scene of every
//! example model, and the pocket integral K of one AT6 helical mesh family, exact helical limit
//! (the default) vs the former 48 discrete slices.
//!
//! Run: `cargo bench --bench compile`. Figures are recorded in docs/performance.md.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use geartherm::model;
use geartherm::physics::losses::pocketing::{PocketFamily, PocketFamilyKind, PocketMeshInput, PocketTable};
use geartherm::scene::{LossScene, Scene};

fn benches(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for name in ["at6_lepelletier", "fzg_c", "helical_stage", "pt6_spur_pair"] {
        let gb = model::load(&root.join(format!("models/{name}.toml"))).expect("bundled model");
        c.bench_function(&format!("compile/loss_scene/{name}"), |b| {
            b.iter(|| LossScene::compile(black_box(&gb)))
        });
        c.bench_function(&format!("compile/scene/{name}"), |b| {
            b.iter(|| Scene::compile(black_box(&gb)))
        });
        c.bench_function(&format!("compile/load_model/{name}"), |b| {
            b.iter(|| model::load(black_box(&root.join(format!("models/{name}.toml")))))
        });
    }
    // AT6 Ravigneaux large sun / long pinion (z 34/37 are read from the model)
    let gb = model::load(&root.join("models/at6_lepelletier.toml")).expect("bundled model");
    let m = gb
        .meshes
        .iter()
        .find(|m| m.name.contains("large_sun"))
        .expect("mesh");
    let (g1, g2) = (&gb.gears[m.gear1].geometry, &gb.gears[m.gear2].geometry);
    let inp = PocketMeshInput::from_gears(g1, g2, m.geometry.a_w);
    let s = inp.helix_angle.tan() / (0.5 * inp.module * inp.z1 as f64 / inp.helix_angle.cos());
    c.bench_function("pocket/family_geometry", |b| {
        b.iter(|| PocketFamily::new(black_box(&inp), PocketFamilyKind::SpaceOfGear2))
    });
    let fam = PocketFamily::new(&inp, PocketFamilyKind::SpaceOfGear2).expect("family");
    c.bench_function("pocket/table", |b| b.iter(|| PocketTable::new(black_box(&fam))));
    let table = PocketTable::new(&fam).expect("table");
    c.bench_function("pocket/k_helical_exact_limit", |b| {
        b.iter(|| table.k_helical_continuum(0.65, black_box(s)))
    });
    c.bench_function("pocket/k_helical_48_slices", |b| {
        b.iter(|| table.k_helical(0.65, black_box(s), 48))
    });
}

criterion_group! {
    name = group;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(group);
