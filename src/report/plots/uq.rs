//! Figures of an uncertainty run:
//! - `bands.png`: each series' median (the 50th percentile, or the middle one asked) over time
//!   as a line, with the band between the outer percentiles shaded (and, with five or more
//!   percentiles, the band between the second and second-to-last shaded darker);
//! - `sensitivity.png`: per output, the first-order and total Sobol' indices of every input as
//!   paired horizontal bars with their bootstrap intervals as whiskers.
//!
//! Both refuse a non-finite number before anything is drawn.

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::panel::{self, Axes, Grid, TimeAxis};
use super::style::{self, LegendEntry, Swatch};
use super::{commit, stage_png, Canvas, DrawResult, PlotError};
use crate::report::uq::{Bands, SobolRow, UqSummary};

const LEGEND_W: u32 = 330;
/// Colour of the first-order bars (Okabe–Ito blue) and of the total bars (orange).
const FIRST: RGBColor = RGBColor(0, 114, 178);
const TOTAL: RGBColor = RGBColor(230, 159, 0);

/// Index of the median percentile: 50 if asked, else the middle one.
fn median_index(ps: &[f64]) -> usize {
    ps.iter().position(|p| *p == 50.0).unwrap_or(ps.len() / 2)
}

/// `c` at opacity `a` over white, as an opaque colour (legend swatches of the shaded bands).
fn tint(c: RGBColor, a: f64) -> RGBColor {
    let m = |x: u8| (f64::from(x) * a + 255.0 * (1.0 - a)).round() as u8;
    RGBColor(m(c.0), m(c.1), m(c.2))
}

fn pct(p: f64) -> String {
    format!("{}", p)
}

/// A closed polygon between two curves over time (display units).
fn band_polygon(t: &[f64], lo: &[f64], hi: &[f64]) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = t.iter().zip(hi).map(|(&x, &y)| (x, y)).collect();
    pts.extend(t.iter().zip(lo).rev().map(|(&x, &y)| (x, y)));
    pts
}

/// Draw `bands.png`: every series' median and shaded percentile bands over time.
pub fn draw_bands(root: &Canvas, b: &Bands, title: &str) -> DrawResult {
    let root = style::titled(root, title)?;
    let (w, _) = root.dim_in_pixel();
    let (main, legend) = root.split_horizontally(w - LEGEND_W);
    let order: Vec<usize> = (0..b.time_s.len()).collect();
    let time = TimeAxis::over(&b.time_s, &order);
    let t: Vec<f64> = b.time_s.iter().map(|x| x * time.scale).collect();
    let (y0, y1) = style::padded_range(
        b.series.iter().flat_map(|s| s.values.iter().flatten().copied()),
        0.06,
    );
    let unit = b.series.first().map_or("°C", |s| s.unit.as_str());
    let y_desc = match unit {
        "°C" => "Temperature (°C)".to_string(),
        u => format!("Value ({u})"),
    };
    let mut chart = ChartBuilder::on(&main)
        .margin_left(20)
        .margin_right(20)
        .margin_top(10)
        .margin_bottom(10)
        .x_label_area_size(80)
        .y_label_area_size(110)
        .build_cartesian_2d(time.x0..time.x1, y0..y1)?;
    Axes::house()
        .x_desc(time.desc)
        .y_desc(y_desc)
        .labels(12, 8)
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    let np = b.percentiles.len();
    let mid = median_index(&b.percentiles);
    let mut entries = Vec::new();
    for (k, s) in b.series.iter().enumerate() {
        let c = style::series_colour(k);
        if np >= 2 {
            let poly = band_polygon(&t, &s.values[0], &s.values[np - 1]);
            chart.draw_series(std::iter::once(Polygon::new(poly, c.mix(0.18).filled())))?;
        }
        if np >= 5 {
            let poly = band_polygon(&t, &s.values[1], &s.values[np - 2]);
            chart.draw_series(std::iter::once(Polygon::new(poly, c.mix(0.30).filled())))?;
        }
        let line: Vec<(f64, f64)> = t.iter().copied().zip(s.values[mid].iter().copied()).collect();
        chart.draw_series(LineSeries::new(line, c.stroke_width(3)))?;
        entries.push(LegendEntry::new(s.name.clone(), Swatch::Line(c, 3)));
    }
    if b.series.is_empty() {
        style::draw_note_centre(&main, "no band series")?;
    }
    let mut key = vec![LegendEntry::new(
        format!("line: p{}", pct(b.percentiles.get(mid).copied().unwrap_or(50.0))),
        Swatch::Line(style::NEUTRAL, 3),
    )];
    if np >= 2 {
        key.push(LegendEntry::new(
            format!("band: p{}–p{}", pct(b.percentiles[0]), pct(b.percentiles[np - 1])),
            Swatch::Fill(tint(style::NEUTRAL, 0.18)),
        ));
    }
    if np >= 5 {
        key.push(LegendEntry::new(
            format!("band: p{}–p{}", pct(b.percentiles[1]), pct(b.percentiles[np - 2])),
            Swatch::Fill(tint(style::NEUTRAL, 0.30)),
        ));
    }
    let (_, lh) = legend.dim_in_pixel();
    let (top, bottom) = legend.split_vertically(lh * 3 / 4);
    style::draw_legend_column(&top, Some("Nodes (median)"), &entries, 14)?;
    style::draw_legend_column(&bottom, Some("Percentiles"), &key, 4)?;
    Ok(())
}

/// Rows of one output, in input order.
fn outputs_of(rows: &[SobolRow]) -> Vec<String> {
    let mut outs: Vec<String> = Vec::new();
    for r in rows {
        if !outs.contains(&r.output) {
            outs.push(r.output.clone());
        }
    }
    outs
}

/// One output's panel: inputs top to bottom, first-order and total bars with whiskers.
fn sensitivity_panel(area: &Canvas, rows: &[&SobolRow], output: &str) -> DrawResult {
    let n = rows.len();
    let (w, _) = area.dim_in_pixel();
    let label_w = rows
        .iter()
        .filter_map(|r| {
            area.estimate_text_size(&r.input, &style::text(style::TICK_PX))
                .ok()
        })
        .map(|(tw, _)| tw + 30)
        .max()
        .unwrap_or(100)
        .min(w * 2 / 5);
    let x0 = rows
        .iter()
        .map(|r| r.first_lo.min(r.total_lo))
        .fold(0.0, f64::min);
    let x1 = rows
        .iter()
        .map(|r| r.first_hi.max(r.total_hi))
        .fold(0.1, f64::max);
    let (x0, x1) = style::pad_range(x0, x1, 0.05);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .margin_top(40)
        .x_label_area_size(60)
        .y_label_area_size(label_w)
        .build_cartesian_2d(x0..x1, -0.6..(n as f64 - 0.4))?;
    let name_of = |v: &f64| {
        let r = v.round();
        if (v - r).abs() < 1e-6 && r >= 0.0 && (r as usize) < n {
            let i = n - 1 - r as usize;
            style::fit_label(area, &rows[i].input, style::TICK_PX, label_w.saturating_sub(20))
        } else {
            String::new()
        }
    };
    Axes::house()
        .grid(Grid::Vertical)
        .x_desc("Sobol' index (share of the output variance)")
        .labels(10, 2 * n + 1)
        .x_format(&panel::compact)
        .y_format(&name_of)
        .draw(&mut chart)?;
    area.draw(&Text::new(
        output.to_string(),
        (w as i32 / 2, 18),
        style::text_at(style::AXIS_DESC_PX, HPos::Center, VPos::Center),
    ))?;
    for (i, r) in rows.iter().enumerate() {
        let y = (n - 1 - i) as f64;
        for (dy, v, lo, hi, c) in [
            (0.2, r.first, r.first_lo, r.first_hi, FIRST),
            (-0.2, r.total, r.total_lo, r.total_hi, TOTAL),
        ] {
            let yc = y + dy;
            chart.draw_series(std::iter::once(Rectangle::new(
                [(0.0, yc - 0.17), (v, yc + 0.17)],
                c.filled(),
            )))?;
            let s = style::TEXT.stroke_width(2);
            chart.draw_series(std::iter::once(PathElement::new(vec![(lo, yc), (hi, yc)], s)))?;
            for x in [lo, hi] {
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(x, yc - 0.1), (x, yc + 0.1)],
                    s,
                )))?;
            }
        }
    }
    Ok(())
}

/// Draw `sensitivity.png`: one panel per output (at most four, stacked), first-order and total
/// indices per input with their intervals.
pub fn draw_sensitivity(root: &Canvas, rows: &[SobolRow], title: &str) -> DrawResult {
    let root = style::titled(root, title)?;
    let (w, _) = root.dim_in_pixel();
    let (main, legend) = root.split_horizontally(w - LEGEND_W);
    let outs: Vec<String> = outputs_of(rows).into_iter().take(4).collect();
    if outs.is_empty() {
        style::draw_note_centre(&main, "no Sobol' indices")?;
    }
    let panels = main.split_evenly((outs.len().max(1), 1));
    for (area, out) in panels.iter().zip(&outs) {
        let mine: Vec<&SobolRow> = rows.iter().filter(|r| &r.output == out).collect();
        sensitivity_panel(area, &mine, out)?;
    }
    let entries = [
        LegendEntry::new("first order S_i", Swatch::Fill(FIRST)),
        LegendEntry::new("total S_Ti", Swatch::Fill(TOTAL)),
        LegendEntry::new("bootstrap interval", Swatch::Line(style::TEXT, 2)),
    ];
    style::draw_legend_column(&legend, Some("Indices"), &entries, 14)?;
    Ok(())
}

fn data_err(dir: &Path, what: String) -> PlotError {
    PlotError::Data {
        path: dir.to_path_buf(),
        what,
    }
}

/// Render `bands.png` (when `bands` has series) and `sensitivity.png` (when the summary has Sobol'
/// indices) into `dir`, all or nothing. Non-finite numbers are refused before drawing.
pub fn render_uq(dir: &Path, summary: &UqSummary, bands: Option<&Bands>) -> Result<Vec<PathBuf>, PlotError> {
    style::ensure_fonts()?;
    summary.check_finite().map_err(|e| data_err(dir, e))?;
    let mut staged = Vec::new();
    let what = format!("{} / {}", summary.model, summary.cycle_or_point);
    if let Some(b) = bands.filter(|b| !b.series.is_empty()) {
        b.check().map_err(|e| data_err(dir, e))?;
        let title = format!(
            "Temperature bands — {what} ({} samples, {} failed)",
            summary.samples, summary.failed_samples
        );
        staged.push(stage_png(dir, "bands.png", |r| draw_bands(r, b, &title))?);
    }
    if !summary.sobol.is_empty() {
        let title = format!("Sobol' indices — {what}");
        staged.push(stage_png(dir, "sensitivity.png", |r| {
            draw_sensitivity(r, &summary.sobol, &title)
        })?);
    }
    commit(staged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::uq::{BandSeries, SobolRow};

    fn summary(sobol: Vec<SobolRow>) -> UqSummary {
        UqSummary {
            model: "m".into(),
            cycle_or_point: "wltc".into(),
            samples: 10,
            method: "saltelli".into(),
            seed: 1,
            inputs: vec![],
            percentiles: vec![5.0, 50.0, 95.0],
            exceedance: vec![],
            sobol,
            energy: vec![],
            scalars: vec![],
            failed_samples: 0,
            notes: vec![],
        }
    }

    fn row(output: &str, input: &str, s: f64) -> SobolRow {
        SobolRow {
            output: output.into(),
            input: input.into(),
            first: s,
            first_lo: s - 0.05,
            first_hi: s + 0.05,
            total: s + 0.1,
            total_lo: s + 0.02,
            total_hi: s + 0.2,
        }
    }

    #[test]
    fn both_figures_render_and_nan_is_refused() {
        let d = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 18.0).collect();
        let curve = |off: f64| t.iter().map(|x| 20.0 + off + x / 30.0).collect::<Vec<_>>();
        let b = Bands {
            time_s: t.clone(),
            percentiles: vec![5.0, 25.0, 50.0, 75.0, 95.0],
            series: vec![BandSeries {
                name: "sump".into(),
                unit: "°C".into(),
                values: vec![curve(-4.0), curve(-2.0), curve(0.0), curve(2.0), curve(5.0)],
            }],
        };
        let s = summary(vec![
            row("temp_max_sump_c", "lubrication.oil_level_mm", 0.5),
            row("temp_max_sump_c", "thermal.links[0].h_w_m2k", 0.2),
            row("energy_total_j", "lubrication.oil_level_mm", 0.7),
        ]);
        let paths = render_uq(d.path(), &s, Some(&b)).unwrap();
        assert_eq!(paths.len(), 2);
        for p in &paths {
            let img = png::Decoder::new(std::fs::File::open(p).unwrap())
                .read_info()
                .unwrap();
            assert_eq!(
                (img.info().width, img.info().height),
                (style::WIDTH, style::HEIGHT)
            );
        }
        let mut bad = b.clone();
        bad.series[0].values[2][7] = f64::NAN;
        let d2 = tempfile::tempdir().unwrap();
        let e = render_uq(d2.path(), &s, Some(&bad)).unwrap_err().to_string();
        assert!(e.contains("NaN"), "{e}");
        assert_eq!(std::fs::read_dir(d2.path()).unwrap().count(), 0);
    }
}
