//! `losses.png`: loss power stacked by source (churning at the bottom, then pocketing, then
//! sliding) vs time, with the file's `loss_total_w` drawn on top as a thin black line.

use plotters::prelude::*;

use super::data::{decimate, finite_segments, RunData};
use super::panel::{self, Axes, TimeAxis};
use super::style::{self, LegendEntry, Source, SourceColour, Swatch};
use super::{Canvas, DrawResult};

const LEGEND_W: u32 = 300;

/// Draw `losses.png` of the run: loss power stacked by source vs time, W.
pub fn draw(root: &Canvas, run: &RunData) -> DrawResult {
    let ts = &run.ts;
    let sm = &run.summary;
    let title = format!(
        "Loss power by source — {} / {}",
        super::data::name_or(&sm.model, "model"),
        super::data::name_or(&sm.cycle, "cycle")
    );
    let root = style::titled(root, &title)?;
    let (w, _) = root.dim_in_pixel();
    let (main, legend) = root.split_horizontally(w - LEGEND_W);

    // Rows with a finite time and finite source powers (a missing source value drops the row).
    let order: Vec<usize> = ts
        .time_order()
        .into_iter()
        .filter(|&i| Source::ALL.iter().all(|s| ts.source_w[s.index()][i].is_finite()))
        .collect();
    let TimeAxis {
        scale: t_scale,
        desc: t_desc,
        x0,
        x1,
    } = TimeAxis::over(&ts.time_s, &order);

    // Cumulative stacks (W): stack[k][r] = sum of sources 0..=k at row order[r].
    let mut stack = vec![vec![0.0; order.len()]; Source::ALL.len()];
    for (r, &i) in order.iter().enumerate() {
        let mut acc = 0.0;
        for s in Source::ALL {
            acc += ts.source_w[s.index()][i].max(0.0);
            stack[s.index()][r] = acc;
        }
    }
    let y_hi = stack[Source::ALL.len() - 1]
        .iter()
        .copied()
        .chain(ts.total_loss_w.iter().copied().filter(|v| v.is_finite()))
        .fold(0.0f64, f64::max);
    let (_, y1) = style::pad_range(0.0, y_hi, 0.06);
    let y1 = if y_hi > 0.0 { y1 } else { 1.0 };

    let mut chart = ChartBuilder::on(&main)
        .margin_left(20)
        .margin_right(30)
        .margin_top(10)
        .margin_bottom(10)
        .x_label_area_size(80)
        .y_label_area_size(120)
        .build_cartesian_2d(x0..x1, 0.0..y1)?;
    Axes::house()
        .x_desc(t_desc)
        .y_desc("Loss power (W)")
        .labels(12, 8)
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;

    let buckets = (w - LEGEND_W) as usize;
    let times: Vec<f64> = order.iter().map(|&i| ts.time_s[i] * t_scale).collect();
    if order.len() >= 2 {
        for s in Source::ALL {
            let k = s.index();
            let upper: Vec<(f64, f64)> = times.iter().copied().zip(stack[k].iter().copied()).collect();
            let lower: Vec<(f64, f64)> = if k == 0 {
                vec![(times[0], 0.0), (times[times.len() - 1], 0.0)]
            } else {
                times.iter().copied().zip(stack[k - 1].iter().copied()).collect()
            };
            // Decimation keeps per-pixel extremes, so the band outline is preserved.
            let mut poly = decimate(&upper, buckets);
            poly.extend(decimate(&lower, buckets).into_iter().rev());
            chart.draw_series(std::iter::once(Polygon::new(poly, s.colour().filled())))?;
            chart.draw_series(LineSeries::new(
                decimate(&upper, buckets),
                s.colour().stroke_width(1),
            ))?;
        }
    } else if let Some(&i) = order.first() {
        // A single row: stacked bar markers at that time.
        let t = ts.time_s[i] * t_scale;
        let half = 0.01 * (x1 - x0);
        let mut base = 0.0;
        for s in Source::ALL {
            let top = stack[s.index()][0];
            chart.draw_series(std::iter::once(Rectangle::new(
                [(t - half, base), (t + half, top)],
                s.colour().filled(),
            )))?;
            base = top;
        }
    }
    let total_order = ts.time_order();
    for seg in finite_segments(&total_order, &ts.time_s, &ts.total_loss_w, t_scale) {
        chart.draw_series(LineSeries::new(decimate(&seg, buckets), BLACK.stroke_width(1)))?;
    }
    if order.is_empty() {
        style::draw_note_centre(&main, "no rows with finite loss values")?;
    }

    let mut entries: Vec<LegendEntry> = Source::ALL
        .iter()
        .rev()
        .map(|s| LegendEntry::new(s.as_str(), Swatch::Fill(s.colour())))
        .collect();
    entries.push(LegendEntry::new("total", Swatch::Line(BLACK, 1)));
    style::draw_legend_column(&legend, Some("Source"), &entries, 14)?;
    Ok(())
}
