//! Heat maps of a (speed × torque) map: `map_efficiency.png`, `map_total_loss.png`,
//! `map_oil_temp.png`. Each grid point is a cell reaching half-way to its neighbours (so
//! non-uniform grids are drawn correctly); non-converged points are hatched grey, points without
//! a value are left blank. Contour lines at "nice" levels are labelled; on small grids the value
//! of every cell is printed as well.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::data::{MapGrid, MapRow};
use super::panel::{self, Axes, Chart, Grid};
use super::style::{self, ColourMap, LegendEntry, Swatch};
use super::{Canvas, DrawResult};

/// The quantity a map heatmap shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Efficiency at the equilibrium (fraction).
    Efficiency,
    /// Total loss at the equilibrium, W.
    TotalLoss,
    /// Oil temperature at the equilibrium, °C.
    OilTemp,
}

impl Quantity {
    /// Every quantity, in the order the map report draws them.
    pub const ALL: [Quantity; 3] = [Quantity::Efficiency, Quantity::TotalLoss, Quantity::OilTemp];

    /// File name of the quantity's figure.
    pub fn file_name(self) -> &'static str {
        match self {
            Quantity::Efficiency => "map_efficiency.png",
            Quantity::TotalLoss => "map_total_loss.png",
            Quantity::OilTemp => "map_oil_temp.png",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Quantity::Efficiency => "Efficiency (%)",
            Quantity::TotalLoss => "Total loss power (W)",
            Quantity::OilTemp => "Steady oil temperature (°C)",
        }
    }

    fn title(self) -> &'static str {
        match self {
            Quantity::Efficiency => "Efficiency map",
            Quantity::TotalLoss => "Total loss map",
            Quantity::OilTemp => "Oil temperature map",
        }
    }

    fn colour_map(self) -> ColourMap {
        match self {
            Quantity::Efficiency => ColourMap::Viridis,
            Quantity::TotalLoss => ColourMap::Inferno,
            Quantity::OilTemp => ColourMap::Plasma,
        }
    }

    /// Value in display units; NaN where missing.
    fn value(self, r: &MapRow) -> f64 {
        let v = match self {
            Quantity::Efficiency => r.efficiency.map(|e| 100.0 * e),
            Quantity::TotalLoss => r.loss_total_w,
            Quantity::OilTemp => r.oil_temp_c,
        };
        v.filter(|x| x.is_finite()).unwrap_or(f64::NAN)
    }
}

/// Cell edges: half-way between neighbouring grid values, mirrored at the ends.
pub fn cell_edges(axis: &[f64]) -> Vec<f64> {
    match axis.len() {
        0 => vec![0.0, 1.0],
        1 => {
            let (lo, hi) = style::pad_range(axis[0], axis[0], 0.0);
            vec![lo, hi]
        }
        n => {
            let mut e = Vec::with_capacity(n + 1);
            e.push(axis[0] - 0.5 * (axis[1] - axis[0]));
            for k in 0..n - 1 {
                e.push(0.5 * (axis[k] + axis[k + 1]));
            }
            e.push(axis[n - 1] + 0.5 * (axis[n - 1] - axis[n - 2]));
            e
        }
    }
}

/// Marching squares on the grid of point values `z[j*nx + i]` at `(xs[i], ys[j])` for `level`.
/// Squares with a missing (NaN) corner are skipped. Returns line segments in data coordinates.
pub fn contour_segments(xs: &[f64], ys: &[f64], z: &[f64], level: f64) -> Vec<[(f64, f64); 2]> {
    let nx = xs.len();
    let mut out = Vec::new();
    if nx < 2 || ys.len() < 2 {
        return out;
    }
    let interp = |(xa, ya, za): (f64, f64, f64), (xb, yb, zb): (f64, f64, f64)| {
        let t = if zb != za {
            ((level - za) / (zb - za)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        (xa + t * (xb - xa), ya + t * (yb - ya))
    };
    for j in 0..ys.len() - 1 {
        for i in 0..nx - 1 {
            // Corners counter-clockwise: bottom-left, bottom-right, top-right, top-left.
            let c = [
                (xs[i], ys[j], z[j * nx + i]),
                (xs[i + 1], ys[j], z[j * nx + i + 1]),
                (xs[i + 1], ys[j + 1], z[(j + 1) * nx + i + 1]),
                (xs[i], ys[j + 1], z[(j + 1) * nx + i]),
            ];
            if c.iter().any(|p| !p.2.is_finite()) {
                continue;
            }
            let above: Vec<bool> = c.iter().map(|p| p.2 >= level).collect();
            // Crossing points on the four edges, in edge order.
            let mut pts = Vec::with_capacity(4);
            for e in 0..4 {
                let (a, b) = (e, (e + 1) % 4);
                if above[a] != above[b] {
                    pts.push(interp(c[a], c[b]));
                }
            }
            match pts.len() {
                2 => out.push([pts[0], pts[1]]),
                4 => {
                    // Saddle: decide by the centre value.
                    let centre = c.iter().map(|p| p.2).sum::<f64>() / 4.0;
                    if (centre >= level) == above[0] {
                        out.push([pts[0], pts[3]]);
                        out.push([pts[1], pts[2]]);
                    } else {
                        out.push([pts[0], pts[1]]);
                        out.push([pts[2], pts[3]]);
                    }
                }
                _ => {}
            }
        }
    }
    out
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[k.min(sorted.len() - 1)]
}

/// The values of one quantity over a map grid and its colour scale.
struct Field {
    nx: usize,
    ny: usize,
    /// Value of cell (i, j) at `j * nx + i`; NaN where missing or not converged.
    z: Vec<f64>,
    /// Cells whose equilibrium did not converge.
    not_converged: Vec<bool>,
    /// True when any cell has a value.
    any_value: bool,
    /// Colour scale range.
    vmin: f64,
    /// Colour scale range.
    vmax: f64,
    /// The scale is clipped at the 5th percentile.
    clipped: bool,
    cmap: ColourMap,
}

impl Field {
    fn of(grid: &MapGrid, q: Quantity) -> Field {
        let (nx, ny) = (grid.speeds_rpm.len(), grid.torques_nm.len());
        let mut z = vec![f64::NAN; nx * ny];
        let mut not_converged = vec![false; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                match grid.cell(i, j) {
                    Some(r) if r.converged => z[j * nx + i] = q.value(r),
                    Some(_) => not_converged[j * nx + i] = true,
                    None => {}
                }
            }
        }
        let mut finite: Vec<f64> = z.iter().copied().filter(|v| v.is_finite()).collect();
        finite.sort_by(f64::total_cmp);
        let (mut vmin, vmax) = match (finite.first(), finite.last()) {
            (Some(&a), Some(&b)) => (a, b),
            _ => (0.0, 1.0),
        };
        // Efficiency near zero torque is far below the rest; clip the colour scale at the 5th
        // percentile so the useful range keeps its contrast (said on the colour bar).
        let mut clipped = false;
        if q == Quantity::Efficiency && finite.len() >= 20 {
            let p5 = percentile(&finite, 0.05);
            if p5 - vmin > 0.5 * (vmax - p5) {
                vmin = p5;
                clipped = true;
            }
        }
        let (vmin, vmax) = if vmax > vmin {
            (vmin, vmax)
        } else {
            style::pad_range(vmin, vmax, 0.0)
        };
        Field {
            nx,
            ny,
            z,
            not_converged,
            any_value: !finite.is_empty(),
            vmin,
            vmax,
            clipped,
            cmap: q.colour_map(),
        }
    }

    /// Colour of value `v`.
    fn colour(&self, v: f64) -> RGBColor {
        self.cmap.at((v - self.vmin) / (self.vmax - self.vmin))
    }

    /// Contour levels: "nice" steps strictly inside the scale, at most 30.
    fn levels(&self) -> Vec<f64> {
        let step = style::nice_step(self.vmax - self.vmin, 8);
        let mut levels = Vec::new();
        let mut lv = (self.vmin / step).ceil() * step;
        while lv < self.vmax && levels.len() < 30 {
            if lv > self.vmin {
                levels.push(lv);
            }
            lv += step;
        }
        levels
    }
}

/// Draw the heatmap of `q` over the map's speed × torque grid.
pub fn draw(root: &Canvas, grid: &MapGrid, q: Quantity) -> DrawResult {
    let model = super::data::name_or(&grid.meta.model, "model");
    let gear = super::data::name_or(&grid.meta.gear, "–");
    let title = format!("{} — {model}, gear {gear}", q.title());
    let root = style::titled(root, &title)?;
    let (w, _) = root.dim_in_pixel();
    let (main, bar_area) = root.split_horizontally(w - 290);
    let field = Field::of(grid, q);
    let (nx, ny) = (field.nx, field.ny);
    let xe = cell_edges(&grid.speeds_rpm);
    let ye = cell_edges(&grid.torques_nm);
    let mut chart = ChartBuilder::on(&main)
        .margin_left(20)
        .margin_right(20)
        .margin_top(10)
        .margin_bottom(10)
        .x_label_area_size(80)
        .y_label_area_size(120)
        .build_cartesian_2d(xe[0]..xe[nx], ye[0]..ye[ny])?;
    Axes::house()
        .grid(Grid::Off)
        .x_desc("Input speed (rpm)")
        .y_desc("Input torque (N·m)")
        .labels(10, 10)
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    draw_cells(&mut chart, &field, &xe, &ye)?;
    let levels = field.levels();
    let small_grid = nx <= 12 && ny <= 12;
    draw_contours(&mut chart, grid, &field, &levels, !small_grid)?;
    if small_grid {
        draw_cell_values(&mut chart, grid, &field)?;
    }
    if !field.any_value {
        style::draw_note_centre(&main, "no converged points with a value")?;
    }
    draw_colour_bar(&bar_area, &field, q, &levels)
}

/// The cells in their colours, non-converged ones grey and hatched.
fn draw_cells(chart: &mut Chart, field: &Field, xe: &[f64], ye: &[f64]) -> DrawResult {
    let (nx, ny) = (field.nx, field.ny);
    chart.draw_series(
        (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .filter_map(|(i, j)| {
                let v = field.z[j * nx + i];
                let colour = if v.is_finite() {
                    field.colour(v)
                } else if field.not_converged[j * nx + i] {
                    style::MISSING
                } else {
                    return None;
                };
                Some(Rectangle::new(
                    [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])],
                    colour.filled(),
                ))
            }),
    )?;
    // Hatching of non-converged cells, in pixels.
    let plot = chart.plotting_area();
    let (ox, oy) = plot.get_base_pixel();
    for j in 0..ny {
        for i in (0..nx).filter(|&i| field.not_converged[j * nx + i]) {
            let a = chart.backend_coord(&(xe[i], ye[j + 1]));
            let b = chart.backend_coord(&(xe[i + 1], ye[j]));
            style::hatch_px(
                &plot.strip_coord_spec(),
                (a.0 - ox, a.1 - oy),
                (b.0 - ox, b.1 - oy),
            )?;
        }
    }
    Ok(())
}

/// Contours at `levels`, drawn white under black so they read on any colour; `labelled`: each
/// with its value at the segment nearest the middle of its list (typically mid-line), avoiding
/// earlier labels.
fn draw_contours(
    chart: &mut Chart,
    grid: &MapGrid,
    field: &Field,
    levels: &[f64],
    labelled: bool,
) -> DrawResult {
    let mut label_boxes: Vec<(i32, i32, i32, i32)> = Vec::new();
    for &level in levels {
        let segs = contour_segments(&grid.speeds_rpm, &grid.torques_nm, &field.z, level);
        if segs.is_empty() {
            continue;
        }
        chart.draw_series(
            segs.iter()
                .map(|s| PathElement::new(s.to_vec(), WHITE.stroke_width(5))),
        )?;
        chart.draw_series(
            segs.iter()
                .map(|s| PathElement::new(s.to_vec(), BLACK.stroke_width(2))),
        )?;
        if labelled {
            draw_contour_label(chart, &segs, level, &mut label_boxes)?;
        }
    }
    Ok(())
}

/// The label of a contour at `level` on the first of its segments `segs`, from the middle of the
/// list outwards, whose label box overlaps none of `boxes` (which it joins).
fn draw_contour_label(
    chart: &mut Chart,
    segs: &[[(f64, f64); 2]],
    level: f64,
    boxes: &mut Vec<(i32, i32, i32, i32)>,
) -> DrawResult {
    let label = style::fmt_num(level);
    let (tw, th) = (label.chars().count() as i32 * 12 + 12, 28);
    let mid = segs.len() / 2;
    let candidates = (0..segs.len()).map(|k| {
        if k % 2 == 0 {
            mid + k / 2
        } else {
            mid.wrapping_sub(k / 2 + 1)
        }
    });
    for k in candidates.filter(|&k| k < segs.len()) {
        let s = segs[k];
        let p = ((s[0].0 + s[1].0) / 2.0, (s[0].1 + s[1].1) / 2.0);
        let (px, py) = chart.backend_coord(&p);
        let b = (px - tw / 2, py - th / 2, px + tw / 2, py + th / 2);
        if boxes
            .iter()
            .any(|o| b.0 < o.2 && o.0 < b.2 && b.1 < o.3 && o.1 < b.3)
        {
            continue;
        }
        boxes.push(b);
        chart.draw_series(std::iter::once(
            EmptyElement::at(p)
                + Rectangle::new([(-tw / 2, -th / 2), (tw / 2, th / 2)], WHITE.mix(0.85).filled())
                + Text::new(
                    label.clone(),
                    (0, 0),
                    style::text_at(style::NOTE_PX, HPos::Center, VPos::Center),
                ),
        ))?;
        break;
    }
    Ok(())
}

/// Every cell's value, in black or white against the cell colour (small grids).
fn draw_cell_values(chart: &mut Chart, grid: &MapGrid, field: &Field) -> DrawResult {
    for j in 0..field.ny {
        for i in 0..field.nx {
            let v = field.z[j * field.nx + i];
            if !v.is_finite() {
                continue;
            }
            let RGBColor(r, g, b) = field.colour(v);
            let luminance = 0.299 * r as f64 + 0.587 * g as f64 + 0.114 * b as f64;
            let colour = if luminance > 140.0 { BLACK } else { WHITE };
            let text = style::text_at(style::NOTE_PX, HPos::Center, VPos::Center).color(&colour);
            chart.draw_series(std::iter::once(Text::new(
                style::fmt_sig(v, 3),
                (grid.speeds_rpm[i], grid.torques_nm[j]),
                text,
            )))?;
        }
    }
    Ok(())
}

/// The colour bar with its own axis and the contour levels, and the legend below it.
fn draw_colour_bar(area: &Canvas, field: &Field, q: Quantity, levels: &[f64]) -> DrawResult {
    let (vmin, vmax) = (field.vmin, field.vmax);
    let (_, bh) = area.dim_in_pixel();
    let (bar_main, bar_legend) = area.split_vertically(bh - 150);
    let mut bar = ChartBuilder::on(&bar_main)
        .margin_top(40)
        .margin_bottom(10)
        .margin_left(20)
        .margin_right(10)
        .x_label_area_size(0)
        .right_y_label_area_size(170)
        .build_cartesian_2d(0.0..1.0, vmin..vmax)?;
    let desc = if field.clipped {
        format!("{} (clipped below)", q.label())
    } else {
        q.label().to_string()
    };
    Axes::house()
        .grid(Grid::Off)
        .without_x_axis()
        .y_desc(desc)
        .y_labels(10)
        .y_format(&panel::compact)
        .draw(&mut bar)?;
    let n_steps = 256;
    bar.draw_series((0..n_steps).map(|k| {
        let a = vmin + (vmax - vmin) * k as f64 / n_steps as f64;
        let b = vmin + (vmax - vmin) * (k + 1) as f64 / n_steps as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            field.cmap.at((k as f64 + 0.5) / n_steps as f64).filled(),
        )
    }))?;
    bar.draw_series(
        levels
            .iter()
            .map(|&l| PathElement::new(vec![(0.0, l), (1.0, l)], BLACK.stroke_width(2))),
    )?;
    let mut entries = Vec::new();
    if field.not_converged.iter().any(|&b| b) {
        entries.push(LegendEntry::new("not converged", Swatch::Hatched));
    }
    let n = field.nx * field.ny;
    if (0..n).any(|k| !field.z[k].is_finite() && !field.not_converged[k]) {
        entries.push(LegendEntry::new("no value", Swatch::Fill(WHITE)));
    }
    entries.push(LegendEntry::new("contour", Swatch::Line(BLACK, 2)));
    style::draw_legend_column(&bar_legend, None, &entries, 10)?;
    Ok(())
}
