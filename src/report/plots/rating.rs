//! `rating.png`: the thermal rating curve of a gear state — rated input torque (top panel) and
//! rated input power (bottom panel) against input speed, at an oil temperature limit. Points
//! where the limit is not reached below the torque ceiling are drawn as triangles at the top
//! edge of the panel (at the ceiling when every point is one), points where the speed alone
//! exceeds the limit as crosses at the lowest torque.

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::panel::{self, Axes};
use super::style::{self, LegendEntry, Marker, Swatch};
use super::{Canvas, DrawResult, PlotError};

/// One rated point of the curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Rated input torque, N·m.
    pub torque_nm: f64,
    /// Rated input power, kW.
    pub power_kw: f64,
    /// The limit is not reached below the torque ceiling (the torque is the ceiling).
    pub ceiling: bool,
    /// The limit is exceeded already at the lowest torque.
    pub at_minimum: bool,
}

/// A thermal rating curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Model name.
    pub model: String,
    /// Gear-state name.
    pub gear: String,
    /// Oil temperature limit, °C.
    pub oil_limit_c: f64,
    /// The ambient, in words (`ambient 35 °C`).
    pub ambient: String,
    /// Points in the order given.
    pub points: Vec<CurvePoint>,
}

const LINE: RGBColor = RGBColor(31, 119, 180);
const FLAGGED: RGBColor = RGBColor(214, 39, 40);

/// Render `rating.png` into `dir` (all or nothing, like the other figures).
pub fn render(dir: &Path, curve: &Curve) -> Result<PathBuf, PlotError> {
    super::style::ensure_fonts()?;
    let staged = super::stage_png(dir, "rating.png", |root| draw(root, curve))?;
    let mut paths = super::commit(vec![staged])?;
    paths.pop().ok_or_else(|| PlotError::Data {
        path: dir.to_path_buf(),
        what: "nothing written".into(),
    })
}

/// Draw the rating curve: torque and power over speed, the legend below.
pub fn draw(root: &Canvas, c: &Curve) -> DrawResult {
    let title = format!(
        "Thermal rating — {} gear {}: oil ≤ {} °C ({})",
        c.model,
        c.gear,
        style::fmt_num(c.oil_limit_c),
        c.ambient
    );
    let root = style::titled(root, &title)?;
    let (_, h) = root.dim_in_pixel();
    let (main, legend) = root.split_vertically(h - 70);
    let (_, mh) = main.dim_in_pixel();
    let (top, bottom) = main.split_vertically(mh / 2);
    let mut pts = c.points.clone();
    pts.sort_by(|a, b| a.speed_rpm.total_cmp(&b.speed_rpm));
    let (x0, x1) = style::padded_range(pts.iter().map(|p| p.speed_rpm), 0.03);
    panel_of(&top, &pts, (x0, x1), "rated input torque, N·m", false, |p| {
        p.torque_nm
    })?;
    panel_of(&bottom, &pts, (x0, x1), "rated input power, kW", true, |p| {
        p.power_kw
    })?;
    let mut entries = vec![LegendEntry::new(
        "rated (equilibrium oil at the limit)",
        Swatch::MarkerLine(LINE, Marker::Circle),
    )];
    if pts.iter().any(|p| p.ceiling) {
        entries.push(LegendEntry::new(
            "limit not reached below the torque ceiling (drawn at the top edge)",
            Swatch::MarkerLine(FLAGGED, Marker::Triangle),
        ));
    }
    if pts.iter().any(|p| p.at_minimum) {
        entries.push(LegendEntry::new(
            "limit exceeded at the lowest torque",
            Swatch::MarkerLine(FLAGGED, Marker::Cross),
        ));
    }
    style::draw_legend_row(&legend, &entries)?;
    Ok(())
}

/// One panel: `value` of each point against speed, the line through the rated points.
fn panel_of(
    area: &Canvas,
    pts: &[CurvePoint],
    (x0, x1): (f64, f64),
    y_desc: &str,
    x_axis: bool,
    value: impl Fn(&CurvePoint) -> f64,
) -> DrawResult {
    // Rated torques and powers are ≥ 0: the axis starts at 0. A point at the ceiling does not
    // set the range (it would flatten the curve): it is drawn at the top edge, unless every
    // point is one.
    let all_ceiling = pts.iter().all(|p| p.ceiling);
    let shown = pts.iter().filter(|p| all_ceiling || !p.ceiling).map(&value);
    let (y0, y1) = style::padded_range(shown.chain([0.0]), 0.06);
    let mut ch = ChartBuilder::on(area)
        .margin_left(20)
        .margin_right(40)
        .margin_top(10)
        .x_label_area_size(if x_axis { 70 } else { 30 })
        .y_label_area_size(120)
        .build_cartesian_2d(x0..x1, y0.max(0.0)..y1)?;
    let mut axes = Axes::house()
        .labels(10, 6)
        .y_desc(y_desc)
        .y_format(&panel::compact);
    axes = if x_axis {
        axes.x_desc("input speed, rpm").x_format(&panel::compact)
    } else {
        axes.x_format(&panel::blank)
    };
    axes.draw(&mut ch)?;
    let line: Vec<(f64, f64)> = pts
        .iter()
        .filter(|p| !p.ceiling)
        .map(|p| (p.speed_rpm, value(p)))
        .collect();
    ch.draw_series(LineSeries::new(line, LINE.stroke_width(3)))?;
    let (bx, by) = area.get_base_pixel();
    for p in pts {
        let (x, y) = ch.backend_coord(&(p.speed_rpm, value(p).min(y1)));
        let (m, colour) = match (p.ceiling, p.at_minimum) {
            (true, _) => (Marker::Triangle, FLAGGED),
            (_, true) => (Marker::Cross, FLAGGED),
            _ => (Marker::Circle, LINE),
        };
        style::draw_marker_px(area, (x - bx, y - by), m, 7, colour.filled())?;
    }
    if pts.is_empty() {
        area.draw(&Text::new(
            "no points",
            (100, 40),
            style::text_at(style::NOTE_PX, HPos::Left, VPos::Center),
        ))?;
    }
    Ok(())
}
