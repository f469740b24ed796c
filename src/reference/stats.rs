//! Summary of `validation.csv` per source and model: median and max |relative error|, bias.

use super::Row;

/// One summary row.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SummaryRow {
    /// Source of the references.
    pub source: String,
    /// Kind of reference.
    pub kind: String,
    /// Case.
    pub case: String,
    /// Model choice.
    pub model: String,
    /// Points.
    pub n: usize,
    /// Median |relative error|.
    pub median_abs_error: f64,
    /// Max |relative error|.
    pub max_abs_error: f64,
    /// Mean relative error (signed).
    pub bias: f64,
}

/// Median of `v` (sorted copy; 0 for an empty slice).
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// One row per (case, model), in first-seen order.
pub fn summarise(rows: &[Row]) -> Vec<SummaryRow> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in rows {
        let k = (r.case.clone(), r.model.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(case, model)| {
            let sel: Vec<&Row> = rows
                .iter()
                .filter(|r| r.case == case && r.model == model)
                .collect();
            let e: Vec<f64> = sel.iter().map(|r| r.relative_error).collect();
            let abs: Vec<f64> = e.iter().map(|x| x.abs()).collect();
            SummaryRow {
                source: sel[0].source.clone(),
                kind: sel[0].kind.as_str().into(),
                case,
                model,
                n: e.len(),
                median_abs_error: median(&abs),
                max_abs_error: abs.iter().copied().fold(0.0, f64::max),
                bias: e.iter().sum::<f64>() / e.len() as f64,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&[]), 0.0);
    }
}
