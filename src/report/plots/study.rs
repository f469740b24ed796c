//! Study figures: `main_effects.png` (each parameter against each chosen output, one panel per
//! pair, every finished case a dot coloured by the study's categorical parameter, e.g. the oil,
//! and the mean per category or per fifth of the range for each colour) and `pareto.png` (two
//! outputs, both minimised: every case, coloured likewise, and the non-dominated front with its
//! cases labelled). Axes carry words and units in readable multiples (kJ, MJ, °C).

use std::path::{Path, PathBuf};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::panel::{self, Axes, Grid};
use super::style::{LegendEntry, Swatch};
use super::{commit, quantity, stage_png, style, Canvas, DrawResult, PlotError};
use crate::report::study::{CaseRow, ParamValue, Table};

/// Position of a parameter value on the x axis: the number, or the index of a text value among
/// the column's distinct values (categorical axis).
fn x_of(v: &ParamValue, cats: &[String]) -> Option<f64> {
    match v {
        ParamValue::Number(x) if x.is_finite() => Some(*x),
        ParamValue::Text(s) => cats.iter().position(|c| c == s).map(|i| i as f64),
        _ => None,
    }
}

fn param<'a>(r: &'a CaseRow, name: &str) -> Option<&'a ParamValue> {
    r.params.iter().find(|(k, _)| k == name).map(|(_, v)| v)
}

fn categories(t: &Table, name: &str) -> Vec<String> {
    let mut c: Vec<String> = Vec::new();
    for r in &t.rows {
        if let Some(ParamValue::Text(s)) = param(r, name) {
            if !c.contains(s) {
                c.push(s.clone());
            }
        }
    }
    c
}

/// The categorical parameter the points are coloured by: the first text parameter of the table
/// (e.g. the oil), with its values in order of appearance. A study without one has a single
/// colour.
struct ColourKey {
    param: Option<String>,
    cats: Vec<String>,
}

impl ColourKey {
    fn of(t: &Table) -> ColourKey {
        let param = t.params.iter().find(|(_, text)| *text).map(|(k, _)| k.clone());
        let cats = param.as_deref().map_or_else(Vec::new, |p| categories(t, p));
        // A text parameter without a text value among the rows colours nothing.
        let param = param.filter(|_| !cats.is_empty());
        ColourKey { param, cats }
    }

    /// Colour group of a row (0 without a key).
    fn group(&self, r: &CaseRow) -> usize {
        match (&self.param, self.param.as_deref().and_then(|p| param(r, p))) {
            (Some(_), Some(ParamValue::Text(s))) => self.cats.iter().position(|c| c == s).unwrap_or(0),
            _ => 0,
        }
    }

    fn groups(&self) -> usize {
        self.cats.len().max(1)
    }

    fn colour(&self, g: usize) -> RGBColor {
        if self.param.is_some() {
            style::series_colour(g)
        } else {
            style::NEUTRAL
        }
    }
}

/// The largest font size (from `px` down to 11) at which `text` fits in `width` pixels.
fn fitting_px(area: &Canvas, text: &str, width: u32, px: u32) -> u32 {
    (11..=px)
        .rev()
        .find(|&p| {
            area.estimate_text_size(text, &style::text(p))
                .is_ok_and(|(w, _)| w <= width)
        })
        .unwrap_or(11)
}

/// (x, y, colour group) of every finished case with both values.
fn points(t: &Table, p: &str, out: &str, cats: &[String], key: &ColourKey) -> Vec<(f64, f64, usize)> {
    t.rows
        .iter()
        .filter_map(|r| {
            let x = x_of(param(r, p)?, cats)?;
            let y = t.output(r, out).filter(|y| y.is_finite())?;
            Some((x, y, key.group(r)))
        })
        .collect()
}

fn panel(area: &Canvas, t: &Table, p: &str, out: &str, key: &ColourKey) -> DrawResult {
    let cats = categories(t, p);
    let raw = points(t, p, out, &cats, key);
    if raw.is_empty() {
        style::draw_note_centre(area, &format!("{out}: no finished case"))?;
        return Ok(());
    }
    let yq = quantity::axis(out, raw.iter().map(|q| q.1.abs()).fold(0.0, f64::max));
    let xq = quantity::axis(p, raw.iter().map(|q| q.0.abs()).fold(0.0, f64::max));
    let pts: Vec<(f64, f64, usize)> = raw.iter().map(|&(x, y, g)| (x, y / yq.factor, g)).collect();
    let (x0, x1) = if cats.is_empty() {
        style::padded_range(pts.iter().map(|p| p.0), 0.05)
    } else {
        (-0.5, cats.len() as f64 - 0.5)
    };
    let (y0, y1) = style::padded_range(pts.iter().map(|p| p.1), 0.08);
    let (w, h) = area.dim_in_pixel();
    let x_desc = if cats.is_empty() {
        xq.desc
    } else {
        format!("{p} (colours: legend)")
    };
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let xfmt = |x: &f64| {
        if cats.is_empty() {
            style::fmt_num(*x)
        } else {
            String::new()
        }
    };
    let y_px = fitting_px(area, &yq.desc, h.saturating_sub(70), 18);
    Axes::with_fonts(style::font(15).into(), style::font(y_px).into())
        .grid(Grid::Lines {
            light: Some(WHITE),
            bold: Some(style::GRID),
        })
        .y_desc(yq.desc)
        .labels(if cats.is_empty() { 5 } else { cats.len() * 2 + 1 }, 5)
        .x_format(&xfmt)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    // The x description across the whole cell (a key path is longer than the plot area).
    let x_px = fitting_px(area, &x_desc, w.saturating_sub(8), 18);
    area.draw(&Text::new(
        x_desc,
        (w as i32 / 2, h as i32 - 14),
        style::text_at(x_px, HPos::Center, VPos::Center),
    ))?;
    chart.draw_series(
        pts.iter()
            .map(|&(x, y, g)| Circle::new((x, y), 3, key.colour(g).mix(0.35).filled())),
    )?;
    // The main effect: the mean of the output per category of this parameter, or per fifth of
    // its range within each colour group (one line per oil, not one through all of them).
    for g in 0..key.groups() {
        let own: Vec<(f64, f64)> = pts.iter().filter(|q| q.2 == g).map(|q| (q.0, q.1)).collect();
        let n = if cats.is_empty() { 5 } else { cats.len() };
        let means = binned_means(&own, n, x0, x1, !cats.is_empty());
        let c = key.colour(g);
        if cats.is_empty() {
            chart.draw_series(LineSeries::new(means.iter().copied(), c.stroke_width(3)))?;
        }
        chart.draw_series(means.iter().map(|&(x, y)| Circle::new((x, y), 5, c.filled())))?;
        chart.draw_series(
            means
                .iter()
                .map(|&(x, y)| Circle::new((x, y), 5, BLACK.stroke_width(1))),
        )?;
    }
    Ok(())
}

/// Mean of y per bin of x: `n` equal bins over [x0, x1], or one bin per integer (categorical).
fn binned_means(pts: &[(f64, f64)], n: usize, x0: f64, x1: f64, categorical: bool) -> Vec<(f64, f64)> {
    let mut sum = vec![(0.0, 0.0, 0usize); n.max(1)];
    for &(x, y) in pts {
        let k = if categorical {
            x.round() as usize
        } else {
            (((x - x0) / (x1 - x0).max(f64::MIN_POSITIVE)) * n as f64) as usize
        };
        let s = &mut sum[k.min(n.max(1) - 1)];
        s.0 += x;
        s.1 += y;
        s.2 += 1;
    }
    sum.iter()
        .filter(|s| s.2 > 0)
        .map(|s| (s.0 / s.2 as f64, s.1 / s.2 as f64))
        .collect()
}

/// The legend of the colours (the categorical parameter's values, in full) and the mean markers.
fn colour_legend(area: &Canvas, key: &ColourKey) -> DrawResult {
    let mut entries: Vec<LegendEntry> = match &key.param {
        Some(p) => key
            .cats
            .iter()
            .enumerate()
            .map(|(g, c)| {
                let label = if g == 0 { format!("{p}: {c}") } else { c.clone() };
                LegendEntry::new(label, Swatch::Fill(key.colour(g)))
            })
            .collect(),
        None => vec![LegendEntry::new(
            "every finished case",
            Swatch::Fill(style::NEUTRAL),
        )],
    };
    entries.push(LegendEntry::new(
        "mean per fifth of the range",
        Swatch::MarkerLine(style::TEXT, style::Marker::nth(0)),
    ));
    style::draw_legend_row(area, &entries)?;
    Ok(())
}

fn draw_effects(root: &Canvas, t: &Table, outputs: &[String], title: &str) -> DrawResult {
    let root = style::titled(root, title)?;
    let (legend, grid) = root.split_vertically(56);
    let key = ColourKey::of(t);
    colour_legend(&legend, &key)?;
    let params: Vec<&str> = t.params.iter().map(|(k, _)| k.as_str()).collect();
    let (nr, nc) = (outputs.len().max(1), params.len().max(1));
    let cells = grid.split_evenly((nr, nc));
    for (k, cell) in cells.iter().enumerate() {
        let (i, j) = (k / nc, k % nc);
        if let (Some(out), Some(p)) = (outputs.get(i), params.get(j)) {
            panel(cell, t, p, out, &key)?;
        }
    }
    Ok(())
}

/// Indices of the rows on the Pareto front of (a, b), both minimised.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&i, &j| {
        points[i]
            .0
            .total_cmp(&points[j].0)
            .then(points[i].1.total_cmp(&points[j].1))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in idx {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

fn draw_pareto(root: &Canvas, t: &Table, a: &str, b: &str, title: &str) -> DrawResult {
    let root = style::titled(root, title)?;
    let key = ColourKey::of(t);
    let rows: Vec<(f64, f64, usize, &str)> = t
        .rows
        .iter()
        .filter_map(|r| {
            let x = t.output(r, a).filter(|v| v.is_finite())?;
            let y = t.output(r, b).filter(|v| v.is_finite())?;
            Some((x, y, key.group(r), r.case.as_str()))
        })
        .collect();
    if rows.is_empty() {
        style::draw_note_centre(&root, "no finished case has both outputs")?;
        return Ok(());
    }
    let max = |f: fn(&(f64, f64, usize, &str)) -> f64| rows.iter().map(|r| f(r).abs()).fold(0.0, f64::max);
    let (xq, yq) = (quantity::axis(a, max(|r| r.0)), quantity::axis(b, max(|r| r.1)));
    let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.0 / xq.factor, r.1 / yq.factor)).collect();
    let (x0, x1) = style::padded_range(pts.iter().map(|p| p.0), 0.05);
    let (y0, y1) = style::padded_range(pts.iter().map(|p| p.1), 0.05);
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(110)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    Axes::house()
        .x_desc(format!("{} (minimised)", xq.desc))
        .y_desc(format!("{} (minimised)", yq.desc))
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    for g in 0..key.groups() {
        let c = key.colour(g).mix(0.5);
        let own = pts.iter().zip(&rows).filter(|(_, r)| r.2 == g).map(|(p, _)| *p);
        let label = match &key.param {
            Some(p) => format!("{p} = {}", key.cats[g]),
            None => format!("all finished cases ({})", pts.len()),
        };
        chart
            .draw_series(own.map(|(x, y)| Circle::new((x, y), 4, c.filled())))?
            .label(label)
            .legend(move |(x, y)| Circle::new((x, y), 5, c.filled()));
    }
    let front = pareto_front(&pts);
    let line: Vec<(f64, f64)> = front.iter().map(|&i| pts[i]).collect();
    chart
        .draw_series(LineSeries::new(line.iter().copied(), BLACK.stroke_width(2)))?
        .label(format!("Pareto front ({} cases, labelled)", front.len()))
        .legend(move |(x, y)| PathElement::new(vec![(x - 12, y), (x + 12, y)], BLACK.stroke_width(2)));
    chart.draw_series(
        line.iter()
            .map(|&(x, y)| Circle::new((x, y), 6, BLACK.stroke_width(2))),
    )?;
    // Each front case labelled with its id (the row of study.csv), alternately right and left
    // of its point so that neighbours along a steep front do not overlap.
    chart.draw_series(front.iter().enumerate().map(|(k, &i)| {
        let (dx, h) = if k % 2 == 0 {
            (12, HPos::Left)
        } else {
            (-12, HPos::Right)
        };
        EmptyElement::at(pts[i])
            + Text::new(
                rows[i].3.to_string(),
                (dx, 0),
                style::text_at(15, h, VPos::Center),
            )
    }))?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(style::GRID_BOLD)
        .label_font(style::font(style::LEGEND_PX))
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    Ok(())
}

/// Render `main_effects.png` and, when two outputs are given, `pareto.png` into `dir`.
pub fn render(
    dir: &Path,
    t: &Table,
    name: &str,
    effects: &[String],
    pareto: Option<(&str, &str)>,
) -> Result<Vec<PathBuf>, PlotError> {
    style::ensure_fonts()?;
    let mut staged = vec![stage_png(dir, "main_effects.png", |root| {
        draw_effects(
            root,
            t,
            effects,
            &format!("Main effects — study {name} ({} cases)", t.rows.len()),
        )
    })?];
    if let Some((a, b)) = pareto {
        staged.push(stage_png(dir, "pareto.png", |root| {
            draw_pareto(root, t, a, b, &format!("Pareto front — study {name}"))
        })?);
    }
    commit(staged)
}

#[cfg(test)]
mod tests {
    use super::pareto_front;

    #[test]
    fn front_keeps_only_non_dominated_points() {
        let p = [
            (1.0, 5.0),
            (2.0, 3.0),
            (2.5, 4.0),
            (3.0, 1.0),
            (4.0, 1.0),
            (1.0, 6.0),
        ];
        let mut f = pareto_front(&p);
        f.sort();
        assert_eq!(f, vec![0, 1, 3]);
    }
}
