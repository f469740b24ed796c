#![allow(dead_code)]
//! The AT6 with its housing meshed into patches (`[thermal.wall_mesh]` appended to the bundled
//! model file), for the sparse-network tests and benches.

use std::path::Path;

use geartherm::cycle::DriveCycle;
use geartherm::model::{self, Gearbox};
use geartherm::scene::{Needs, Scene};
use geartherm::solve::drive::segments;
use geartherm::solve::transient::{LinearAlgebra, Method, Segment, TransientOptions};

/// Patches (around, along) for a wall of about `n` patches.
pub fn grid(n: usize) -> (usize, usize) {
    match n {
        50 => (10, 5),
        100 => (10, 10),
        200 => (20, 10),
        500 => (25, 20),
        1000 => (40, 25),
        _ => (n.clamp(1, 10), n.div_ceil(10).max(1)),
    }
}

/// The `[thermal.wall_mesh]` table for the AT6 case: 0.7 m² of die-cast aluminium (the
/// housing-air area of the model) as a 1.4 m × 0.5 m shell, 15 mm thick (28 kg at 2700 kg/m³),
/// conductivity 100 W/(m·K) (assumed for a die-cast AlSi alloy).
pub fn mesh_toml(around: usize, along: usize, wetted: Option<f64>, k: f64) -> String {
    let mut s = format!(
        "\n[thermal.wall_mesh]\nnode = \"housing\"\naround = {around}\nalong = {along}\n\
         circumference_m = 1.4\nlength_m = 0.5\nthickness_mm = 15.0\nconductivity_w_per_mk = {k}\n"
    );
    if let Some(f) = wetted {
        s += &format!("oil_wetted_fraction = {f}\n");
    }
    s
}

/// The AT6 model, with `extra` appended to its text.
pub fn at6_with(extra: &str) -> Gearbox {
    let path = Path::new("models/at6_lepelletier.toml");
    let text = std::fs::read_to_string(path).unwrap() + extra;
    model::from_str(&text, path).unwrap()
}

/// Scene (as `run --summary-only` compiles it) and WLTC segments of a gearbox.
pub fn wltc_scene(gb: &Gearbox) -> (Scene, Vec<Segment>) {
    let cycle = DriveCycle::resolve("wltc").unwrap();
    let (_, segs) = segments(gb, &cycle).unwrap();
    let needs = Needs {
        states: Some(segs.iter().map(|s| s.inputs.state).collect()),
        energy_per_source_only: true,
        ..Needs::default()
    };
    (Scene::compile_for(gb, &needs).unwrap(), segs)
}

/// Wall sizes (patches) of the cost-per-step study (`benches/solve.rs` `wltc_network`,
/// `examples/cost_per_step.rs`).
pub const STUDY_SIZES: [usize; 9] = [0, 10, 20, 30, 50, 100, 200, 500, 1000];

/// The AT6 with a wall of about `n` patches (0: the lumped housing), 30 % of the circumference
/// wetted, k = 100 W/(m·K): scene and WLTC segments.
pub fn meshed_at6_wltc(n: usize) -> (Scene, Vec<Segment>) {
    let (around, along) = grid(n);
    let extra = if n == 0 {
        String::new()
    } else {
        mesh_toml(around, along, Some(0.3), 100.0)
    };
    wltc_scene(&at6_with(&extra))
}

/// Options of the cost-per-step study: `method` at the default tolerance, no per-row losses.
pub fn study_options(method: Method, la: LinearAlgebra) -> TransientOptions {
    TransientOptions {
        method,
        record_losses: false,
        linear_algebra: la,
        ..TransientOptions::default()
    }
}
