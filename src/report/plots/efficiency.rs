//! `efficiency.png`: efficiency vs time where it is defined (the line breaks where the output
//! power is zero), and beside it on the same efficiency axis its distribution as a histogram
//! **weighted by time** (share of the time during which efficiency is defined; each row
//! weighs half the interval to each neighbour, so non-uniform sampling is handled).

use plotters::prelude::*;
use plotters::series::DashedLineSeries;
use plotters::style::text_anchor::{HPos, VPos};

use super::data::{decimate, finite_segments, RunData};
use super::panel::{self, Axes, Chart, TimeAxis};
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

/// The efficiency values of a run and the axis range they are drawn on.
struct Efficiency {
    /// Rows in time order.
    order: Vec<usize>,
    /// Efficiency of every row, %.
    pct: Vec<f64>,
    /// (efficiency %, time weight) of the rows where it is defined.
    pairs: Vec<(f64, f64)>,
    /// Time during which it is defined, s.
    defined_time: f64,
    /// The energy-weighted cycle efficiency of summary.json, %.
    cycle: Option<f64>,
    /// Axis range, %.
    y0: f64,
    /// Axis range, %.
    y1: f64,
}

impl Efficiency {
    fn of(run: &RunData) -> Efficiency {
        let ts = &run.ts;
        let order = ts.time_order();
        let weights = ts.time_weights(&order);
        let pct: Vec<f64> = ts.efficiency.iter().map(|e| 100.0 * e).collect();
        let pairs: Vec<(f64, f64)> = order
            .iter()
            .zip(&weights)
            .filter(|(&i, _)| pct[i].is_finite())
            .map(|(&i, &wt)| (pct[i], wt))
            .collect();
        let defined_time: f64 = pairs.iter().map(|p| p.1).sum();
        // y range: robust lower end (time-weighted 1st percentile) so that short low-efficiency
        // spells at near-zero output power do not squash the range where the gearbox spends its
        // time.
        let e_min = pairs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
        let e_max = pairs.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
        let p1 = weighted_quantile(&pairs, 0.01).unwrap_or(e_min);
        let floor = if e_min < p1 - 0.5 * (e_max - p1).max(1e-9) {
            p1
        } else {
            e_min
        };
        // One efficiency figure for the cycle: the energy-weighted ∫P_out/∫P_in of summary.json.
        let cycle = run
            .summary
            .cycle_efficiency
            .filter(|m| m.is_finite())
            .map(|m| 100.0 * m);
        let (lo, hi) = cycle
            .iter()
            .fold((floor, e_max), |(a, b), &m| (a.min(m), b.max(m)));
        let (y0, y1) = style::pad_range(lo, hi, 0.06);
        Efficiency {
            order,
            pct,
            pairs,
            defined_time,
            cycle,
            y0,
            y1,
        }
    }
}

/// Draw `efficiency.png` of the run: efficiency vs time and its time-weighted histogram.
pub fn draw(root: &Canvas, run: &RunData) -> DrawResult {
    let sm = &run.summary;
    let title = format!(
        "Efficiency — {} / {}",
        super::data::name_or(&sm.model, "model"),
        super::data::name_or(&sm.cycle, "cycle")
    );
    let root = style::titled(root, &title)?;
    let (w, h) = root.dim_in_pixel();
    let (main, legend_strip) = root.split_vertically(h - 90);
    let (left, right) = main.split_horizontally((w as f64 * 0.70) as u32);
    let eff = Efficiency::of(run);
    let time = TimeAxis::over(&run.ts.time_s, &eff.order);
    let mut chart = draw_over_time(&left, run, &eff, time)?;
    let (mut hist, s_hi) = draw_histogram(&right, &eff)?;

    // The cycle efficiency.
    let (y0, y1) = (eff.y0, eff.y1);
    let summary_colour = RGBColor(213, 94, 0);
    let mut entries = vec![LegendEntry::new(
        "efficiency P_out / (P_out + P_loss)",
        Swatch::Line(LINE_COLOUR, 2),
    )];
    let label = "cycle efficiency (energy-weighted, ∫P_out/∫P_in)";
    if let Some(m) = eff.cycle.filter(|m| *m >= y0 && *m <= y1) {
        let dashed = |a: (f64, f64), b: (f64, f64)| {
            DashedLineSeries::new([a, b], 12, 8, summary_colour.stroke_width(2))
        };
        chart.draw_series(dashed((time.x0, m), (time.x1, m)))?;
        hist.draw_series(dashed((0.0, m), (s_hi, m)))?;
        entries.push(LegendEntry::new(
            format!("{label}: {m:.2} %"),
            Swatch::Dashed(summary_colour, 2),
        ));
    } else if let Some(m) = eff.cycle {
        entries.push(LegendEntry::new(
            format!("{label}: {m:.2} % (off scale)"),
            Swatch::Dashed(summary_colour, 2),
        ));
    }
    let (legend_row, note_row) = legend_strip.split_vertically(50);
    style::draw_legend_row(&legend_row, &entries)?;
    let clipped_time: f64 = eff.pairs.iter().filter(|p| p.0 < y0).map(|p| p.1).sum();
    if clipped_time > 0.0 {
        let (nw, _) = note_row.dim_in_pixel();
        note_row.draw(&Text::new(
            format!(
                "Efficiency below {:.1} % ({:.1} % of the time) is drawn at the lower edge of the axis and counted in the lowest bin.",
                y0,
                100.0 * clipped_time / eff.defined_time
            ),
            (nw as i32 / 2, 18),
            style::text_at(style::NOTE_PX, HPos::Center, VPos::Center),
        ))?;
    }
    Ok(())
}

/// Colour of the efficiency curve.
const LINE_COLOUR: RGBColor = RGBColor(0, 90, 160);

/// Left panel: efficiency vs time where it is defined.
fn draw_over_time<'b>(
    area: &Canvas<'b>,
    run: &RunData,
    eff: &Efficiency,
    time: TimeAxis,
) -> Result<Chart<'b>, Box<dyn std::error::Error>> {
    let (y0, y1) = (eff.y0, eff.y1);
    let mut chart = ChartBuilder::on(area)
        .margin_left(20)
        .margin_right(10)
        .margin_top(20)
        .caption(
            "Efficiency vs time (where defined)",
            style::font(style::AXIS_DESC_PX),
        )
        .x_label_area_size(80)
        .y_label_area_size(110)
        .build_cartesian_2d(time.x0..time.x1, y0..y1)?;
    Axes::house()
        .x_desc(time.desc)
        .y_desc("Efficiency (%)")
        .labels(10, 8)
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    // plotters does not clip line series to the plotting area: clamp to the axis range so no
    // line is drawn over the title or below the axis.
    let clamped: Vec<f64> = eff
        .pct
        .iter()
        .map(|e| if e.is_finite() { e.clamp(y0, y1) } else { *e })
        .collect();
    for seg in finite_segments(&eff.order, &run.ts.time_s, &clamped, time.scale) {
        if seg.len() == 1 {
            chart.draw_series(std::iter::once(Circle::new(seg[0], 3, LINE_COLOUR.filled())))?;
        } else {
            // Two-point paths, not one polyline: plotters joins the segments of a wide polyline
            // with unlimited mitres, and the sharp spikes of this curve turned them into lines
            // across the whole figure (over the title, below the axis).
            let pts = decimate(&seg, 1200);
            chart.draw_series(
                pts.windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], LINE_COLOUR.stroke_width(2))),
            )?;
        }
    }
    if eff.pairs.is_empty() {
        style::draw_note_centre(area, "efficiency undefined throughout (no output power)")?;
    }
    Ok(chart)
}

/// Right panel: the time-weighted distribution as a horizontal histogram sharing the efficiency
/// axis. Returns the chart and the upper end of its share axis, %.
fn draw_histogram<'b>(
    area: &Canvas<'b>,
    eff: &Efficiency,
) -> Result<(Chart<'b>, f64), Box<dyn std::error::Error>> {
    let (y0, y1) = (eff.y0, eff.y1);
    let bin_w = (y1 - y0) / BINS as f64;
    let mut share = [0.0f64; BINS];
    if eff.defined_time > 0.0 {
        for (e, wt) in &eff.pairs {
            let b = (((e.max(y0) - y0) / bin_w).floor().max(0.0) as usize).min(BINS - 1);
            share[b] += 100.0 * wt / eff.defined_time;
        }
    }
    let s_max = share.iter().copied().fold(0.0f64, f64::max);
    let s_hi = if s_max > 0.0 { s_max * 1.1 } else { 1.0 };
    let mut hist = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(30)
        .margin_top(20)
        .caption("Distribution (time-weighted)", style::font(style::AXIS_DESC_PX))
        .x_label_area_size(80)
        .y_label_area_size(20)
        .build_cartesian_2d(0.0..s_hi, y0..y1)?;
    Axes::house()
        .x_desc("Share of time (%)")
        .labels(4, 8)
        .x_format(&panel::compact)
        .y_format(&panel::blank)
        .draw(&mut hist)?;
    hist.draw_series(share.iter().enumerate().filter(|(_, s)| **s > 0.0).map(|(b, s)| {
        let lo = y0 + b as f64 * bin_w;
        Rectangle::new([(0.0, lo), (*s, lo + bin_w)], RGBColor(86, 140, 196).filled())
    }))?;
    Ok((hist, s_hi))
}
