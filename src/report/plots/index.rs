//! `report.md`: the run's summary figures and the four PNGs, as a Markdown page.

use std::fmt::Write;

use super::data::{name_or, RunData};
use super::energy::source_energies;
use super::style::{fmt_fixed, fmt_share, fmt_sig, Source};

/// Escape text for a Markdown table cell.
fn cell(s: &str) -> String {
    s.replace('\\', "\\\\").replace('|', "\\|").replace('\n', " ")
}

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.filter(|x| x.is_finite()).map(f).unwrap_or_else(|| "–".into())
}

/// The run's `report.md`: its summary figures and the four PNGs.
pub fn markdown(run: &RunData) -> String {
    let sm = &run.summary;
    let ts = &run.ts;
    let model = name_or(&sm.model, "(unnamed model)");
    let cycle = name_or(&sm.cycle, "(unnamed cycle)");
    let mut s = String::new();
    let _ = writeln!(s, "# geartherm run report: {} — {}\n", cell(model), cell(cycle));
    let _ = writeln!(s, "| Quantity | Value |\n|---|---|");
    let _ = writeln!(s, "| Model | {} |", cell(model));
    let _ = writeln!(s, "| Cycle | {} |", cell(cycle));
    let _ = writeln!(s, "| Solver | {} |", cell(name_or(&sm.solver, "–")));
    let _ = writeln!(
        s,
        "| rtol / atol | {} / {} |",
        cell(&fmt_sig(sm.rtol, 3)),
        cell(&fmt_sig(sm.atol, 3))
    );
    let _ = writeln!(
        s,
        "| Wall time | {} |",
        opt(Some(sm.wall_time_s), |t| format!("{} s", fmt_sig(t, 3)))
    );
    let _ = writeln!(
        s,
        "| Steps | {} |",
        opt(Some(sm.steps as f64), |n| fmt_fixed(n, 0))
    );
    let t0 = ts.time_order().first().map(|&i| ts.time_s[i]);
    let t1 = ts.time_order().last().map(|&i| ts.time_s[i]);
    if let (Some(a), Some(b)) = (t0, t1) {
        let _ = writeln!(
            s,
            "| Simulated time | {} s ({} rows) |",
            fmt_sig(b - a, 4),
            ts.len()
        );
    }
    let _ = writeln!(
        s,
        "| Energy balance residual (relative) | {} |",
        opt(Some(sm.energy_balance_relative), |b| format!("{b:.2e}"))
    );
    let _ = writeln!(
        s,
        "| Cycle efficiency (energy-weighted, ∫P_out/∫P_in) | {} |",
        opt(sm.cycle_efficiency, |m| format!("{:.2} %", 100.0 * m))
    );
    if !sm.oil_node.is_empty() {
        let _ = writeln!(s, "| Oil node | {} |", cell(&sm.oil_node));
    }

    let src = source_energies(run);
    let total = super::energy::summary_energies(run)
        .map(|e| e.sum())
        .filter(|v| v.is_finite())
        .unwrap_or_else(|| src.iter().sum());
    let _ = writeln!(
        s,
        "\n## Energy lost\n\n| Source | Energy (kJ) | Share |\n|---|---:|---:|"
    );
    for x in Source::ALL {
        let e = src[x.index()];
        let share = fmt_share(e, total);
        let _ = writeln!(s, "| {} | {} | {} |", x.as_str(), fmt_sig(e / 1e3, 4), share);
    }
    let _ = writeln!(s, "| **total** | **{}** | |", fmt_sig(total / 1e3, 4));

    let _ = writeln!(
        s,
        "\n## Temperatures\n\n| Node | Boundary | Min (°C) | Max (°C) | Final (°C) |\n|---|---|---:|---:|---:|"
    );
    // Order: the summary's node list, then nodes only in the time series, then the rest.
    let mut names: Vec<String> = sm.nodes.iter().map(|n| n.name.clone()).collect();
    for (n, _) in &ts.temps_c {
        if !names.contains(n) {
            names.push(n.clone());
        }
    }
    for n in sm.temperatures_c.keys() {
        if !names.contains(n) {
            names.push(n.clone());
        }
    }
    for n in &names {
        // Summary values first; otherwise computed from the time series.
        let series = ts.temps_c.iter().find(|(m, _)| m == n).map(|(_, v)| v);
        let finite = |v: &Vec<f64>| v.iter().copied().filter(|x| x.is_finite()).collect::<Vec<_>>();
        let from_ts = series.map(finite).unwrap_or_default();
        let st = sm.temperatures_c.get(n);
        let min = st
            .map(|t| t.min)
            .or_else(|| from_ts.iter().copied().reduce(f64::min));
        let max = st
            .map(|t| t.max)
            .or_else(|| from_ts.iter().copied().reduce(f64::max));
        let last = st.map(|t| t.r#final).or_else(|| {
            let order = ts.time_order();
            series.and_then(|v| order.iter().rev().map(|&i| v[i]).find(|x| x.is_finite()))
        });
        let f = |v: Option<f64>| opt(v, |x| fmt_fixed(x, 1));
        let boundary = if sm.is_boundary(n) { "yes" } else { "" };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            cell(n),
            boundary,
            f(min),
            f(max),
            f(last)
        );
    }

    let _ = writeln!(s, "\n## Figures\n");
    let _ = writeln!(
        s,
        "### Temperatures\n\n![Node temperatures, vehicle speed and gear](temperatures.png)\n"
    );
    let _ = writeln!(
        s,
        "### Loss power by source\n\n![Loss power stacked by source](losses.png)\n"
    );
    let _ = writeln!(
        s,
        "### Energy lost per component\n\n![Energy lost per component and per source](energy.png)\n"
    );
    let _ = writeln!(
        s,
        "### Efficiency\n\n![Efficiency vs time and its time-weighted distribution](efficiency.png)\n"
    );

    let _ = writeln!(s, "## Skipped by the scene\n");
    if sm.skipped.is_empty() {
        let _ = writeln!(s, "Nothing was skipped.");
    } else {
        for k in &sm.skipped {
            let _ = writeln!(
                s,
                "- **{}**: {}",
                k.what.replace('\n', " "),
                k.why.replace('\n', " ")
            );
        }
    }
    s
}
