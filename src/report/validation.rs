//! `geartherm validate` outputs: `validation.csv`, `validation_summary.csv` and `validation.md`
//! (the table docs/validation.md shows), and the JSON document of `--json`.

use std::fmt::Write as _;

use crate::reference::{Row, SummaryRow};

fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.6}")
    } else {
        String::new()
    }
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// `validation.csv`: one row per case, point and model choice.
pub fn rows_csv(rows: &[Row]) -> String {
    let mut s =
        String::from("case,point,model,quantity,speed_rpm,predicted,reference,kind,relative_error,source\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{}",
            quote(&r.case),
            quote(&r.point),
            quote(&r.model),
            r.quantity,
            num(r.speed_rpm),
            num(r.predicted),
            num(r.reference),
            r.kind.as_str(),
            num(r.relative_error),
            quote(&r.source)
        );
    }
    s
}

/// `validation_summary.csv`: per case (source) and model.
pub fn summary_csv(sum: &[SummaryRow]) -> String {
    let mut s = String::from("case,kind,model,n,median_abs_error,max_abs_error,bias,source\n");
    for r in sum {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{}",
            quote(&r.case),
            r.kind,
            quote(&r.model),
            r.n,
            num(r.median_abs_error),
            num(r.max_abs_error),
            num(r.bias),
            quote(&r.source)
        );
    }
    s
}

/// Markdown table of the summary (|error| and bias in %).
pub fn summary_markdown(sum: &[SummaryRow]) -> String {
    let mut s = String::from(
        "| case | kind | model | points | median abs. error | max abs. error | bias |\n|---|---|---|---:|---:|---:|---:|\n",
    );
    for r in sum {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.1} % | {:.1} % | {:+.1} % |",
            r.case,
            r.kind,
            r.model,
            r.n,
            100.0 * r.median_abs_error,
            100.0 * r.max_abs_error,
            100.0 * r.bias
        );
    }
    s
}

/// `--json` document.
#[derive(Debug, serde::Serialize)]
pub struct ValidationReport<'a> {
    /// Every row.
    pub rows: &'a [Row],
    /// Summary per case and model.
    pub summary: &'a [SummaryRow],
}
