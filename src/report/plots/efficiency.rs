//! `efficiency.png`: efficiency vs time where it is defined (the line breaks where the output
//! power is zero), and beside it on the same efficiency axis its distribution as a histogram
//! **weighted by time** (share of the time during which efficiency is defined; each row
//! weighs half the interval to each neighbour, so non-uniform sampling is handled).

use plotters::prelude::*;
use plotters::series::DashedLineSeries;
use plotters::style::text_anchor::{HPos, VPos};

use super::data::{decimate, finite_segments, RunData};
use super::style::{self, LegendEntry, Swatch};
use super::{Canvas, DrawResult};

const BINS: usize = 30;

/// Time-weighted quantile `q` of `(value, weight)` pairs (weights ≥ 0).
pub fn weighted_quantile(pairs: &[(f64, f64)], q: f64) -> Option<f64> {
    let mut v: Vec<(f64, f64)> = pairs
        .iter()
        .copied()
        .filter(|(x, w)| x.is_finite() && *w >= 0.0)
        .collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = v.iter().map(|p| p.1).sum();
    if total <= 0.0 {
        return Some(v[0].0);
    }
    let mut acc = 0.0;
    for (x, w) in &v {
        acc += w;
        if acc >= q * total {
            return Some(*x);
        }
    }
    v.last().map(|p| p.0)
}

/// Draw `efficiency.png` of the run: efficiency vs time and its time-weighted histogram.
pub fn draw(root: &Canvas, run: &RunData) -> DrawResult {
    let ts = &run.ts;
    let sm = &run.summary;
    let title = format!(
        "Efficiency — {} / {}",
        sm.model.as_deref().unwrap_or("model"),
        sm.cycle.as_deref().unwrap_or("cycle")
    );
    let root = style::titled(root, &title)?;
    let (w, h) = root.dim_in_pixel();
    let (main, legend_strip) = root.split_vertically(h - 90);
    let (left, right) = main.split_horizontally((w as f64 * 0.70) as u32);

    let order = ts.time_order();
    let weights = ts.time_weights(&order);
    let eff_pct: Vec<f64> = ts.efficiency.iter().map(|e| 100.0 * e).collect();
    let pairs: Vec<(f64, f64)> = order
        .iter()
        .zip(&weights)
        .filter(|(&i, _)| eff_pct[i].is_finite())
        .map(|(&i, &wt)| (eff_pct[i], wt))
        .collect();
    let defined_time: f64 = pairs.iter().map(|p| p.1).sum();

    // y range: robust lower end (time-weighted 1st percentile) so that short low-efficiency
    // spells at near-zero output power do not squash the range where the gearbox spends its time.
    let e_min = pairs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let e_max = pairs.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    let p1 = weighted_quantile(&pairs, 0.01).unwrap_or(e_min);
    let floor = if e_min < p1 - 0.5 * (e_max - p1).max(1e-9) {
        p1
    } else {
        e_min
    };
    // One efficiency figure for the cycle: the energy-weighted ∫P_out/∫P_in of summary.json.
    let cycle_eff = sm.cycle_efficiency.filter(|m| m.is_finite()).map(|m| 100.0 * m);
    let (lo, hi) = cycle_eff
        .iter()
        .fold((floor, e_max), |(a, b), &m| (a.min(m), b.max(m)));
    let (y0, y1) = style::pad_range(lo, hi, 0.06);
    let clipped_time: f64 = pairs.iter().filter(|p| p.0 < y0).map(|p| p.1).sum();

    let t_lo = order.first().map(|&i| ts.time_s[i]).unwrap_or(0.0);
    let t_hi = order.last().map(|&i| ts.time_s[i]).unwrap_or(1.0);
    let (t_scale, t_desc) = style::time_axis(t_hi);
    let (x0, x1) = if t_hi > t_lo {
        (t_lo * t_scale, t_hi * t_scale)
    } else {
        style::pad_range(t_lo * t_scale, t_hi * t_scale, 0.0)
    };

    let mut chart = ChartBuilder::on(&left)
        .margin_left(20)
        .margin_right(10)
        .margin_top(20)
        .caption(
            "Efficiency vs time (where defined)",
            style::font(style::AXIS_DESC_PX),
        )
        .x_label_area_size(80)
        .y_label_area_size(110)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(t_desc)
        .y_desc("Efficiency (%)")
        .axis_desc_style(style::font(style::AXIS_DESC_PX))
        .label_style(style::font(style::TICK_PX))
        .light_line_style(style::GRID)
        .bold_line_style(style::GRID_BOLD)
        .x_labels(10)
        .y_labels(8)
        .x_label_formatter(&|v| style::fmt_num(*v))
        .y_label_formatter(&|v| style::fmt_num(*v))
        .draw()?;
    let line_colour = RGBColor(0, 90, 160);
    // plotters does not clip line series to the plotting area: clamp to the axis range so no
    // line is drawn over the title or below the axis.
    let clamped: Vec<f64> = eff_pct
        .iter()
        .map(|e| if e.is_finite() { e.clamp(y0, y1) } else { *e })
        .collect();
    for seg in finite_segments(&order, &ts.time_s, &clamped, t_scale) {
        if seg.len() == 1 {
            chart.draw_series(std::iter::once(Circle::new(seg[0], 3, line_colour.filled())))?;
        } else {
            // Two-point paths, not one polyline: plotters joins the segments of a wide polyline
            // with unlimited mitres, and the sharp spikes of this curve turned them into lines
            // across the whole figure (over the title, below the axis).
            let pts = decimate(&seg, 1200);
            chart.draw_series(
                pts.windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], line_colour.stroke_width(2))),
            )?;
        }
    }
    if pairs.is_empty() {
        style::draw_note_centre(&left, "efficiency undefined throughout (no output power)")?;
    }

    // Histogram, horizontal, sharing the efficiency axis.
    let bin_w = (y1 - y0) / BINS as f64;
    let mut share = [0.0f64; BINS];
    if defined_time > 0.0 {
        for (e, wt) in &pairs {
            let b = (((e.max(y0) - y0) / bin_w).floor().max(0.0) as usize).min(BINS - 1);
            share[b] += 100.0 * wt / defined_time;
        }
    }
    let s_max = share.iter().copied().fold(0.0f64, f64::max);
    let s_hi = if s_max > 0.0 { s_max * 1.1 } else { 1.0 };
    let mut hist = ChartBuilder::on(&right)
        .margin_left(10)
        .margin_right(30)
        .margin_top(20)
        .caption("Distribution (time-weighted)", style::font(style::AXIS_DESC_PX))
        .x_label_area_size(80)
        .y_label_area_size(20)
        .build_cartesian_2d(0.0..s_hi, y0..y1)?;
    hist.configure_mesh()
        .x_desc("Share of time (%)")
        .axis_desc_style(style::font(style::AXIS_DESC_PX))
        .label_style(style::font(style::TICK_PX))
        .light_line_style(style::GRID)
        .bold_line_style(style::GRID_BOLD)
        .x_labels(4)
        .y_labels(8)
        .x_label_formatter(&|v| style::fmt_num(*v))
        .y_label_formatter(&|_| String::new())
        .draw()?;
    hist.draw_series(share.iter().enumerate().filter(|(_, s)| **s > 0.0).map(|(b, s)| {
        let lo = y0 + b as f64 * bin_w;
        Rectangle::new([(0.0, lo), (*s, lo + bin_w)], RGBColor(86, 140, 196).filled())
    }))?;

    // The cycle efficiency.
    let summary_colour = RGBColor(213, 94, 0);
    let mut entries = vec![LegendEntry::new(
        "efficiency P_out / (P_out + P_loss)",
        Swatch::Line(line_colour, 2),
    )];
    for (m, colour, label) in [(
        cycle_eff,
        summary_colour,
        "cycle efficiency (energy-weighted, ∫P_out/∫P_in)",
    )] {
        if let Some(m) = m.filter(|m| *m >= y0 && *m <= y1) {
            chart.draw_series(DashedLineSeries::new(
                [(x0, m), (x1, m)],
                12,
                8,
                colour.stroke_width(2),
            ))?;
            hist.draw_series(DashedLineSeries::new(
                [(0.0, m), (s_hi, m)],
                12,
                8,
                colour.stroke_width(2),
            ))?;
            entries.push(LegendEntry::new(
                format!("{label}: {m:.2} %"),
                Swatch::Dashed(colour, 2),
            ));
        } else if let Some(m) = m {
            entries.push(LegendEntry::new(
                format!("{label}: {m:.2} % (off scale)"),
                Swatch::Dashed(colour, 2),
            ));
        }
    }
    let (legend_row, note_row) = legend_strip.split_vertically(50);
    style::draw_legend_row(&legend_row, &entries)?;
    if clipped_time > 0.0 {
        let (nw, _) = note_row.dim_in_pixel();
        note_row.draw(&Text::new(
            format!(
                "Efficiency below {:.1} % ({:.1} % of the time) is drawn at the lower edge of the axis and counted in the lowest bin.",
                y0,
                100.0 * clipped_time / defined_time
            ),
            (nw as i32 / 2, 18),
            style::text_at(style::NOTE_PX, HPos::Center, VPos::Center),
        ))?;
    }
    Ok(())
}
