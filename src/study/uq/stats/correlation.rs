//! Correlated inputs.
//!
//! - [`rank_correlate`]: the distribution-free method of R. L. Iman and W. J. Conover, "A
//!   distribution-free approach to inducing rank correlation among input variables", Commun.
//!   Statist.-Simula. Computa. 11 (1982) 311–334: the columns of a sample are reordered (each
//!   column keeps its values, so the marginals are exact) so that their rank correlation
//!   approaches a target. Scores are van der Waerden scores Φ⁻¹(r/(n+1)) of the sample's own
//!   ranks; with T = L_T L_Tᵀ their correlation and C = L_C L_Cᵀ the target, the scores are
//!   transformed by S = L_C L_T⁻¹ (Iman & Conover's variance-reduced form, which makes the
//!   correlation of the transformed scores exactly C), and each column of the sample is put in
//!   the rank order of its transformed score column.
//! - [`gaussian_copula`]: exact multivariate normal dependence: uniforms u → z = Φ⁻¹(u),
//!   z' = L z with C = L Lᵀ, u' = Φ(z'). With normal marginals (sd_i from a covariance's
//!   diagonal) the inputs are exactly N(μ, Σ) — the form a calibrated covariance takes
//!   ([`covariance_to_correlation`]).

use super::dist::{normal_cdf, normal_quantile};
pub use crate::model::uncertainty::matrix::{check_correlation, cholesky};

/// Solve L x = b for lower-triangular L.
fn forward(l: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; b.len()];
    for i in 0..b.len() {
        let s: f64 = (0..i).map(|k| l[i][k] * x[k]).sum();
        x[i] = (b[i] - s) / l[i][i];
    }
    x
}

/// Ranks 0..n of a column (ties broken by position).
fn ranks(col: &[f64]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..col.len()).collect();
    idx.sort_by(|&a, &b| col[a].total_cmp(&col[b]).then(a.cmp(&b)));
    let mut r = vec![0; col.len()];
    for (rank, &i) in idx.iter().enumerate() {
        r[i] = rank;
    }
    r
}

/// Pearson correlation matrix of the columns of `rows` (n × d).
pub fn pearson(rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = rows.len() as f64;
    let d = rows.first().map_or(0, Vec::len);
    let mean: Vec<f64> = (0..d)
        .map(|j| rows.iter().map(|r| r[j]).sum::<f64>() / n)
        .collect();
    let mut c = vec![vec![0.0; d]; d];
    for i in 0..d {
        for j in 0..=i {
            let s: f64 = rows.iter().map(|r| (r[i] - mean[i]) * (r[j] - mean[j])).sum();
            c[i][j] = s;
            c[j][i] = s;
        }
    }
    let sd: Vec<f64> = (0..d).map(|i| c[i][i].sqrt()).collect();
    for i in 0..d {
        for j in 0..d {
            c[i][j] /= sd[i] * sd[j];
        }
    }
    c
}

/// Spearman rank correlation matrix of the columns of `rows` (Pearson correlation of the ranks).
pub fn spearman(rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let d = rows.first().map_or(0, Vec::len);
    let rk: Vec<Vec<usize>> = (0..d)
        .map(|j| ranks(&rows.iter().map(|r| r[j]).collect::<Vec<_>>()))
        .collect();
    let as_rows: Vec<Vec<f64>> = (0..rows.len())
        .map(|i| (0..d).map(|j| rk[j][i] as f64).collect())
        .collect();
    pearson(&as_rows)
}

/// Reorder each column of `samples` (rows = samples, columns = inputs) so that the columns' rank
/// correlation approaches `target` (Iman & Conover 1982; see the module docs). Each column keeps
/// its values. Needs at least d + 2 samples and a valid `target` ([`check_correlation`]).
pub fn rank_correlate(samples: &mut [Vec<f64>], target: &[Vec<f64>]) -> Result<(), String> {
    check_correlation(target)?;
    let d = target.len();
    let n = samples.len();
    if samples.iter().any(|r| r.len() != d) {
        return Err(format!(
            "every sample needs {d} values (the correlation matrix is {d}×{d})"
        ));
    }
    if n < d + 2 {
        return Err(format!(
            "{n} samples: rank correlation of {d} inputs needs at least {}",
            d + 2
        ));
    }
    let rk: Vec<Vec<usize>> = (0..d)
        .map(|j| ranks(&samples.iter().map(|r| r[j]).collect::<Vec<_>>()))
        .collect();
    let score = |r: usize| normal_quantile((r as f64 + 1.0) / (n as f64 + 1.0));
    let scores: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..d).map(|j| score(rk[j][i])).collect())
        .collect();
    let lt = cholesky(&pearson(&scores))
        .map_err(|e| format!("the sample's own scores are degenerate ({e}); use more samples"))?;
    let lc = cholesky(target)?;
    // Transformed scores: s' = L_C L_T⁻¹ s per row.
    let new_scores: Vec<Vec<f64>> = scores
        .iter()
        .map(|s| {
            let w = forward(&lt, s);
            (0..d).map(|i| (0..=i).map(|k| lc[i][k] * w[k]).sum()).collect()
        })
        .collect();
    for j in 0..d {
        let mut sorted: Vec<f64> = samples.iter().map(|r| r[j]).collect();
        sorted.sort_by(f64::total_cmp);
        let target_rank = ranks(&new_scores.iter().map(|s| s[j]).collect::<Vec<_>>());
        for (i, row) in samples.iter_mut().enumerate() {
            row[j] = sorted[target_rank[i]];
        }
    }
    Ok(())
}

/// Correlated uniforms by a Gaussian copula: each row u (values in (0, 1)) becomes Φ(L Φ⁻¹(u)),
/// C = L Lᵀ. Results are clamped to [2^-1074·…, 1 − 2^-53] so they stay inside (0, 1) for a
/// quantile transform.
pub fn gaussian_copula(u_rows: &[Vec<f64>], corr: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, String> {
    check_correlation(corr)?;
    let l = cholesky(corr)?;
    let d = corr.len();
    let hi = 1.0 - f64::EPSILON / 2.0;
    u_rows
        .iter()
        .enumerate()
        .map(|(r, u)| {
            if u.len() != d {
                return Err(format!(
                    "row {r} has {} values, the correlation matrix is {d}×{d}",
                    u.len()
                ));
            }
            if let Some(x) = u.iter().find(|x| !(**x > 0.0 && **x < 1.0)) {
                return Err(format!("row {r}: {x} is not in the open interval (0, 1)"));
            }
            let z: Vec<f64> = u.iter().map(|&x| normal_quantile(x)).collect();
            Ok((0..d)
                .map(|i| {
                    let zi: f64 = (0..=i).map(|k| l[i][k] * z[k]).sum();
                    normal_cdf(zi).clamp(f64::MIN_POSITIVE, hi)
                })
                .collect())
        })
        .collect()
}

/// Standard deviations and correlation matrix of a covariance matrix (which must be symmetric
/// positive definite).
pub fn covariance_to_correlation(cov: &[Vec<f64>]) -> Result<(Vec<f64>, Vec<Vec<f64>>), String> {
    let n = cov.len();
    let mut sd = Vec::with_capacity(n);
    for (i, row) in cov.iter().enumerate() {
        if row.len() != n {
            return Err(format!(
                "covariance row [{i}] has {} entries, needs {n}",
                row.len()
            ));
        }
        let v = row[i];
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("covariance [{i}][{i}] = {v}: a variance must be > 0"));
        }
        sd.push(v.sqrt());
    }
    let corr: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i == j { 1.0 } else { cov[i][j] / (sd[i] * sd[j]) })
                .collect()
        })
        .collect();
    check_correlation(&corr).map_err(|e| format!("covariance: {e}"))?;
    Ok((sd, corr))
}

#[cfg(test)]
mod tests {
    use super::super::lowdisc::sobol_points;
    use super::*;

    #[test]
    fn bad_matrices_are_refused_naming_the_entry() {
        let m = |v: &[&[f64]]| v.iter().map(|r| r.to_vec()).collect::<Vec<_>>();
        let cases: [(Vec<Vec<f64>>, &str); 5] = [
            (m(&[&[1.0, 0.5], &[0.4, 1.0]]), "[0][1] = 0.5 but [1][0] = 0.4"),
            (m(&[&[1.0, 1.5], &[1.5, 1.0]]), "[0][1] = 1.5: must be in [-1, 1]"),
            (
                m(&[&[0.9, 0.0], &[0.0, 1.0]]),
                "[0][0] = 0.9: the diagonal must be 1",
            ),
            (
                m(&[&[1.0, 0.9, -0.9], &[0.9, 1.0, 0.9], &[-0.9, 0.9, 1.0]]),
                "not positive definite",
            ),
            (m(&[&[1.0, 0.0], &[0.0]]), "row [1] has 1 entries"),
        ];
        for (c, want) in cases {
            let e = check_correlation(&c).unwrap_err();
            assert!(e.contains(want), "{c:?}: {e}");
        }
        check_correlation(&m(&[&[1.0, 0.3], &[0.3, 1.0]])).unwrap();
    }

    #[test]
    fn iman_conover_reaches_the_target_rank_correlation() {
        let target = vec![vec![1.0, 0.7, -0.3], vec![0.7, 1.0, 0.0], vec![-0.3, 0.0, 1.0]];
        let mut s = sobol_points(1024, 3, Some(3)).unwrap();
        let before: Vec<Vec<f64>> = s.clone();
        rank_correlate(&mut s, &target).unwrap();
        let r = spearman(&s);
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (r[i][j] - target[i][j]).abs() < 0.03,
                    "[{i}][{j}]: {} vs {}",
                    r[i][j],
                    target[i][j]
                );
            }
            // Marginals unchanged: the same values in each column.
            let mut a: Vec<f64> = before.iter().map(|x| x[i]).collect();
            let mut b: Vec<f64> = s.iter().map(|x| x[i]).collect();
            a.sort_by(f64::total_cmp);
            b.sort_by(f64::total_cmp);
            assert_eq!(a, b);
        }
    }

    #[test]
    fn gaussian_copula_gives_the_normal_correlation() {
        let c = vec![vec![1.0, 0.6], vec![0.6, 1.0]];
        let u = sobol_points(4096, 2, Some(11)).unwrap();
        let v = gaussian_copula(&u, &c).unwrap();
        let z: Vec<Vec<f64>> = v
            .iter()
            .map(|r| r.iter().map(|&x| normal_quantile(x)).collect())
            .collect();
        let p = pearson(&z);
        assert!((p[0][1] - 0.6).abs() < 0.01, "{}", p[0][1]);
        let (sd, corr) = covariance_to_correlation(&[vec![4.0, 1.2], vec![1.2, 1.0]]).unwrap();
        assert_eq!(sd, vec![2.0, 1.0]);
        assert!((corr[0][1] - 0.6).abs() < 1e-15);
    }
}
