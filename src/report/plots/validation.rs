//! Validation plots: parity (predicted vs reference, ±10/±20 % bands, log axes) per quantity and
//! relative error vs input speed. Range rows (trend and handbook checks) are left out of both.

use plotters::prelude::*;
use plotters::series::DashedLineSeries;

use super::panel::{Axes, Grid};
use super::style::{self, LegendEntry, Marker, Swatch};
use super::{Canvas, DrawResult};
use crate::reference::Row;

/// Model choices in first-seen order (colour index).
fn models(rows: &[&Row]) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for r in rows {
        if !v.contains(&r.model) {
            v.push(r.model.clone());
        }
    }
    v
}

/// Cases in first-seen order (marker index).
fn cases(rows: &[&Row]) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for r in rows {
        if !v.contains(&r.case) {
            v.push(r.case.clone());
        }
    }
    v
}

fn legend(models: &[String], cases: &[String]) -> Vec<LegendEntry> {
    let mut e: Vec<LegendEntry> = models
        .iter()
        .enumerate()
        .map(|(i, m)| LegendEntry::new(m.clone(), Swatch::Fill(style::series_colour(i))))
        .collect();
    e.extend(cases.iter().enumerate().map(|(i, c)| {
        LegendEntry::new(
            c.clone(),
            Swatch::MarkerLine(RGBColor(90, 90, 90), Marker::nth(i)),
        )
    }));
    e
}

/// Parity plot of the rows (already filtered to one quantity).
pub fn draw_parity(root: &Canvas, rows: &[&Row], title: &str) -> DrawResult {
    let root = style::titled(root, title)?;
    let (w, _) = root.dim_in_pixel();
    let (plot, side) = root.split_horizontally(w - 420);
    let rows: Vec<&Row> = rows.iter().copied().filter(|r| !r.kind.is_range()).collect();
    if rows.is_empty() {
        style::draw_note_centre(
            &plot,
            "no reference values in watts (range checks only: see validation.csv)",
        )?;
        return Ok(());
    }
    let vals = rows
        .iter()
        .flat_map(|r| [r.predicted, r.reference])
        .filter(|v| *v > 0.0);
    let lo = vals.clone().fold(f64::INFINITY, f64::min) / 1.5;
    let hi = vals.fold(0.0, f64::max) * 1.5;
    let mut ch = ChartBuilder::on(&plot)
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(100)
        .build_cartesian_2d((lo..hi).log_scale(), (lo..hi).log_scale())?;
    let watts = |v: &f64| format!("{v:.0}");
    Axes::with_fonts(style::text(22), style::text(24))
        .grid(Grid::Lines {
            light: Some(WHITE),
            bold: None,
        })
        .labels(8, 8)
        .x_format(&watts)
        .y_format(&watts)
        .x_desc("reference, W")
        .y_desc("geartherm, W")
        .draw(&mut ch)?;
    let line = |f: f64| vec![(lo, lo * f), (hi, hi * f)];
    ch.draw_series(LineSeries::new(line(1.0), BLACK.stroke_width(2)))?;
    for (f, c) in [(1.1, RGBColor(120, 120, 120)), (0.9, RGBColor(120, 120, 120))] {
        ch.draw_series(LineSeries::new(line(f), c.stroke_width(1)))?;
    }
    for f in [1.2, 0.8] {
        ch.draw_series(DashedLineSeries::new(
            line(f),
            8,
            6,
            RGBColor(160, 160, 160).stroke_width(1),
        ))?;
    }
    let (ms, cs) = (models(&rows), cases(&rows));
    for r in &rows {
        let i = ms.iter().position(|m| *m == r.model).unwrap_or(0);
        let k = cs.iter().position(|c| *c == r.case).unwrap_or(0);
        let (x, y) = ch.backend_coord(&(r.reference, r.predicted));
        let (bx, by) = plot.get_base_pixel();
        style::draw_marker_px(
            &plot,
            (x - bx, y - by),
            Marker::nth(k),
            7,
            style::series_colour(i).filled(),
        )?;
    }
    let mut entries = legend(&ms, &cs);
    entries.push(LegendEntry::new(
        "±10 %",
        Swatch::Line(RGBColor(120, 120, 120), 1),
    ));
    entries.push(LegendEntry::new(
        "±20 %",
        Swatch::Dashed(RGBColor(160, 160, 160), 1),
    ));
    style::draw_legend_column(&side, Some("model / case"), &entries, 40)?;
    Ok(())
}

/// Relative error (%) vs input speed.
pub fn draw_error_vs_speed(root: &Canvas, rows: &[&Row], title: &str) -> DrawResult {
    error_vs_speed(root, rows, title, false)
}

/// Distance (%) to the range of each range check (0 inside; trend and handbook rows) vs input
/// speed.
pub fn draw_range_distance(root: &Canvas, rows: &[&Row], title: &str) -> DrawResult {
    error_vs_speed(root, rows, title, true)
}

fn error_vs_speed(root: &Canvas, rows: &[&Row], title: &str, ranges: bool) -> DrawResult {
    let root = style::titled(root, title)?;
    let (w, _) = root.dim_in_pixel();
    let (plot, side) = root.split_horizontally(w - 420);
    let rows: Vec<&Row> = rows
        .iter()
        .copied()
        .filter(|r| r.kind.is_range() == ranges)
        .collect();
    if rows.is_empty() {
        style::draw_note_centre(
            &plot,
            if ranges {
                "no range checks"
            } else {
                "no reference values in watts (range checks only: see validation.csv)"
            },
        )?;
        return Ok(());
    }
    let y_desc = if ranges {
        "distance to the range, % (0 inside)"
    } else {
        "(geartherm − reference)/reference, %"
    };
    let (x0, x1) = style::padded_range(rows.iter().map(|r| r.speed_rpm), 0.05);
    let (y0, y1) = style::padded_range(
        rows.iter().map(|r| 100.0 * r.relative_error).chain([-25.0, 25.0]),
        0.05,
    );
    let mut ch = ChartBuilder::on(&plot)
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(100)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    Axes::with_fonts(style::text(22), style::text(24))
        .x_desc("input speed, rpm")
        .y_desc(y_desc)
        .draw(&mut ch)?;
    ch.draw_series(LineSeries::new(vec![(x0, 0.0), (x1, 0.0)], BLACK.stroke_width(2)))?;
    for v in [10.0, -10.0] {
        ch.draw_series(LineSeries::new(
            vec![(x0, v), (x1, v)],
            RGBColor(120, 120, 120).stroke_width(1),
        ))?;
    }
    for v in [20.0, -20.0] {
        ch.draw_series(DashedLineSeries::new(
            vec![(x0, v), (x1, v)],
            8,
            6,
            RGBColor(160, 160, 160).stroke_width(1),
        ))?;
    }
    let (ms, cs) = (models(&rows), cases(&rows));
    for r in &rows {
        let i = ms.iter().position(|m| *m == r.model).unwrap_or(0);
        let k = cs.iter().position(|c| *c == r.case).unwrap_or(0);
        let (x, y) = ch.backend_coord(&(r.speed_rpm, 100.0 * r.relative_error));
        let (bx, by) = plot.get_base_pixel();
        style::draw_marker_px(
            &plot,
            (x - bx, y - by),
            Marker::nth(k),
            7,
            style::series_colour(i).filled(),
        )?;
    }
    style::draw_legend_column(&side, Some("model / case"), &legend(&ms, &cs), 40)?;
    Ok(())
}
