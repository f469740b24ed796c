//! Cost per step against network size, from the criterion medians of
//! `cargo bench --bench solve -- wltc_network` (the AT6 WLTC with its housing meshed into N
//! patches): writes `plots/performance/cost_per_step.csv` and `cost_per_step.png` (log–log, sparse
//! and dense LU, with an N^1.2 guide through the sparse 50-patch point).
//!
//! `cargo run --release --example cost_per_step` (after the bench). Steps, LU factorisations and
//! RHS calls come from one integration per size here (they do not depend on the timing).

#[path = "../tests/common/wall.rs"]
mod wall;

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_time;

use std::fs;
use std::path::Path;

use plotters::prelude::*;

use geartherm::report::plots::style;
use geartherm::solve::transient::{integrate, LinearAlgebra, Method};

/// Criterion's median (s) of `wltc_network/<label>/<n>` (stored as `<label>_<n>`), if measured.
fn median(label: &str, n: usize) -> Option<f64> {
    let p = format!("target/criterion/wltc_network/{label}_{n}/new/estimates.json");
    let v: serde_json::Value = serde_json::from_str(&fs::read_to_string(p).ok()?).ok()?;
    Some(v["median"]["point_estimate"].as_f64()? * 1e-9)
}

struct Row {
    patches: usize,
    states: usize,
    steps: usize,
    lu: usize,
    rhs: usize,
    sparse_s: Option<f64>,
    dense_s: Option<f64>,
    sparse_cpu: f64,
    dense_cpu: Option<f64>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut rows = Vec::new();
    // COST_SIZES=500,1000 limits the sizes (for profiling one of them).
    let sizes: Vec<usize> = match std::env::var("COST_SIZES") {
        Ok(v) => v.split(',').filter_map(|x| x.trim().parse().ok()).collect(),
        Err(_) => wall::STUDY_SIZES.to_vec(),
    };
    // TR-BDF2 throughout (what `auto` uses above 24 nodes), so that the curve shows how the
    // linear algebra scales; COST_METHOD=ros3 for the other method.
    let method = std::env::var("COST_METHOD")
        .ok()
        .and_then(|m| Method::parse(&m))
        .unwrap_or(Method::TrBdf2);
    for n in sizes {
        let (scene, segs) = wall::meshed_at6_wltc(n);
        let run = |la: LinearAlgebra| {
            let o = wall::study_options(method, la);
            let c0 = cpu_time();
            let t = integrate(&scene, &segs, &o, &mut |_, _| {});
            (t, cpu_time() - c0)
        };
        let (t, cpu) = run(LinearAlgebra::Sparse);
        let t = t?;
        let dense_cpu = (n <= 200).then(|| run(LinearAlgebra::Dense).1);
        eprintln!(
            "{n} patches: {} states, one sparse run {:.4} s wall, {:.4} s CPU, {} steps, {} LU",
            scene.n_states(),
            t.wall_time_s,
            cpu,
            t.stats.steps,
            t.stats.lu_factorisations
        );
        if let Some(d) = dense_cpu {
            eprintln!("{n} patches: dense run {d:.4} s CPU");
        }
        rows.push(Row {
            patches: n,
            states: scene.n_states(),
            steps: t.stats.steps,
            lu: t.stats.lu_factorisations,
            rhs: t.stats.rhs_evals,
            sparse_s: median("sparse", n),
            dense_s: median("dense", n),
            sparse_cpu: cpu,
            dense_cpu,
        });
    }
    let out = Path::new("plots/performance");
    fs::create_dir_all(out)?;
    let mut csv = String::from(
        "patches,nodes,states,steps,lu_factorisations,rhs_evals,sparse_wltc_s,dense_wltc_s,sparse_us_per_step,dense_us_per_step,sparse_cpu_s,dense_cpu_s\n",
    );
    let f = |v: Option<f64>| v.map(|x| format!("{x:.6e}")).unwrap_or_default();
    for r in &rows {
        let per = |v: Option<f64>| v.map(|x| x / r.steps as f64 * 1e6);
        csv += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.patches,
            if r.patches == 0 { 5 } else { 4 + r.patches },
            r.states,
            r.steps,
            r.lu,
            r.rhs,
            f(r.sparse_s),
            f(r.dense_s),
            f(per(r.sparse_s)),
            f(per(r.dense_s)),
            f(Some(r.sparse_cpu)),
            f(r.dense_cpu)
        );
    }
    fs::write(out.join("cost_per_step.csv"), &csv)?;
    print!("{csv}");
    plot(&rows, &out.join("cost_per_step.png"))?;
    Ok(())
}

fn plot(rows: &[Row], path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    style::ensure_fonts()?;
    let per_step = |f: &dyn Fn(&Row) -> Option<f64>| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.patches >= 10)
            .filter_map(|r| Some((r.states as f64, f(r)? / r.steps as f64 * 1e6)))
            .collect()
    };
    let sp = per_step(&|r| Some(r.sparse_cpu));
    let de = per_step(&|r| r.dense_cpu);
    let sp_wall = per_step(&|r| r.sparse_s);
    let de_wall = per_step(&|r| r.dense_s);
    let all: Vec<f64> = sp
        .iter()
        .chain(&de)
        .chain(&sp_wall)
        .chain(&de_wall)
        .map(|p| p.1)
        .collect();
    let (ylo, yhi) = (
        all.iter().cloned().fold(f64::INFINITY, f64::min) / 1.5,
        all.iter().cloned().fold(0.0, f64::max) * 1.5,
    );
    let xs: Vec<f64> = sp.iter().map(|p| p.0).collect();
    let (xlo, xhi) = (xs[0] / 1.3, xs[xs.len() - 1] * 1.3);
    let root = BitMapBackend::new(path, (style::WIDTH, style::HEIGHT)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        "Cost per step vs network size — AT6 WLTC, housing meshed into patches (TR-BDF2, rtol 1e-4)",
        style::font(style::TITLE_PX - 8),
    )?;
    let mut chart = ChartBuilder::on(&root)
        .margin(30)
        .x_label_area_size(80)
        .y_label_area_size(110)
        .build_cartesian_2d((xlo..xhi).log_scale(), (ylo..yhi).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("States (nodes + per-source loss energies + boundary heat)")
        .x_labels(10)
        .y_labels(8)
        .y_desc("Time per accepted step (µs)")
        .axis_desc_style(style::font(style::AXIS_DESC_PX))
        .label_style(style::font(style::TICK_PX))
        .light_line_style(style::GRID)
        .bold_line_style(style::GRID_BOLD)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| style::fmt_num(*v))
        .draw()?;
    let blue = style::series_colour(0);
    let red = style::series_colour(1);
    chart
        .draw_series(LineSeries::new(sp.clone(), blue.stroke_width(3)))?
        .label("sparse (network LU), CPU time")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], blue.stroke_width(3)));
    chart.draw_series(sp.iter().map(|&p| Circle::new(p, 6, blue.filled())))?;
    chart
        .draw_series(LineSeries::new(de.clone(), red.stroke_width(3)))?
        .label("dense LU (nalgebra), CPU time")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], red.stroke_width(3)));
    chart.draw_series(de.iter().map(|&p| TriangleMarker::new(p, 7, red.filled())))?;
    // Criterion medians (wall time: on a loaded machine it includes waiting for a core).
    for (pts, c, label) in [
        (&sp_wall, blue, "sparse, criterion median (wall)"),
        (&de_wall, red, "dense, criterion median (wall)"),
    ] {
        if pts.is_empty() {
            continue;
        }
        let light = c.mix(0.45);
        chart
            .draw_series(LineSeries::new(pts.clone(), light.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], light.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Cross::new(p, 6, light.stroke_width(2))))?;
    }
    // N^1.2 guide through the sparse point of 50 patches (the criterion median if measured).
    let anchor = if sp_wall.is_empty() { &sp } else { &sp_wall };
    if let Some(&(x0, y0)) = anchor
        .iter()
        .min_by(|a, b| (a.0 - 58.0).abs().total_cmp(&(b.0 - 58.0).abs()))
    {
        let guide: Vec<(f64, f64)> = [x0, xhi / 1.3]
            .iter()
            .map(|&x| (x, y0 * (x / x0).powf(1.2)))
            .collect();
        let grey = style::NEUTRAL;
        chart
            .draw_series(LineSeries::new(guide, grey.stroke_width(2)))?
            .label("N^1.2 guide (goal: no steeper)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], grey.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(style::font(style::LEGEND_PX))
        .background_style(WHITE.mix(0.9))
        .border_style(style::GRID_BOLD)
        .draw()?;
    root.present()?;
    Ok(())
}
