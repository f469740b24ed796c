//! `calibration.png` from a calibration directory's `fit.csv`: above, the measured temperatures
//! (dots) and the calibrated model's (lines) against time; below, the residuals (simulated −
//! measured). Held-out rows are shaded grey in both panels.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::style::{self, LegendEntry, Swatch};
use super::{commit, stage_png, Canvas, DrawResult, PlotError};

const LEGEND_W: u32 = 320;
const Y_LABEL_W: u32 = 110;

/// One channel of `fit.csv`: (node, measured, simulated, residual).
type Channel = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// The columns of `fit.csv`.
struct Fit {
    time_s: Vec<f64>,
    holdout: Vec<bool>,
    channels: Vec<Channel>,
}

fn read_fit(dir: &Path) -> Result<Fit, PlotError> {
    let path = dir.join("fit.csv");
    let text = std::fs::read_to_string(&path).map_err(|source| PlotError::Io {
        path: path.clone(),
        source,
    })?;
    let csv_err = |msg: String| PlotError::Csv {
        path: path.clone(),
        msg,
    };
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    if head.len() < 5 || head[0] != "time_s" || head[1] != "holdout" || (head.len() - 2) % 4 != 0 {
        return Err(PlotError::Data {
            path: path.clone(),
            what: "not a fit.csv: expected time_s,holdout and four columns per channel".into(),
        });
    }
    let nc = (head.len() - 2) / 4;
    let mut fit = Fit {
        time_s: Vec::new(),
        holdout: Vec::new(),
        channels: (0..nc)
            .map(|c| {
                let name = head[2 + 4 * c].trim_end_matches("_measured_c").to_string();
                (name, Vec::new(), Vec::new(), Vec::new())
            })
            .collect(),
    };
    for (k, l) in lines.enumerate() {
        let f: Vec<&str> = l.split(',').collect();
        if f.len() != head.len() {
            return Err(csv_err(format!(
                "line {}: {} fields, the header has {}",
                k + 2,
                f.len(),
                head.len()
            )));
        }
        let num = |i: usize| -> Result<f64, PlotError> {
            f[i].parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                csv_err(format!(
                    "line {}, column {}: \"{}\" is not a finite number",
                    k + 2,
                    head[i],
                    f[i]
                ))
            })
        };
        fit.time_s.push(num(0)?);
        fit.holdout.push(f[1] == "1");
        for c in 0..nc {
            fit.channels[c].1.push(num(2 + 4 * c)?);
            fit.channels[c].2.push(num(3 + 4 * c)?);
            fit.channels[c].3.push(num(4 + 4 * c)?);
        }
    }
    if fit.time_s.is_empty() {
        return Err(PlotError::Data {
            path,
            what: "no data rows".into(),
        });
    }
    Ok(fit)
}

/// Time spans of the held-out rows (scaled), for shading.
fn holdout_spans(fit: &Fit, scale: f64) -> Vec<(f64, f64)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (k, &h) in fit.holdout.iter().enumerate() {
        match (h, start) {
            (true, None) => start = Some(k),
            (false, Some(s)) => {
                spans.push((fit.time_s[s] * scale, fit.time_s[k - 1] * scale));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        spans.push((fit.time_s[s] * scale, fit.time_s[fit.time_s.len() - 1] * scale));
    }
    spans
}

fn draw(root: &Canvas, fit: &Fit) -> DrawResult {
    let root = style::titled(root, "Calibration — measured (dots) and calibrated model (lines)")?;
    let (w, h) = root.dim_in_pixel();
    let (main, legend) = root.split_horizontally(w - LEGEND_W);
    let split_y = (h as f64 * 0.62) as u32;
    let (upper, lower) = main.split_vertically(split_y);
    let t_hi = fit.time_s.iter().cloned().fold(f64::MIN, f64::max);
    let t_lo = fit.time_s.iter().cloned().fold(f64::MAX, f64::min);
    let (scale, desc) = style::time_axis(t_hi);
    let (x0, x1) = style::pad_range(t_lo * scale, t_hi * scale, 0.0);
    let spans = holdout_spans(fit, scale);
    let shade = RGBColor(232, 232, 232).filled();
    let t: Vec<f64> = fit.time_s.iter().map(|x| x * scale).collect();

    let (y0, y1) = style::padded_range(
        fit.channels
            .iter()
            .flat_map(|c| c.1.iter().chain(c.2.iter()).copied()),
        0.06,
    );
    let mut chart = ChartBuilder::on(&upper)
        .margin_left(20)
        .margin_right(20)
        .margin_top(10)
        .x_label_area_size(12)
        .y_label_area_size(Y_LABEL_W)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .y_desc("Temperature (°C)")
        .axis_desc_style(style::font(style::AXIS_DESC_PX))
        .label_style(style::font(style::TICK_PX))
        .light_line_style(style::GRID)
        .bold_line_style(style::GRID_BOLD)
        .x_label_formatter(&|_| String::new())
        .y_label_formatter(&|v| style::fmt_num(*v))
        .draw()?;
    chart.draw_series(
        spans
            .iter()
            .map(|&(a, b)| Rectangle::new([(a, y0), (b, y1)], shade)),
    )?;
    let mut entries = Vec::new();
    for (k, (name, meas, sim, _)) in fit.channels.iter().enumerate() {
        let colour = style::series_colour(k);
        chart.draw_series(
            t.iter()
                .zip(meas)
                .map(|(&x, &y)| Circle::new((x, y), 3, colour.mix(0.55).filled())),
        )?;
        chart.draw_series(LineSeries::new(
            t.iter().copied().zip(sim.iter().copied()),
            colour.stroke_width(3),
        ))?;
        entries.push(LegendEntry::new(name.clone(), Swatch::Line(colour, 3)));
    }
    if !spans.is_empty() {
        entries.push(LegendEntry::new(
            "held out (grey)",
            Swatch::Line(RGBColor(200, 200, 200), 12),
        ));
    }
    style::draw_legend_column(&legend, Some("Measured channels"), &entries, 14)?;

    let (r0, r1) = style::padded_range(
        fit.channels.iter().flat_map(|c| c.3.iter().copied()).chain([0.0]),
        0.08,
    );
    let mut low = ChartBuilder::on(&lower)
        .margin_left(20)
        .margin_right(20)
        .margin_top(14)
        .margin_bottom(10)
        .x_label_area_size(80)
        .y_label_area_size(Y_LABEL_W)
        .build_cartesian_2d(x0..x1, r0..r1)?;
    low.configure_mesh()
        .x_desc(desc)
        .y_desc("Simulated − measured (K)")
        .axis_desc_style(style::font(style::AXIS_DESC_PX))
        .label_style(style::font(style::TICK_PX))
        .light_line_style(style::GRID)
        .bold_line_style(style::GRID_BOLD)
        .x_label_formatter(&|v| style::fmt_num(*v))
        .y_label_formatter(&|v| style::fmt_num(*v))
        .draw()?;
    low.draw_series(
        spans
            .iter()
            .map(|&(a, b)| Rectangle::new([(a, r0), (b, r1)], shade)),
    )?;
    low.draw_series(LineSeries::new(
        [(x0, 0.0), (x1, 0.0)],
        style::NEUTRAL.stroke_width(2),
    ))?;
    for (k, (_, _, _, res)) in fit.channels.iter().enumerate() {
        let colour = style::series_colour(k);
        low.draw_series(LineSeries::new(
            t.iter().copied().zip(res.iter().copied()),
            colour.stroke_width(2),
        ))?;
    }
    Ok(())
}

/// Render `calibration.png` from `dir/fit.csv` into `dir`.
pub fn render_calibration(dir: &Path) -> Result<PathBuf, PlotError> {
    style::ensure_fonts()?;
    let fit = read_fit(dir)?;
    let staged = stage_png(dir, "calibration.png", |root| draw(root, &fit))?;
    let mut paths = commit(vec![staged])?;
    paths.pop().ok_or_else(|| PlotError::Data {
        path: dir.to_path_buf(),
        what: "nothing written".into(),
    })
}
