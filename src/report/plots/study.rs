//! Study figures: `main_effects.png` (each parameter against each chosen output, one panel per
//! pair, every finished case a dot, the mean per category or per fifth of the range a red line)
//! and `pareto.png` (two outputs, both minimised: every case and
//! the non-dominated front).

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::panel::{self, Axes, Grid};
use super::{commit, stage_png, style, Canvas, DrawResult, PlotError};
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

fn panel(area: &Canvas, t: &Table, p: &str, out: &str, cats: &[String]) -> DrawResult {
    let pts: Vec<(f64, f64)> = t
        .rows
        .iter()
        .filter_map(|r| {
            Some((
                x_of(param(r, p)?, cats)?,
                t.output(r, out).filter(|y| y.is_finite())?,
            ))
        })
        .collect();
    if pts.is_empty() {
        style::draw_note_centre(area, &format!("{out}: no finished case"))?;
        return Ok(());
    }
    let (x0, x1) = if cats.is_empty() {
        style::padded_range(pts.iter().map(|p| p.0), 0.05)
    } else {
        (-0.5, cats.len() as f64 - 0.5)
    };
    let (y0, y1) = style::padded_range(pts.iter().map(|p| p.1), 0.08);
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(44)
        .y_label_area_size(86)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let cats_owned = cats.to_vec();
    let xfmt = move |x: &f64| {
        if cats_owned.is_empty() {
            style::fmt_num(*x)
        } else {
            let i = x.round();
            if (x - i).abs() < 1e-9 && i >= 0.0 {
                let max = (40 / cats_owned.len().max(1)).max(4);
                let full = cats_owned.get(i as usize).cloned().unwrap_or_default();
                if full.chars().count() > max {
                    full.chars().take(max - 1).chain(['…']).collect()
                } else {
                    full
                }
            } else {
                String::new()
            }
        }
    };
    Axes::with_fonts(style::font(16).into(), style::font(18).into())
        .grid(Grid::Lines {
            light: Some(WHITE),
            bold: Some(style::GRID),
        })
        .x_desc(p)
        .y_desc(out)
        .labels(if cats.is_empty() { 5 } else { cats.len() * 2 + 1 }, 5)
        .x_format(&xfmt)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    let c = style::series_colour(0).mix(0.45);
    chart.draw_series(pts.iter().map(|&(x, y)| Circle::new((x, y), 3, c.filled())))?;
    // The main effect: the mean of the output per category, or per fifth of the range.
    let means = binned_means(
        &pts,
        if cats.is_empty() { 5 } else { cats.len() },
        x0,
        x1,
        !cats.is_empty(),
    );
    let red = style::series_colour(1);
    chart.draw_series(LineSeries::new(means.iter().copied(), red.stroke_width(3)))?;
    chart.draw_series(means.iter().map(|&(x, y)| Circle::new((x, y), 5, red.filled())))?;
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

fn draw_effects(root: &Canvas, t: &Table, outputs: &[String], title: &str) -> DrawResult {
    let root = style::titled(root, title)?;
    let params: Vec<&str> = t.params.iter().map(|(k, _)| k.as_str()).collect();
    let (nr, nc) = (outputs.len().max(1), params.len().max(1));
    let cells = root.split_evenly((nr, nc));
    for (k, cell) in cells.iter().enumerate() {
        let (i, j) = (k / nc, k % nc);
        if let (Some(out), Some(p)) = (outputs.get(i), params.get(j)) {
            let cats = categories(t, p);
            panel(cell, t, p, out, &cats)?;
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
    let pts: Vec<(f64, f64)> = t
        .rows
        .iter()
        .filter_map(|r| {
            let x = t.output(r, a).filter(|v| v.is_finite())?;
            let y = t.output(r, b).filter(|v| v.is_finite())?;
            Some((x, y))
        })
        .collect();
    if pts.is_empty() {
        style::draw_note_centre(&root, "no finished case has both outputs")?;
        return Ok(());
    }
    let (x0, x1) = style::padded_range(pts.iter().map(|p| p.0), 0.05);
    let (y0, y1) = style::padded_range(pts.iter().map(|p| p.1), 0.05);
    let mut chart = ChartBuilder::on(&root)
        .margin(20)
        .x_label_area_size(70)
        .y_label_area_size(110)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    Axes::house()
        .grid(Grid::Lines {
            light: Some(style::GRID),
            bold: None,
        })
        .x_desc(format!("{a} (minimised)"))
        .y_desc(format!("{b} (minimised)"))
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    let grey = style::NEUTRAL.mix(0.45);
    chart
        .draw_series(pts.iter().map(|&(x, y)| Circle::new((x, y), 4, grey.filled())))?
        .label(format!("all finished cases ({})", pts.len()))
        .legend(move |(x, y)| Circle::new((x, y), 5, grey.filled()));
    let front: Vec<(f64, f64)> = pareto_front(&pts).into_iter().map(|i| pts[i]).collect();
    let red = style::series_colour(1);
    chart
        .draw_series(LineSeries::new(front.iter().copied(), red.stroke_width(3)))?
        .label(format!("Pareto front ({} cases)", front.len()))
        .legend(move |(x, y)| PathElement::new(vec![(x - 12, y), (x + 12, y)], red.stroke_width(3)));
    chart.draw_series(front.iter().map(|&(x, y)| Circle::new((x, y), 6, red.filled())))?;
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
