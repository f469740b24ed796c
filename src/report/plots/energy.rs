//! `energy.png`: energy lost over the cycle per loss item (component) as horizontal bars
//! coloured by source, largest at the top, and the per-source totals beside it (kJ).
//!
//! Values come from `summary.json` (`energy_by_item_j`, `energy_lost_j`); where the summary
//! lacks them they are integrated from `timeseries.csv` with the trapezoidal rule.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::data::RunData;
use super::panel::{self, Axes, Grid};
use super::style::{self, LegendEntry, Source, SourceColour, Swatch};
use super::{Canvas, DrawResult};
use crate::scene::{PerSource, N_SOURCES};

/// Most bars shown; the rest are summed into one "other" bar.
const MAX_BARS: usize = 40;

/// ∫ p dt by the trapezoidal rule over rows in time order; intervals touching a missing value
/// are skipped. J when `p` is in W and time in s.
pub fn trapezoid(order: &[usize], t: &[f64], p: &[f64]) -> f64 {
    order
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let e = 0.5 * (p[a] + p[b]) * (t[b] - t[a]);
            if e.is_finite() {
                e
            } else {
                0.0
            }
        })
        .sum()
}

/// (source, item name, J) for every item, from the summary or integrated from the time series.
pub fn item_energies(run: &RunData) -> Vec<(Option<Source>, String, f64)> {
    let sm = &run.summary;
    if !sm.energy_by_item_j.is_empty() {
        return sm
            .energy_by_item_j
            .iter()
            .map(|e| (Some(e.source), e.name.clone(), e.j))
            .collect();
    }
    let order = run.ts.time_order();
    run.ts
        .items
        .iter()
        .map(|it| {
            (
                Some(it.source),
                it.name.clone(),
                trapezoid(&order, &run.ts.time_s, &it.power_w),
            )
        })
        .collect()
}

/// The summary's energy per source, when it has one (`energy_lost_j` with its `total`; a
/// summary without the key reads as none).
pub fn summary_energies<'a>(run: &'a RunData) -> Option<&'a crate::report::sources::SourceValues> {
    Some(&run.summary.energy_lost_j).filter(|e| e.total)
}

/// Energy per source, J (summary first, else integrated source columns).
pub fn source_energies(run: &RunData) -> PerSource {
    let order = run.ts.time_order();
    let mut out = [0.0; N_SOURCES];
    for s in Source::ALL {
        let from_summary = summary_energies(run).map(|e| e.get(s)).filter(|v| v.is_finite());
        out[s.index()] =
            from_summary.unwrap_or_else(|| trapezoid(&order, &run.ts.time_s, &run.ts.source_w[s.index()]));
    }
    out
}

/// Draw `energy.png` of the run: energy lost per item and per source, kJ.
pub fn draw(root: &Canvas, run: &RunData) -> DrawResult {
    let sm = &run.summary;
    let title = format!(
        "Energy lost over the cycle — {} / {}",
        super::data::name_or(&sm.model, "model"),
        super::data::name_or(&sm.cycle, "cycle")
    );
    let root = style::titled(root, &title)?;
    let (w, _) = root.dim_in_pixel();
    let (left, right) = root.split_horizontally((w as f64 * 0.66) as u32);
    let items = bar_items(run);
    draw_items(&left, &items)?;

    // Right: per-source totals and the legend.
    let (_, rh) = right.dim_in_pixel();
    let (totals_area, legend_area) = right.split_vertically((rh as f64 * 0.6) as u32);
    draw_sources(&totals_area, run)?;
    let mut entries: Vec<LegendEntry> = Source::ALL
        .iter()
        .map(|s| LegendEntry::new(s.as_str(), Swatch::Fill(s.colour())))
        .collect();
    if items.iter().any(|r| r.0.is_none()) {
        entries.push(LegendEntry::new(
            "other / unknown source",
            Swatch::Fill(style::NEUTRAL),
        ));
    }
    style::draw_legend_column(&legend_area, Some("Bar colour = loss source"), &entries, 20)?;
    if let Some(b) = Some(sm.energy_balance_relative).filter(|b| b.is_finite()) {
        let (_, lh) = legend_area.dim_in_pixel();
        legend_area.draw(&Text::new(
            format!("energy balance residual: {:.2e} (relative)", b),
            (10, lh as i32 - 30),
            style::text_at(style::NOTE_PX, HPos::Left, VPos::Center),
        ))?;
    }
    Ok(())
}

/// The bars of the per-component chart: (source, name, J), largest first, NaN dropped, beyond
/// [`MAX_BARS`] summed into "other".
fn bar_items(run: &RunData) -> Vec<(Option<Source>, String, f64)> {
    let mut items: Vec<(Option<Source>, String, f64)> = item_energies(run)
        .into_iter()
        .filter(|(_, _, j)| j.is_finite())
        .collect();
    items.sort_by(|a, b| b.2.total_cmp(&a.2));
    if items.len() > MAX_BARS {
        let rest: Vec<_> = items.split_off(MAX_BARS - 1);
        let sum: f64 = rest.iter().map(|r| r.2).sum();
        items.push((None, format!("other ({} items)", rest.len()), sum));
    }
    items
}

/// The label of category row `v` of a bar chart whose rows, from the top, are named `names`.
fn row_name(names: &[String], v: &SegmentValue<i32>) -> String {
    match v {
        SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => {
            let k = names.len() as i32 - 1 - *i;
            if k >= 0 && (k as usize) < names.len() {
                names[k as usize].clone()
            } else {
                String::new()
            }
        }
        SegmentValue::Last => String::new(),
    }
}

/// Left panel: one bar per item (kJ), coloured by source, its value at its end.
fn draw_items(area: &Canvas, items: &[(Option<Source>, String, f64)]) -> DrawResult {
    let n = items.len();
    let kj: Vec<f64> = items.iter().map(|r| r.2 / 1e3).collect();
    let x_max = kj.iter().copied().fold(0.0f64, f64::max);
    let x_min = kj.iter().copied().fold(0.0f64, f64::min);
    let x_hi = if x_max > 0.0 { x_max * 1.22 } else { 1.0 };

    // Label font shrinks with the number of bars so that names stay readable and separate.
    let (_, lh) = area.dim_in_pixel();
    let bar_px = (lh as f64 - 140.0) / n.max(1) as f64;
    let label_px = (bar_px * 0.7).clamp(12.0, style::TICK_PX as f64) as u32;
    let names: Vec<String> = items
        .iter()
        .map(|r| style::fit_label(area, &r.1, label_px, 260))
        .collect();
    let name_w = names
        .iter()
        .map(|s| {
            area.estimate_text_size(s, &style::text(label_px))
                .map(|(w, _)| w)
                .unwrap_or(100)
        })
        .max()
        .unwrap_or(60)
        + 20;

    let mut chart = ChartBuilder::on(area)
        .margin_left(20)
        .margin_right(20)
        .margin_top(20)
        .margin_bottom(10)
        .caption("Per component", style::font(style::AXIS_DESC_PX))
        .x_label_area_size(80)
        .y_label_area_size(name_w.max(80))
        .build_cartesian_2d(x_min.min(0.0)..x_hi, (0..(n.max(2) as i32 - 1)).into_segmented())?;
    Axes::house()
        .grid(Grid::Vertical)
        .x_desc("Energy lost (kJ)")
        .y_tick_style(style::font(label_px).into())
        .labels(8, n.max(1))
        .x_format(&panel::compact)
        .y_format(&|v| row_name(&names, v))
        .draw(&mut chart)?;
    let margin = ((bar_px * 0.15) as u32).clamp(1, 8);
    for (k, ((src, _, _), v)) in items.iter().zip(&kj).enumerate() {
        let row = (n - 1 - k) as i32;
        let colour = src.map(|s| s.colour()).unwrap_or(style::NEUTRAL);
        let mut bar = Rectangle::new(
            [
                (0.0, SegmentValue::Exact(row)),
                (*v, SegmentValue::Exact(row + 1)),
            ],
            colour.filled(),
        );
        bar.set_margin(margin, margin, 0, 0);
        chart.draw_series(std::iter::once(bar))?;
        let label = style::fmt_sig(*v, 3);
        chart.draw_series(std::iter::once(
            EmptyElement::at((v.max(0.0), SegmentValue::CenterOf(row)))
                + Text::new(
                    label,
                    (6, 0),
                    style::text_at(label_px.min(style::NOTE_PX), HPos::Left, VPos::Center),
                ),
        ))?;
    }
    if n == 0 {
        style::draw_note_centre(area, "no loss items")?;
    }
    Ok(())
}

/// Right panel: one bar per source and the total (kJ), the three largest shares in %.
fn draw_sources(area: &Canvas, run: &RunData) -> DrawResult {
    let src_kj: Vec<f64> = source_energies(run).iter().map(|j| j / 1e3).collect();
    let total_kj: f64 = summary_energies(run)
        .map(|e| e.sum())
        .filter(|v| v.is_finite())
        .map(|j| j / 1e3)
        .unwrap_or_else(|| src_kj.iter().sum());
    let rows: Vec<(String, RGBColor, f64)> = Source::ALL
        .iter()
        .map(|s| (s.as_str().to_string(), s.colour(), src_kj[s.index()]))
        .chain([("total".to_string(), RGBColor(70, 70, 70), total_kj)])
        .collect();
    let names: Vec<String> = rows.iter().map(|r| r.0.clone()).collect();
    let t_max = rows.iter().map(|r| r.2).fold(0.0f64, f64::max);
    let t_hi = if t_max > 0.0 { t_max * 1.45 } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(30)
        .margin_top(20)
        .caption("Per source", style::font(style::AXIS_DESC_PX))
        .x_label_area_size(80)
        .y_label_area_size(140)
        .build_cartesian_2d(0.0..t_hi, (0..(rows.len() as i32 - 1)).into_segmented())?;
    Axes::house()
        .grid(Grid::Vertical)
        .x_desc("Energy lost (kJ)")
        .labels(4, rows.len())
        .x_format(&panel::compact)
        .y_format(&|v| row_name(&names, v))
        .draw(&mut chart)?;
    for (k, (_, colour, v)) in rows.iter().enumerate() {
        let row = (rows.len() - 1 - k) as i32;
        let mut bar = Rectangle::new(
            [
                (0.0, SegmentValue::Exact(row)),
                (v.max(0.0), SegmentValue::Exact(row + 1)),
            ],
            colour.filled(),
        );
        bar.set_margin(10, 10, 0, 0);
        chart.draw_series(std::iter::once(bar))?;
        let share = if total_kj > 0.0 && k < 3 {
            format!(" ({:.0} %)", 100.0 * v / total_kj)
        } else {
            String::new()
        };
        chart.draw_series(std::iter::once(
            EmptyElement::at((v.max(0.0), SegmentValue::CenterOf(row)))
                + Text::new(
                    format!("{}{share}", style::fmt_sig(*v, 3)),
                    (6, 0),
                    style::text_at(style::NOTE_PX, HPos::Left, VPos::Center),
                ),
        ))?;
    }
    Ok(())
}
