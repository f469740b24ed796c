//! Criterion benches of the scene compile: the loss scene and the full scene of every example
//! model, and the pocket integral K of one AT6 helical mesh family, exact helical limit (what the
//! scene uses) vs 48 discrete slices.
//!
//! Also: the pocket teeth of one gear (geometry build from `physics::geometry::ToothProfile` +
//! the space bottom integral along the generated fillet) and the loss scene with every external
//! mesh's pocketing counted (`pocketing_mixture_density_kg_m3` set: by default the AT6, helical
//! and PT6 meshes run above the oil and build no pocket table).
//!
//! Run: `cargo bench --bench compile`. Figures are recorded in docs/performance.md.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use geartherm::model;
use geartherm::physics::losses::pocketing::{
    PocketFamily, PocketFamilyKind, PocketMeshInput, PocketTable, PocketTeeth,
};
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
        // every external mesh's pocket table built (mixture density set for the share above
        // the oil)
        let path = root.join(format!("models/{name}.toml"));
        let text = std::fs::read_to_string(&path).expect("model text");
        let text = if text.contains("\n[losses]\n") {
            text.replacen(
                "\n[losses]\n",
                "\n[losses]\npocketing_mixture_density_kg_m3 = 800.0\n",
                1,
            )
        } else {
            format!("{text}\n[losses]\npocketing_mixture_density_kg_m3 = 800.0\n")
        };
        let gb = model::from_str(&text, &path).expect("model with mixture density");
        c.bench_function(&format!("compile/loss_scene_all_pockets/{name}"), |b| {
            b.iter(|| LossScene::compile(black_box(&gb)))
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
    c.bench_function("pocket/teeth", |b| {
        b.iter(|| {
            PocketTeeth::new(
                inp.z1,
                inp.module,
                inp.pressure_angle,
                inp.helix_angle,
                inp.x1,
                black_box(inp.tip_radius1),
                inp.root_radius1,
                inp.rho_fp1,
                inp.face_width,
            )
        })
    });
    let profile = *g1.profile();
    c.bench_function("pocket/space_bottom_integral", |b| {
        b.iter(|| black_box(&profile).space_bottom_integral())
    });
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
