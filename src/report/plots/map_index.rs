//! `report.md` of a map directory: model, gear, grid, the ranges of efficiency, total loss and
//! oil temperature over the converged points, and the three heat maps.

use std::fmt::Write as _;

use super::data::{name_or, MapGrid};
use super::style::fmt_fixed;

fn range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

fn range_text(r: Option<(f64, f64)>, scale: f64, unit: &str, digits: usize) -> String {
    r.map_or("–".into(), |(lo, hi)| {
        format!(
            "{} … {} {unit}",
            fmt_fixed(lo * scale, digits),
            fmt_fixed(hi * scale, digits)
        )
    })
}

/// The markdown text.
pub fn markdown(grid: &MapGrid) -> String {
    let mut s = String::new();
    let cells: Vec<_> = grid.cells.iter().flatten().collect();
    let _ = writeln!(
        s,
        "# Operating map — {} / gear {}\n",
        name_or(&grid.meta.model, "model"),
        name_or(&grid.meta.gear, "–")
    );
    let _ = writeln!(s, "| | |\n|---|---|");
    let axis = |v: &[f64]| match (v.first(), v.last()) {
        (Some(a), Some(b)) => format!("{a} … {b} ({} points)", v.len()),
        _ => "–".into(),
    };
    let _ = writeln!(s, "| Input speed | {} rpm |", axis(&grid.speeds_rpm));
    let _ = writeln!(s, "| Input torque | {} N·m |", axis(&grid.torques_nm));
    let _ = writeln!(
        s,
        "| Converged points | {} of {} |",
        cells.iter().filter(|c| c.converged).count(),
        grid.speeds_rpm.len() * grid.torques_nm.len()
    );
    let _ = writeln!(
        s,
        "| Efficiency P_out/(P_out+P_loss) | {} |",
        range_text(range(cells.iter().filter_map(|c| c.efficiency)), 100.0, "%", 2)
    );
    let _ = writeln!(
        s,
        "| Total loss | {} |",
        range_text(range(cells.iter().filter_map(|c| c.loss_total_w)), 1.0, "W", 1)
    );
    let _ = writeln!(
        s,
        "| Oil temperature | {} |",
        range_text(range(cells.iter().filter_map(|c| c.oil_temp_c)), 1.0, "°C", 1)
    );
    s.push_str("\n![Efficiency](map_efficiency.png)\n\n![Total loss](map_total_loss.png)\n\n");
    s.push_str("![Oil temperature](map_oil_temp.png)\n");
    s
}
