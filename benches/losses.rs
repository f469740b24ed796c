//! Cost of evaluating every loss item of a gearbox at one operating point (criterion).
//!
//! Run: `cargo bench --bench losses`. Figures are recorded in docs/performance.md.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use geartherm::model;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{LossScene, OperatingPoint};

fn bench(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for (file, gear) in [
        ("at6_lepelletier", "1"),
        ("at6_lepelletier", "3"),
        ("fzg_c", "1"),
        ("helical_stage", "1"),
        ("pt6_spur_pair", "1"),
    ] {
        let gb = model::load(&root.join(format!("models/{file}.toml"))).expect("bundled model");
        let scene = LossScene::compile(&gb).expect("scene");
        let op = OperatingPoint {
            state: gb.state_index(gear).expect("gear"),
            input_speed: 2000.0 * std::f64::consts::PI / 30.0,
            input_torque: 200.0,
            oil: gb.oil.properties(80.0 + KELVIN_OFFSET),
        };
        let mut out = vec![0.0; scene.len()];
        c.bench_function(&format!("all losses {file} gear {gear}"), |b| {
            b.iter(|| {
                scene.evaluate(black_box(&op), &mut out);
                black_box(&out);
            })
        });
        c.bench_function(&format!("oil properties + all losses {file} gear {gear}"), |b| {
            b.iter(|| {
                let mut o = op;
                o.oil = gb.oil.properties(black_box(353.15));
                scene.evaluate(&o, &mut out);
                black_box(&out);
            })
        });
    }
    let gb = model::load(&root.join("models/at6_lepelletier.toml")).expect("bundled model");
    c.bench_function("compile loss scene at6_lepelletier", |b| {
        b.iter(|| LossScene::compile(black_box(&gb)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
