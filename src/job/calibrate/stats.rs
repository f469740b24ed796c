//! What the fit's Jacobian says about the fitted values: covariance (JᵀJ)⁻¹·σ², 95 % intervals
//! through Student's t quantile, the correlation matrix (Seber & Wild, Nonlinear Regression,
//! 1989, §2.1: the linearised intervals of a least-squares fit).

use nalgebra::DMatrix;

/// Student's t density's normalising constant Γ((ν+1)/2) / (√(νπ)·Γ(ν/2)), from the
/// recurrence r(ν+1) = (ν/2)/r(ν) of r(ν) = Γ((ν+1)/2)/Γ(ν/2), r(1) = 1/√π.
fn t_norm(nu: usize) -> f64 {
    let mut r = 1.0 / std::f64::consts::PI.sqrt();
    for k in 1..nu {
        r = (k as f64 / 2.0) / r;
    }
    r / (nu as f64 * std::f64::consts::PI).sqrt()
}

/// P(|T| < x) for Student's t with ν degrees of freedom: twice the density's integral over
/// [0, x] (composite Simpson rule, 4000 intervals).
fn t_central(x: f64, nu: usize) -> f64 {
    let c = t_norm(nu);
    let n = 4000;
    let h = x / n as f64;
    let pdf = |u: f64| c * (1.0 + u * u / nu as f64).powf(-(nu as f64 + 1.0) / 2.0);
    let mut s = pdf(0.0) + pdf(x);
    for k in 1..n {
        s += pdf(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    2.0 * s * h / 3.0
}

/// The two-sided 95 % quantile t(0.975, ν) (bisection on [`t_central`]); above 10⁵ degrees of
/// freedom the normal quantile's value at that ν is used.
pub fn t975(dof: usize) -> f64 {
    let nu = dof.clamp(1, 100_000);
    let (mut lo, mut hi) = (0.0, 50.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if t_central(mid, nu) < 0.95 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Relative eigenvalue λ/λ_max of the scaled information below which a direction is not
/// determined at all: the sensitivities are accurate to about 10⁻⁶ relative
/// (docs/calibration.md), so singular values below √(10⁻⁹) ≈ 3·10⁻⁵ of the largest cannot be
/// told from zero.
pub const NULL_EIGENVALUE: f64 = 1e-9;
/// A parameter takes part in a direction whose component (the direction scaled to its largest
/// component 1) exceeds this.
pub const INVOLVED: f64 = 0.05;

/// An eigen-direction of the scaled information, in the fitted coordinates.
#[derive(Debug, Clone)]
pub struct EigenDirection {
    /// λ/λ_max of the scaled information DᵀJᵀJD⁻¹ (D = diag(√(JᵀJ)_kk)).
    pub relative_eigenvalue: f64,
    /// The direction v in the fitted coordinates (one per parameter, 0 for a parameter left out),
    /// its largest component ±1.
    pub direction: Vec<f64>,
    /// Standard error of the step s along v (θ = θ̂ + s·v); None for a null direction.
    pub std_error: Option<f64>,
}

/// Covariance, correlation and standard errors of the fitted coordinates.
#[derive(Debug, Clone)]
pub struct Linearised {
    /// σ² = SSR / (m − P), K².
    pub sigma2: f64,
    /// Degrees of freedom m − P.
    pub dof: usize,
    /// Standard error of each coordinate (None: not identifiable).
    pub std_err: Vec<Option<f64>>,
    /// Correlation matrix (NaN where undefined).
    pub correlation: Vec<Vec<f64>>,
    /// Covariance of the fitted coordinates (NaN where undefined).
    pub covariance: Vec<Vec<f64>>,
    /// Eigen-directions of the scaled information, least determined first.
    pub directions: Vec<EigenDirection>,
    /// Per parameter: takes part in a null direction (the data do not fix it).
    pub in_null: Vec<bool>,
    /// √(JᵀJ)_kk per parameter (0 for one left out).
    pub scale: Vec<f64>,
}

/// Linearised statistics from the residuals' Jacobian `j` (m × P) and sum of squares `ssr`;
/// `lost` degrees of freedom go to the residual model's own parameters.
/// Parameters not `identifiable` (no influence, at a bound) are left out. The covariance is the
/// pseudo-inverse σ²·D⁻¹(Σ u uᵀ/λ)D⁻¹ over the eigenpairs (λ, u) of the scaled information
/// above [`NULL_EIGENVALUE`]: a parameter that takes part in a null direction gets no standard
/// error, the others their variance across it.
pub fn linearised(j: &DMatrix<f64>, ssr: f64, identifiable: &[bool], lost: usize) -> Linearised {
    let (m, p) = j.shape();
    let keep: Vec<usize> = (0..p).filter(|&k| identifiable[k]).collect();
    let dof = m.saturating_sub(keep.len() + lost).max(1);
    let sigma2 = ssr / dof as f64;
    let jk = DMatrix::from_fn(m, keep.len(), |r, c| j[(r, keep[c])]);
    let a = jk.transpose() * &jk;
    let d: Vec<f64> = (0..keep.len()).map(|k| a[(k, k)].max(0.0).sqrt()).collect();
    let mut out = Linearised {
        sigma2,
        dof,
        std_err: vec![None; p],
        correlation: vec![vec![f64::NAN; p]; p],
        covariance: vec![vec![f64::NAN; p]; p],
        directions: Vec::new(),
        in_null: vec![false; p],
        scale: vec![0.0; p],
    };
    for (c, &k) in keep.iter().enumerate() {
        out.scale[k] = d[c];
    }
    if keep.is_empty() || d.iter().any(|&x| !(x > 0.0 && x.is_finite())) {
        return out;
    }
    let s = DMatrix::from_fn(keep.len(), keep.len(), |r, c| a[(r, c)] / (d[r] * d[c]));
    let eig = s.symmetric_eigen();
    let lmax = eig.eigenvalues.iter().fold(0.0_f64, |x, &y| x.max(y));
    let mut pinv = DMatrix::zeros(keep.len(), keep.len());
    let mut order: Vec<usize> = (0..keep.len()).collect();
    order.sort_by(|&x, &y| eig.eigenvalues[x].total_cmp(&eig.eigenvalues[y]));
    for &i in &order {
        let (lam, u) = (eig.eigenvalues[i], eig.eigenvectors.column(i));
        let rel = if lmax > 0.0 { lam / lmax } else { 0.0 };
        let v: Vec<f64> = (0..keep.len()).map(|k| u[k] / d[k]).collect();
        let vmax = v.iter().fold(0.0_f64, |x, y| x.max(y.abs()));
        let null = rel.is_nan() || rel <= NULL_EIGENVALUE;
        let mut direction = vec![0.0; p];
        for (c, &k) in keep.iter().enumerate() {
            direction[k] = v[c] / vmax;
            if null && (v[c] / vmax).abs() > INVOLVED {
                out.in_null[k] = true;
            }
        }
        if !null {
            pinv += (u * u.transpose()) / lam;
        }
        out.directions.push(EigenDirection {
            relative_eigenvalue: rel.max(0.0),
            direction,
            std_error: (!null).then(|| (sigma2 / lam).sqrt() * vmax),
        });
    }
    for (x, &kx) in keep.iter().enumerate() {
        for (y, &ky) in keep.iter().enumerate() {
            out.covariance[kx][ky] = sigma2 * pinv[(x, y)] / (d[x] * d[y]);
        }
    }
    for &kx in &keep {
        if !out.in_null[kx] {
            out.std_err[kx] = Some(out.covariance[kx][kx].max(0.0).sqrt());
        }
    }
    for &kx in &keep {
        for &ky in &keep {
            let v = out.covariance[kx][kx] * out.covariance[ky][ky];
            if !out.in_null[kx] && !out.in_null[ky] && v > 0.0 {
                out.correlation[kx][ky] = out.covariance[kx][ky] / v.sqrt();
            }
        }
    }
    out
}

/// The sandwich covariance of the least-squares estimate when the residuals have covariance
/// Σ instead of σ²I (Seber & Wild, Nonlinear Regression, 1989, §2.1.4 and §6.1):
/// Cov = A⁺(JᵀΣJ)A⁺, A⁺ the pseudo-inverse of JᵀJ of `lin` (its covariance over σ²), `b` =
/// JᵀΣJ. The standard errors, correlations and the directions' standard errors follow.
pub fn sandwich(lin: &mut Linearised, b: &DMatrix<f64>) {
    let p = lin.covariance.len();
    let kept: Vec<usize> = (0..p).filter(|&k| lin.scale[k] > 0.0).collect();
    if kept.is_empty() || lin.sigma2.is_nan() || lin.sigma2 <= 0.0 {
        return;
    }
    let ap = DMatrix::from_fn(kept.len(), kept.len(), |x, y| {
        lin.covariance[kept[x]][kept[y]] / lin.sigma2
    });
    let bk = DMatrix::from_fn(kept.len(), kept.len(), |x, y| b[(kept[x], kept[y])]);
    let cov = &ap * bk * &ap;
    for (x, &kx) in kept.iter().enumerate() {
        for (y, &ky) in kept.iter().enumerate() {
            lin.covariance[kx][ky] = cov[(x, y)];
        }
    }
    for &kx in &kept {
        if !lin.in_null[kx] {
            lin.std_err[kx] = Some(lin.covariance[kx][kx].max(0.0).sqrt());
        }
        for &ky in &kept {
            let v = lin.covariance[kx][kx] * lin.covariance[ky][ky];
            if !lin.in_null[kx] && !lin.in_null[ky] && v > 0.0 {
                lin.correlation[kx][ky] = lin.covariance[kx][ky] / v.sqrt();
            }
        }
    }
    // The step s along v = D⁻¹u/max|D⁻¹u| is s = max|D⁻¹u|·uᵀDθ = w·θ with w = max²·D²v.
    for d in lin.directions.iter_mut().filter(|d| d.std_error.is_some()) {
        let vmax2 = 1.0
            / kept
                .iter()
                .map(|&k| (d.direction[k] * lin.scale[k]).powi(2))
                .sum::<f64>();
        let w: Vec<f64> = (0..p)
            .map(|k| vmax2 * lin.scale[k].powi(2) * d.direction[k])
            .collect();
        let mut v = 0.0;
        for &kx in &kept {
            for &ky in &kept {
                v += w[kx] * lin.covariance[kx][ky] * w[ky];
            }
        }
        d.std_error = Some(v.max(0.0).sqrt());
    }
}

/// The posterior covariance (I_data + I_prior)⁻¹ replaces the data's: I_data is the
/// pseudo-inverse of `lin`'s covariance over its identifiable parameters, `prior` the prior
/// information per parameter (0 without a prior). Scaled by D = diag √(I)_kk and inverted over
/// the eigenpairs above [`NULL_EIGENVALUE`], as in [`linearised`]; a parameter in a direction
/// neither data nor prior fix keeps no standard error. Parameters left out of `lin` (no
/// influence, at a bound) stay out.
pub fn posterior(lin: &mut Linearised, prior: &[f64]) {
    let p = lin.covariance.len();
    let kept: Vec<usize> = (0..p).filter(|&k| lin.scale[k] > 0.0).collect();
    if kept.is_empty() {
        return;
    }
    let n = kept.len();
    let cov = DMatrix::from_fn(n, n, |x, y| {
        let v = lin.covariance[kept[x]][kept[y]];
        if v.is_finite() {
            v
        } else {
            0.0
        }
    });
    let mut info = pseudo_inverse(&cov);
    for (x, &k) in kept.iter().enumerate() {
        info[(x, x)] += prior[k];
    }
    let d: Vec<f64> = (0..n).map(|k| info[(k, k)].max(0.0).sqrt()).collect();
    let mut in_null = vec![false; n];
    let mut pinv = DMatrix::zeros(n, n);
    let live: Vec<usize> = (0..n).filter(|&k| d[k] > 0.0).collect();
    for &k in &(0..n).filter(|k| !live.contains(k)).collect::<Vec<_>>() {
        in_null[k] = true;
    }
    let s = DMatrix::from_fn(live.len(), live.len(), |x, y| {
        info[(live[x], live[y])] / (d[live[x]] * d[live[y]])
    });
    let eig = s.symmetric_eigen();
    let lmax = eig.eigenvalues.iter().fold(0.0_f64, |a, &b| a.max(b));
    for i in 0..live.len() {
        let (lam, u) = (eig.eigenvalues[i], eig.eigenvectors.column(i));
        if lmax > 0.0 && lam / lmax > NULL_EIGENVALUE {
            let m = (u * u.transpose()) / lam;
            for x in 0..live.len() {
                for y in 0..live.len() {
                    pinv[(live[x], live[y])] += m[(x, y)] / (d[live[x]] * d[live[y]]);
                }
            }
        } else {
            let umax = u.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            for x in 0..live.len() {
                if (u[x] / umax).abs() > INVOLVED {
                    in_null[live[x]] = true;
                }
            }
        }
    }
    for (x, &kx) in kept.iter().enumerate() {
        lin.in_null[kx] = in_null[x];
        for (y, &ky) in kept.iter().enumerate() {
            lin.covariance[kx][ky] = pinv[(x, y)];
        }
    }
    for &kx in &kept {
        lin.std_err[kx] = (!lin.in_null[kx]).then(|| lin.covariance[kx][kx].max(0.0).sqrt());
        for &ky in &kept {
            let v = lin.covariance[kx][kx] * lin.covariance[ky][ky];
            lin.correlation[kx][ky] = if !lin.in_null[kx] && !lin.in_null[ky] && v > 0.0 {
                lin.covariance[kx][ky] / v.sqrt()
            } else {
                f64::NAN
            };
        }
    }
}

/// Pseudo-inverse of a symmetric positive semi-definite matrix (eigenvalues above 10⁻¹² of the
/// largest; scaled by its diagonal first).
fn pseudo_inverse(a: &DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    let d: Vec<f64> = (0..n)
        .map(|k| {
            let v = a[(k, k)].max(0.0).sqrt();
            if v > 0.0 {
                v
            } else {
                1.0
            }
        })
        .collect();
    let s = DMatrix::from_fn(n, n, |x, y| a[(x, y)] / (d[x] * d[y]));
    let eig = s.symmetric_eigen();
    let lmax = eig.eigenvalues.iter().fold(0.0_f64, |x, &y| x.max(y));
    let mut out = DMatrix::zeros(n, n);
    for i in 0..n {
        let lam = eig.eigenvalues[i];
        if lmax > 0.0 && lam > 1e-12 * lmax {
            let u = eig.eigenvectors.column(i);
            out += (u * u.transpose()) / lam;
        }
    }
    DMatrix::from_fn(n, n, |x, y| out[(x, y)] / (d[x] * d[y]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles() {
        // P(|T| < t975) = 0.95 by construction; check the density integrates to 1 and the
        // limits: ν = 1 is the Cauchy distribution, t = tan(0.475π); ν large → 1.95996.
        assert!((t975(1) - (0.475 * std::f64::consts::PI).tan()).abs() < 1e-3);
        assert!((t975(100_000) - 1.959_964).abs() < 1e-3);
        assert!(t975(5) > t975(30) && t975(30) > t975(1000));
        // ν = 2 has the closed form t = q·√(2/(1 − q²)) with q = 0.95.
        let q: f64 = 0.95;
        assert!((t975(2) - q * (2.0 / (1.0 - q * q)).sqrt()).abs() < 1e-6);
    }

    #[test]
    fn straight_line_intervals() {
        // y = a + b·x: Cov = σ²(XᵀX)⁻¹, checked against the closed form of simple regression.
        let x: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let j = DMatrix::from_fn(10, 2, |r, c| if c == 0 { 1.0 } else { x[r] });
        let l = linearised(&j, 8.0, &[true, true], 0);
        let sxx: f64 = x.iter().map(|v| (v - 4.5).powi(2)).sum();
        assert!((l.sigma2 - 1.0).abs() < 1e-12);
        assert!((l.std_err[1].unwrap() - (1.0 / sxx).sqrt()).abs() < 1e-12);
        let r = l.correlation[0][1];
        assert!((r - (-4.5 / (sxx / 10.0 + 20.25).sqrt())).abs() < 1e-9, "{r}");
        let l = linearised(&j, 8.0, &[true, false], 0);
        assert!(l.std_err[1].is_none() && l.std_err[0].is_some());
    }

    #[test]
    fn a_null_direction_is_named() {
        // y = (a + b)·x + c: a and b enter only as their sum; c is determined.
        let x: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let j = DMatrix::from_fn(10, 3, |r, c| if c < 2 { x[r] } else { 1.0 });
        let l = linearised(&j, 8.0, &[true, true, true], 0);
        assert!(l.in_null[0] && l.in_null[1] && !l.in_null[2], "{:?}", l.in_null);
        assert!(l.std_err[0].is_none() && l.std_err[1].is_none());
        let se = l.std_err[2].unwrap();
        // c's standard error is that of the intercept of y = s·x + c.
        let sxx: f64 = x.iter().map(|v| (v - 4.5).powi(2)).sum();
        let want = (l.sigma2 * (0.1 + 20.25 / sxx)).sqrt();
        assert!((se - want).abs() < 1e-9 * want, "{se} {want}");
        let n = &l.directions[0];
        assert!(n.std_error.is_none() && n.relative_eigenvalue < 1e-12);
        assert!((n.direction[0] + n.direction[1]).abs() < 1e-9 && n.direction[2].abs() < 1e-9);
    }

    #[test]
    fn posterior_adds_the_prior_information() {
        // Two parameters entering as a sum: the data fix a + b only; a prior of sd 0.5 on a fixes
        // both: Var(a) = 0.25, Var(b) = Var(a + b) + Var(a).
        let x: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let j = DMatrix::from_fn(10, 2, |r, _| x[r]);
        let mut l = linearised(&j, 8.0, &[true, true], 0);
        assert!(l.std_err[0].is_none());
        let sxx: f64 = x.iter().map(|v| v * v).sum();
        posterior(&mut l, &[4.0, 0.0]);
        let var_sum = l.sigma2 / sxx;
        assert!((l.std_err[0].unwrap() - 0.5).abs() < 1e-9, "{:?}", l.std_err);
        assert!((l.std_err[1].unwrap().powi(2) - (0.25 + var_sum)).abs() < 1e-9);
        // A determined parameter: 1/Var_post = 1/Var_data + 1/sd².
        let j = DMatrix::from_fn(10, 1, |r, _| x[r]);
        let mut l = linearised(&j, 8.0, &[true], 0);
        let v = l.covariance[0][0];
        posterior(&mut l, &[1.0 / v]);
        assert!((l.covariance[0][0] - v / 2.0).abs() < 1e-12 * v);
    }
}
