//! Correlation and covariance matrices of uncertain inputs: the checks a rank-correlation
//! matrix and a calibration's covariance must pass, and the Cholesky factor both use.

/// Tolerance on the unit diagonal and on symmetry.
const TOL: f64 = 1e-9;

/// Check a correlation matrix: square, symmetric, unit diagonal, entries in [−1, 1], positive
/// definite. The message names the entry as `[i][j]` (0-based row and column) with its value, or
/// says "not positive definite".
pub fn check_correlation(matrix: &[Vec<f64>]) -> Result<(), String> {
    let n = matrix.len();
    if n == 0 {
        return Err("an empty correlation matrix".into());
    }
    for (i, row) in matrix.iter().enumerate() {
        if row.len() != n {
            return Err(format!(
                "row [{i}] has {} entries: a {n}×{n} matrix needs {n}",
                row.len()
            ));
        }
        for (j, &c) in row.iter().enumerate() {
            if !c.is_finite() || !(-1.0..=1.0).contains(&c) {
                return Err(format!("[{i}][{j}] = {c}: must be in [-1, 1]"));
            }
            if i == j && (c - 1.0).abs() > TOL {
                return Err(format!("[{i}][{j}] = {c}: the diagonal must be 1"));
            }
            if (c - matrix[j][i]).abs() > TOL {
                return Err(format!(
                    "[{i}][{j}] = {c} but [{j}][{i}] = {}: the matrix must be symmetric",
                    matrix[j][i]
                ));
            }
        }
    }
    cholesky(matrix).map(|_| ())
}

/// Lower-triangular Cholesky factor L of a symmetric matrix (A = L Lᵀ); "not positive definite"
/// with the failing pivot otherwise.
pub fn cholesky(a: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, String> {
    let n = a.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            if i == j {
                let d = a[i][i] - s;
                // Relative to the diagonal: a pivot lost to rounding is not definite either.
                if d.is_nan() || d <= 1e-12 * a[i][i].abs().max(1e-300) {
                    return Err(format!(
                        "not positive definite (Cholesky pivot {i} is {d:.3e}: the correlations \
                         among the first {} inputs contradict each other)",
                        i + 1
                    ));
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (a[i][j] - s) / l[j][j];
            }
        }
    }
    Ok(l)
}
