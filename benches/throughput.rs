//! Study throughput: cases of the bundled AT6 WLTC study (`models/studies/at6_wltc_lhs.toml`)
//! solved per second by the study runner that `geartherm study` and Python's local backend call
//! (`study::runner::run`, nothing written), on every rayon thread, and one case on one thread
//! split into its parts: the model with the sample's overrides (parse + checks), the scene
//! compile, and the summary-only integration with and without the range checks over its output
//! rows (a study's table row keeps no warnings). Last, one whole sample of the AT6 WLTC
//! uncertainty study (`models/studies/at6_wltc_uq.toml`: overrides, checks, compile, run, band
//! series), as `geartherm uq` solves it.
//!
//! Run: `cargo bench --bench throughput`. Figures are recorded in docs/performance.md.

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use geartherm::job::{self, RunOptions};
use geartherm::study::uq::run::{Uq, UqOptions};
use geartherm::study::{runner, Selection, Study};

fn benches(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let study = Study::from_file(&root.join("models/studies/at6_wltc_lhs.toml")).expect("bundled study");
    let cases = Selection::cases((0..64).collect()).expect("64 cases");
    let mut g = c.benchmark_group("study");
    g.sample_size(10);
    g.throughput(Throughput::Elements(64));
    g.bench_function("at6_wltc/64_cases", |b| {
        b.iter(|| {
            runner::run(&study, black_box(&cases), None, &AtomicBool::new(false), &|_| {}).expect("run")
        })
    });
    g.finish();

    let (ovs, _) = study.overrides(0).expect("overrides");
    let model = || job::Model::from_text(&study.model_text, &study.model_file, &ovs).expect("model");
    let m = model();
    let o = RunOptions {
        summary_only: true,
        ..RunOptions::default()
    };
    c.bench_function("study/case/model_with_overrides", |b| b.iter(model));
    c.bench_function("study/case/scene_compile", |b| {
        b.iter(|| {
            black_box(&m)
                .compile(&geartherm::scene::Needs::default())
                .expect("scene")
        })
    });
    c.bench_function("study/case/run_summary_only", |b| {
        b.iter(|| job::run::run(black_box(&m), &o, &mut |_, _| {}).expect("run"))
    });
    let mut p = job::run::prepare(&m, &o).expect("prepare");
    for warnings in [true, false] {
        p.range_warnings = warnings;
        let name = if warnings { "with" } else { "without" };
        c.bench_function(&format!("study/case/solve_{name}_range_warnings"), |b| {
            b.iter(|| job::run::solve(black_box(&m), &p, &mut |_, _| {}).expect("run"))
        });
    }

    let uq = Uq::from_file(
        &root.join("models/studies/at6_wltc_uq.toml"),
        UqOptions::default(),
    )
    .expect("bundled uq study");
    let case = uq.study.cases()[0];
    c.bench_function("uq/case/at6_wltc_with_bands", |b| {
        b.iter(|| uq.study.run_case(black_box(&case), false))
    });
}

criterion_group!(throughput, benches);
criterion_main!(throughput);
