//! `temperatures.png`: node temperatures vs time (the oil node thicker; boundary nodes dashed on
//! their own right axis, so that a fixed 90 °C coolant does not set the scale of the nodes),
//! and below it, on the same time axis, vehicle speed (left axis) and gear (step line, right axis).

use plotters::prelude::*;
use plotters::series::DashedLineSeries;
use plotters::style::text_anchor::{HPos, VPos};

use super::data::{decimate, finite_segments, RunData, TimeSeries};
use super::panel::{self, Axes, TimeAxis};
use super::style::{self, LegendEntry, Swatch};
use super::{Canvas, DrawResult};

const LEGEND_W: u32 = 300;
const Y_LABEL_W: u32 = 110;
const Y2_LABEL_W: u32 = 100;

/// Order gear-state names: P, R, N first, then numeric gears ascending, then the rest by name.
pub fn gear_levels(gears: &[String]) -> Vec<String> {
    let mut names: Vec<&str> = gears.iter().map(|g| g.trim()).filter(|g| !g.is_empty()).collect();
    names.sort_unstable();
    names.dedup();
    let rank = |g: &str| -> (u8, f64, String) {
        match g {
            "P" => (0, 0.0, String::new()),
            "R" => (1, 0.0, String::new()),
            "N" => (2, 0.0, String::new()),
            _ => match g.parse::<f64>() {
                Ok(x) => (3, x, String::new()),
                Err(_) => (4, 0.0, g.to_string()),
            },
        }
    };
    names.sort_by(|a, b| {
        let (ra, rb) = (rank(a), rank(b));
        ra.0.cmp(&rb.0).then(ra.1.total_cmp(&rb.1)).then(ra.2.cmp(&rb.2))
    });
    names.into_iter().map(String::from).collect()
}

/// Draw `temperatures.png` of the run: node temperatures, vehicle speed and gear vs time.
pub fn draw(root: &Canvas, run: &RunData) -> DrawResult {
    let sm = &run.summary;
    let title = format!(
        "Temperatures — {} / {}",
        super::data::name_or(&sm.model, "model"),
        super::data::name_or(&sm.cycle, "cycle")
    );
    let root = style::titled(root, &title)?;
    let (w, h) = root.dim_in_pixel();
    let (main, legend) = root.split_horizontally(w - LEGEND_W);
    let split_y = (h as f64 * 0.64) as u32;
    let (upper, lower) = main.split_vertically(split_y);
    let (leg_up, leg_low) = legend.split_vertically(split_y);
    let order = run.ts.time_order();
    let time = TimeAxis::over(&run.ts.time_s, &order);
    let buckets = (w - LEGEND_W) as usize;
    draw_temperatures(&upper, &leg_up, run, (&order, time, buckets))?;
    draw_drive(&lower, &leg_low, run, (&order, time, buckets))?;
    if gear_levels(&run.ts.gear).is_empty() {
        lower.draw(&Text::new(
            "no gear data",
            (w as i32 / 2, 30),
            style::text_at(style::NOTE_PX, HPos::Center, VPos::Top),
        ))?;
    }
    Ok(())
}

/// The rows in time order, the time axis and the number of horizontal pixel buckets the curves
/// are decimated to.
type Timeline<'a> = (&'a [usize], TimeAxis, usize);

/// Upper panel: temperatures. The gearbox nodes set the left axis; boundaries (ambient, coolant
/// at a fixed 90 °C, ...) have their own right axis, so a distant boundary does not squash the
/// node curves into a thin band.
fn draw_temperatures(area: &Canvas, legend: &Canvas, run: &RunData, line: Timeline) -> DrawResult {
    let (ts, sm) = (&run.ts, &run.summary);
    let (order, time, buckets) = line;
    let (x0, x1) = (time.x0, time.x1);
    let oil = (!sm.oil_node.is_empty()).then_some(sm.oil_node.as_str());
    let any_node = ts.temps_c.iter().any(|(n, _)| !sm.is_boundary(n));
    let any_boundary = ts.temps_c.iter().any(|(n, _)| sm.is_boundary(n));
    let range_of = |boundary: bool| {
        style::padded_range(
            ts.temps_c
                .iter()
                .filter(|(n, _)| sm.is_boundary(n) == boundary || !(any_node && any_boundary))
                .flat_map(|(_, v)| v.iter().copied()),
            0.06,
        )
    };
    let (y0, y1) = range_of(!any_node);
    let (b0, b1) = range_of(true);
    let mut chart = ChartBuilder::on(area)
        .margin_left(20)
        .margin_right(10)
        .margin_top(10)
        .x_label_area_size(12)
        .y_label_area_size(Y_LABEL_W)
        .right_y_label_area_size(Y2_LABEL_W)
        .build_cartesian_2d(x0..x1, y0..y1)?
        .set_secondary_coord(x0..x1, b0..b1);
    Axes::house()
        .y_desc("Temperature (°C)")
        .labels(12, 8)
        .x_format(&panel::blank)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    if any_node && any_boundary {
        chart
            .configure_secondary_axes()
            .y_desc("Boundaries (°C, dashed)")
            .axis_desc_style(style::font(style::AXIS_DESC_PX))
            .label_style(style::font(style::TICK_PX))
            .y_labels(8)
            .y_label_formatter(&|v| style::fmt_num(*v))
            .draw()?;
    }
    let mut entries = Vec::new();
    for (k, (name, values)) in ts.temps_c.iter().enumerate() {
        let colour = style::series_colour(k);
        let boundary = sm.is_boundary(name);
        let width = if Some(name.as_str()) == oil { 5 } else { 3 };
        for seg in finite_segments(order, &ts.time_s, values, time.scale) {
            let seg = decimate(&seg, buckets);
            if seg.len() == 1 {
                chart.draw_series(std::iter::once(Circle::new(seg[0], 5, colour.filled())))?;
            } else if boundary && any_node {
                chart.draw_secondary_series(DashedLineSeries::new(seg, 14, 10, colour.stroke_width(2)))?;
            } else if boundary {
                chart.draw_series(DashedLineSeries::new(seg, 14, 10, colour.stroke_width(2)))?;
            } else {
                chart.draw_series(LineSeries::new(seg, colour.stroke_width(width)))?;
            }
        }
        let (label, swatch) = if boundary {
            (format!("{name} (right axis)"), Swatch::Dashed(colour, 2))
        } else if Some(name.as_str()) == oil {
            (format!("{name} (oil)"), Swatch::Line(colour, 5))
        } else {
            (name.clone(), Swatch::Line(colour, 3))
        };
        entries.push(LegendEntry::new(label, swatch));
    }
    if ts.temps_c.is_empty() {
        style::draw_note_centre(area, "no temperature columns in timeseries.csv")?;
    }
    style::draw_legend_column(legend, Some("Thermal nodes"), &entries, 14)?;
    Ok(())
}

/// Lower panel: vehicle speed (left axis) and gear (step line, right axis).
fn draw_drive(area: &Canvas, legend: &Canvas, run: &RunData, line: Timeline) -> DrawResult {
    let ts = &run.ts;
    let (order, time, buckets) = line;
    let (x0, x1) = (time.x0, time.x1);
    let (s0, s1) = style::padded_range(ts.vehicle_speed_kmh.iter().copied().chain([0.0]), 0.06);
    let all_non_negative = ts.vehicle_speed_kmh.iter().all(|v| v.is_nan() || *v >= 0.0);
    let s0 = if all_non_negative { 0.0 } else { s0 };
    let levels = gear_levels(&ts.gear);
    let n_levels = levels.len().max(1) as f64;
    let mut chart = ChartBuilder::on(area)
        .margin_left(20)
        .margin_right(10)
        .margin_top(14)
        .margin_bottom(10)
        .x_label_area_size(80)
        .y_label_area_size(Y_LABEL_W)
        .right_y_label_area_size(Y2_LABEL_W)
        .build_cartesian_2d(x0..x1, s0..s1)?
        .set_secondary_coord(x0..x1, -0.6..(n_levels - 0.4));
    Axes::house()
        .x_desc(time.desc)
        .y_desc("Vehicle speed (km/h)")
        .labels(12, 5)
        .x_format(&panel::compact)
        .y_format(&panel::compact)
        .draw(&mut chart)?;
    let gear_label = |v: &f64| {
        let r = v.round();
        if (v - r).abs() < 1e-6 && r >= 0.0 && (r as usize) < levels.len() {
            levels[r as usize].clone()
        } else {
            String::new()
        }
    };
    chart
        .configure_secondary_axes()
        .y_desc("Gear")
        .axis_desc_style(style::font(style::AXIS_DESC_PX))
        .label_style(style::font(style::TICK_PX))
        .y_labels(levels.len() + 1)
        .y_label_formatter(&gear_label)
        .draw()?;

    let speed_colour = RGBColor(40, 40, 40);
    let gear_colour = RGBColor(204, 121, 167);
    for seg in finite_segments(order, &ts.time_s, &ts.vehicle_speed_kmh, time.scale) {
        if seg.len() == 1 {
            chart.draw_series(std::iter::once(Circle::new(seg[0], 5, speed_colour.filled())))?;
        }
        let seg = decimate(&seg, buckets);
        chart.draw_series(LineSeries::new(seg, speed_colour.stroke_width(2)))?;
    }
    for s in gear_steps(ts, order, &levels, time.scale) {
        if s.len() == 1 {
            chart.draw_secondary_series(std::iter::once(Circle::new(s[0], 6, gear_colour.filled())))?;
        }
        chart.draw_secondary_series(LineSeries::new(s, gear_colour.stroke_width(3)))?;
    }
    let entries = [
        LegendEntry::new("vehicle speed", Swatch::Line(speed_colour, 2)),
        LegendEntry::new("gear (right axis)", Swatch::Line(gear_colour, 3)),
    ];
    style::draw_legend_column(legend, Some("Drive"), &entries, 18)?;
    Ok(())
}

/// The gear as step lines (time in display units, gear level): each gear held until the next
/// sample; a new line where the gear is missing.
fn gear_steps(ts: &TimeSeries, order: &[usize], levels: &[String], t_scale: f64) -> Vec<Vec<(f64, f64)>> {
    let mut step: Vec<(f64, f64)> = Vec::new();
    let mut steps = Vec::new();
    for &i in order {
        let lvl = levels.iter().position(|l| l == ts.gear[i].trim());
        let t = ts.time_s[i] * t_scale;
        match lvl {
            Some(l) => {
                let y = l as f64;
                if let Some(&(_, py)) = step.last() {
                    step.push((t, py));
                }
                step.push((t, y));
            }
            None => {
                if !step.is_empty() {
                    step.push((t, step[step.len() - 1].1));
                    steps.push(std::mem::take(&mut step));
                }
            }
        }
    }
    if !step.is_empty() {
        steps.push(step);
    }
    steps
}
