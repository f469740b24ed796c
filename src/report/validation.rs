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

/// The kinds of reference in the order the docs show them: measurements, peers and standards
/// first, then handbook ranges and trends, and self-consistency checks (a formula evaluated by
/// hand, a model's own input table) apart at the end.
pub const KIND_ORDER: [&str; 6] = [
    "measurement",
    "peer",
    "standard",
    "handbook",
    "trend",
    "self_consistency",
];

/// The block docs/validation.md carries between [`DOC_BEGIN`] and [`DOC_END`]: the row count and
/// the summary per kind of reference, each kind in a table of its own.
pub fn doc_block(rows: &[Row], sum: &[SummaryRow]) -> String {
    let cases: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.case.as_str()).collect();
    let mut s = format!(
        "{} rows over {} cases (`geartherm validate validation --doc docs/validation.md` writes this block).\n",
        rows.len(),
        cases.len()
    );
    let known = |k: &str| KIND_ORDER.contains(&k);
    let other: Vec<&str> = {
        let mut o: Vec<&str> = sum
            .iter()
            .map(|r| r.kind.as_str())
            .filter(|k| !known(k))
            .collect();
        o.sort_unstable();
        o.dedup();
        o
    };
    for kind in KIND_ORDER.iter().copied().chain(other) {
        let part: Vec<SummaryRow> = sum.iter().filter(|r| r.kind == kind).cloned().collect();
        if part.is_empty() {
            continue;
        }
        let n: usize = part.iter().map(|r| r.n).sum();
        let _ = write!(
            s,
            "\n**{kind}** ({} case–model rows, {n} points):\n\n",
            part.len()
        );
        s.push_str(&summary_markdown(&part));
    }
    s
}

/// Marker before the generated block in a Markdown file.
pub const DOC_BEGIN: &str = "<!-- geartherm validate: begin -->";
/// Marker after the generated block.
pub const DOC_END: &str = "<!-- geartherm validate: end -->";

/// `doc` with the text between its markers replaced by `block`.
pub fn splice_doc(doc: &str, block: &str) -> Result<String, String> {
    let (Some(a), Some(b)) = (doc.find(DOC_BEGIN), doc.find(DOC_END)) else {
        return Err(format!("the file has no `{DOC_BEGIN}` … `{DOC_END}` markers"));
    };
    if b < a {
        return Err(format!("`{DOC_END}` stands before `{DOC_BEGIN}`"));
    }
    let head = &doc[..a + DOC_BEGIN.len()];
    Ok(format!("{head}\n{block}{}", &doc[b..]))
}

/// The generated block of a Markdown file (between its markers), if it has one.
pub fn doc_block_of(doc: &str) -> Option<&str> {
    let a = doc.find(DOC_BEGIN)? + DOC_BEGIN.len();
    let b = doc.find(DOC_END)?;
    doc.get(a..b).map(|t| t.strip_prefix('\n').unwrap_or(t))
}

/// `--json` document.
#[derive(Debug, serde::Serialize)]
pub struct ValidationReport<'a> {
    /// Every row.
    pub rows: &'a [Row],
    /// Summary per case and model.
    pub summary: &'a [SummaryRow],
    /// Loss models used outside their range, per case and model choice.
    pub warnings: &'a [crate::reference::CaseWarning],
}
