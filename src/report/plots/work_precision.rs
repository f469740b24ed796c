//! `work_precision.png`: wall time vs maximum temperature error (log–log), one line with
//! markers per solver (points joined in order of rtol), rtol written next to points where it
//! does not collide with another label, the default setting ringed and annotated.

use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::data::{name_or, BenchRow};
use super::panel::Axes;
use super::style::{self, LegendEntry, Marker, Swatch};
use super::{Canvas, DrawResult};

/// Log-axis tick label: 1e-3 style outside [0.01, 1000), plain otherwise.
/// A value a bench row holds, None where it has none (NaN: an empty field, a failed run).
fn fin(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

fn log_label(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    if (0.01..1000.0).contains(&v) {
        style::fmt_num(v)
    } else {
        let e = v.log10();
        if (e - e.round()).abs() < 1e-6 {
            format!("1e{}", e.round() as i32)
        } else {
            format!("{v:.0e}")
        }
    }
}

/// Tick values for a log axis over [lo, hi]: 1, 2, 5 × 10^k over narrow ranges, decades (or every
/// n-th decade) over wide ones; and the remaining 1..9 × 10^k as light grid lines.
pub fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    // Held to the positive finite doubles: 0 would start the decades at i32::MIN.
    let lo = if lo > 0.0 {
        lo.min(f64::MAX)
    } else {
        f64::MIN_POSITIVE
    };
    let hi = if hi.is_finite() { hi.max(lo) } else { f64::MAX };
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let decades = (hi / lo).log10();
    let mults: &[f64] = if decades <= 2.5 { &[1.0, 2.0, 5.0] } else { &[1.0] };
    let every = ((k1 - k0) / 12 + 1).max(1);
    let (mut keys, mut light) = (Vec::new(), Vec::new());
    for k in k0..=k1 {
        let p = 10f64.powi(k);
        for m in 1..10 {
            let v = m as f64 * p;
            if v < lo || v > hi {
                continue;
            }
            if mults.contains(&(m as f64)) && (m != 1 || (k - k0) % every == 0) {
                keys.push(v);
            } else {
                light.push(v);
            }
        }
    }
    (keys, light)
}

fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    // Pad by a factor (log-space padding); widen a single value to a decade.
    let f = if hi / lo < 1.0 + 1e-9 {
        3.0
    } else {
        (hi / lo).powf(0.06).max(1.15)
    };
    // Within the normal doubles: a padded 1e-308 would underflow to 0.
    ((lo / f).max(f64::MIN_POSITIVE), (hi * f).min(f64::MAX))
}

/// True for a row with a positive finite error and wall time (drawn on the log–log axes).
fn drawable(r: &BenchRow) -> bool {
    matches!((fin(r.err_max_k), fin(r.wall_time_s)), (Some(e), Some(t)) if e.is_finite() && e > 0.0 && t.is_finite() && t > 0.0)
}

/// A log axis with its own tick values.
type LogAxis = WithKeyPoints<LogCoord<f64>>;

/// The log–log chart of the figure.
type LogChart<'b> = ChartContext<'b, BitMapBackend<'b>, Cartesian2d<LogAxis, LogAxis>>;

/// A log axis over [lo, hi] with the key and light points of [`log_ticks`].
fn log_axis(lo: f64, hi: f64) -> LogAxis {
    let (keys, light) = log_ticks(lo, hi);
    (lo..hi)
        .log_scale()
        .with_key_points(keys)
        .with_light_points(light)
}

/// Pixel boxes (x0, y0, x1, y1) of what is drawn, and the rtol labels waiting for a free place.
#[derive(Default)]
struct Placement {
    boxes: Vec<(i32, i32, i32, i32)>,
    pending: Vec<((i32, i32), String)>,
}

/// Draw `work_precision.png`: wall time vs maximum temperature error per solver.
pub fn draw(root: &Canvas, rows: &[BenchRow], model: &str, cycle: &str) -> DrawResult {
    let title = format!(
        "Work–precision — {} / {}",
        name_or(model, "model"),
        name_or(cycle, "cycle")
    );
    let root = style::titled(root, &title)?;
    let (w, _) = root.dim_in_pixel();
    let (main, legend) = root.split_horizontally(w - 320);
    let hidden = rows.iter().filter(|r| !drawable(r)).count();
    let (ex0, ex1) = log_range(
        rows.iter()
            .filter(|r| drawable(r))
            .filter_map(|r| fin(r.err_max_k)),
    );
    let (ty0, ty1) = log_range(
        rows.iter()
            .filter(|r| drawable(r))
            .filter_map(|r| fin(r.wall_time_s)),
    );
    let mut chart = ChartBuilder::on(&main)
        .margin_left(20)
        .margin_right(30)
        .margin_top(20)
        .margin_bottom(10)
        .x_label_area_size(80)
        .y_label_area_size(120)
        .build_cartesian_2d(log_axis(ex0, ex1), log_axis(ty0, ty1))?;
    let label = |v: &f64| log_label(*v);
    Axes::house()
        .x_desc("Maximum temperature error vs reference (K)")
        .y_desc("Wall time (s)")
        .labels(40, 40)
        .x_format(&label)
        .y_format(&label)
        .draw(&mut chart)?;
    let mut placed = Placement::default();
    let mut entries = draw_solvers(&mut chart, rows, &mut placed)?;
    let default_colour = RGBColor(0, 0, 0);
    for r in rows.iter().filter(|r| r.default && drawable(r)) {
        draw_default(&chart, r, default_colour, &mut placed)?;
    }
    draw_rtol_labels(&chart, placed)?;
    if rows.iter().any(|r| r.default) {
        entries.push(LegendEntry::new("default setting", Swatch::Ring(default_colour)));
    }
    style::draw_legend_column(&legend, Some("Solver"), &entries, 30)?;
    if hidden > 0 {
        let (_, lh) = legend.dim_in_pixel();
        legend.draw(&Text::new(
            format!("{hidden} row(s) with zero or missing"),
            (10, lh as i32 - 70),
            style::text(style::NOTE_PX),
        ))?;
        legend.draw(&Text::new(
            "error or time not shown".to_string(),
            (10, lh as i32 - 44),
            style::text(style::NOTE_PX),
        ))?;
    }
    Ok(())
}

/// One line with markers per solver (in order of first appearance; points joined in order of
/// rtol); every other point's rtol (and the last one's) waits in `placed` for a free place.
/// Returns the legend entries.
fn draw_solvers(
    chart: &mut LogChart,
    rows: &[BenchRow],
    placed: &mut Placement,
) -> Result<Vec<LegendEntry>, Box<dyn std::error::Error>> {
    let mut solvers: Vec<&str> = Vec::new();
    for r in rows {
        if !solvers.contains(&r.solver.as_str()) {
            solvers.push(&r.solver);
        }
    }
    let plot = chart.plotting_area().strip_coord_spec();
    let (ox, oy) = chart.plotting_area().get_base_pixel();
    let mut entries = Vec::new();
    for (k, solver) in solvers.iter().enumerate() {
        let colour = style::series_colour(k);
        let marker = Marker::nth(k);
        let mut pts: Vec<&BenchRow> = rows
            .iter()
            .filter(|r| r.solver == *solver && drawable(r))
            .collect();
        pts.sort_by(|a, b| b.rtol.total_cmp(&a.rtol));
        let xy: Vec<(f64, f64)> = pts
            .iter()
            .filter_map(|r| Some((fin(r.err_max_k)?, fin(r.wall_time_s)?)))
            .collect();
        chart.draw_series(LineSeries::new(xy.clone(), colour.stroke_width(3)))?;
        for (j, (r, p)) in pts.iter().zip(&xy).enumerate() {
            let (px, py) = chart.backend_coord(p);
            style::draw_marker_px(&plot, (px - ox, py - oy), marker, 9, colour.filled())?;
            placed.boxes.push((px - 12, py - 12, px + 12, py + 12));
            // Sparse labels: every other point, plus the last one.
            let wanted = j % 2 == 0 || j + 1 == xy.len();
            if let Some(rt) = fin(r.rtol).filter(|_| wanted) {
                placed.pending.push(((px, py), format!("rtol {}", log_label(rt))));
            }
        }
        entries.push(LegendEntry::new(*solver, Swatch::MarkerLine(colour, marker)));
    }
    Ok(entries)
}

/// The default setting `r`: ringed and annotated (right of the point, or left near the edge).
fn draw_default(chart: &LogChart, r: &BenchRow, colour: RGBColor, placed: &mut Placement) -> DrawResult {
    let (Some(e), Some(t)) = (fin(r.err_max_k), fin(r.wall_time_s)) else {
        return Ok(());
    };
    let plot = chart.plotting_area().strip_coord_spec();
    let (ox, oy) = chart.plotting_area().get_base_pixel();
    let (px, py) = chart.backend_coord(&(e, t));
    plot.draw(&Circle::new((px - ox, py - oy), 20, colour.stroke_width(4)))?;
    let label = format!(
        "default: {}, rtol {}",
        r.solver,
        fin(r.rtol).map(log_label).unwrap_or_default()
    );
    let (pw, _) = plot.dim_in_pixel();
    let right = px - ox < pw as i32 - 420;
    let (tx, anchor) = if right {
        (px - ox + 28, HPos::Left)
    } else {
        (px - ox - 28, HPos::Right)
    };
    plot.draw(&Text::new(
        label,
        (tx, py - oy - 26),
        style::text_at(style::LEGEND_PX, anchor, VPos::Center).color(&colour),
    ))?;
    let x0 = if right { px + 28 } else { px - 448 };
    placed.boxes.push((x0, py - 42, x0 + 420, py - 10));
    Ok(())
}

/// The waiting rtol labels where they fit (greedy, in row order): beside their point, inside the
/// plot, over nothing drawn.
fn draw_rtol_labels(chart: &LogChart, placed: Placement) -> DrawResult {
    let plot = chart.plotting_area().strip_coord_spec();
    let (ox, oy) = chart.plotting_area().get_base_pixel();
    let Placement { mut boxes, pending } = placed;
    let f = style::text(style::NOTE_PX);
    for ((px, py), label) in pending {
        let tw = plot
            .estimate_text_size(&label, &f)
            .map(|(w, _)| w as i32)
            .unwrap_or(80);
        let th = style::NOTE_PX as i32 + 4;
        for (dx, dy) in [(14, 6), (14, -th - 6), (-tw - 14, 6), (-tw - 14, -th - 6)] {
            let b = (px + dx, py + dy, px + dx + tw, py + dy + th);
            let (pw, ph) = plot.dim_in_pixel();
            let inside = b.0 - ox > 0 && b.2 - ox < pw as i32 && b.1 - oy > 0 && b.3 - oy < ph as i32;
            let free = !boxes
                .iter()
                .any(|o| b.0 < o.2 && o.0 < b.2 && b.1 < o.3 && o.1 < b.3);
            if inside && free {
                plot.draw(&Text::new(
                    label.clone(),
                    (b.0 - ox, b.1 - oy),
                    style::text(style::NOTE_PX).color(&style::NEUTRAL),
                ))?;
                boxes.push(b);
                break;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wall time of 1e-308 (a crafted bench.csv), padded, would reach 0 and start the decades
    /// at i32::MIN; the axis stays within the positive doubles and its ticks are bounded.
    #[test]
    fn log_axes_of_extreme_values_stay_bounded() {
        let (lo, hi) = log_range([1e-308, 3.6e-5, 1.2e29].into_iter());
        assert!(lo > 0.0 && hi.is_finite(), "{lo} {hi}");
        for (a, b) in [
            (lo, hi),
            (0.0, 1e-4),
            (f64::MIN_POSITIVE, f64::MAX),
            (1e-4, f64::INFINITY),
        ] {
            let (keys, light) = log_ticks(a, b);
            assert!(
                keys.len() + light.len() < 10 * 640,
                "{a} {b}: {}",
                keys.len() + light.len()
            );
            assert!(keys.iter().chain(&light).all(|v| v.is_finite() && *v > 0.0));
        }
    }
}
