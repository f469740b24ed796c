//! The involute function, its inverse, and small numerical helpers shared by the geometry
//! module (Gauss–Legendre quadrature, bracketed root finding).

use std::f64::consts::FRAC_PI_2;

/// Taylor coefficients of `tan φ − φ` (φ³, φ⁵, …, φ²¹), i.e. `2^{2n}(2^{2n}−1)|B_{2n}|/(2n)!`.
const INV_SERIES: [f64; 10] = [
    1.0 / 3.0,
    2.0 / 15.0,
    17.0 / 315.0,
    62.0 / 2835.0,
    1382.0 / 155_925.0,
    21844.0 / 6_081_075.0,
    929_569.0 / 638_512_875.0,
    6_404_582.0 / 10_854_718_875.0,
    443_861_162.0 / 1_856_156_927_625.0,
    18_888_466_084.0 / 194_896_477_400_625.0,
];

/// Involute function `inv φ = tan φ − φ` [std] (φ in rad, |φ| < π/2).
///
/// For |φ| < 0.2 the Taylor series (10 terms, truncation < 1e-17 relative) replaces
/// `tan φ − φ`, whose cancellation would otherwise cost up to `3ε/φ²` relative accuracy.
pub fn inv(a: f64) -> f64 {
    if a.abs() < 0.2 {
        let a2 = a * a;
        let mut sum = 0.0;
        for c in INV_SERIES.iter().rev() {
            sum = sum * a2 + c;
        }
        a * a2 * sum
    } else {
        a.tan() - a
    }
}

/// Inverse of the involute function: the angle φ ∈ (−π/2, π/2) with `inv φ = v` [std].
///
/// Newton's method on `f(φ) = tan φ − φ − v` (f' = tan²φ). For v > 0, f is increasing and
/// convex on [0, π/2), so Newton started to the right of the root converges monotonically. The
/// start `φ0 = min((3v)^(1/3), atan(v + π/2))` is always to the right of the root, because
/// `inv φ ≥ φ³/3` (all Taylor coefficients of tan are positive) and `tan φ = v + φ < v + π/2`.
/// The function is odd, so negative v is handled by symmetry. Non-finite v returns NaN.
pub fn inv_inverse(v: f64) -> f64 {
    if !v.is_finite() {
        return f64::NAN;
    }
    if v == 0.0 {
        return 0.0;
    }
    if v < 0.0 {
        return -inv_inverse(-v);
    }
    let mut a = (3.0 * v).cbrt().min((v + FRAC_PI_2).atan());
    for _ in 0..100 {
        let t = a.tan();
        let f = inv(a) - v;
        let step = f / (t * t);
        let next = a - step;
        // Monotone convergence from the right: a non-decreasing step means we are at
        // machine precision.
        if !(next < a) || step.abs() <= 1e-16 * a {
            return next.min(a);
        }
        a = next;
    }
    a
}

/// Antiderivative of `inv(α_R)·R` with respect to R, where `cos α_R = r_b / R` (R ≥ r_b) [derived]:
///
/// `∫ inv(α_R) R dR = (R² − r_b²)^{3/2}/(3 r_b) − α_R R²/2 + r_b √(R² − r_b²)/2`.
///
/// Derivation: `tan α_R = √(R² − r_b²)/r_b` gives the first term directly; for `∫ α_R R dR`
/// integrate by parts with `dα_R/dR = r_b/(R √(R² − r_b²))`.
pub(crate) fn inv_r_antiderivative(r: f64, rb: f64) -> f64 {
    let q = (r * r - rb * rb).max(0.0);
    let sq = q.sqrt();
    let alpha = (rb / r).clamp(-1.0, 1.0).acos();
    q * sq / (3.0 * rb) - alpha * r * r / 2.0 + rb * sq / 2.0
}

/// Pressure angle on a circle of radius `r` of an involute with base radius `rb` (r ≥ rb;
/// clamped to 0 below the base circle).
pub(crate) fn pressure_angle_at(r: f64, rb: f64) -> f64 {
    (rb / r).clamp(-1.0, 1.0).acos()
}

/// 20-point Gauss–Legendre nodes on [−1, 1] (positive half; symmetric) and weights.
const GL_X: [f64; 10] = [
    0.076_526_521_133_497_33,
    0.227_785_851_141_645_08,
    0.373_706_088_715_419_56,
    0.510_867_001_950_827_1,
    0.636_053_680_726_515,
    0.746_331_906_460_150_8,
    0.839_116_971_822_218_8,
    0.912_234_428_251_326,
    0.963_971_927_277_913_8,
    0.993_128_599_185_094_9,
];
const GL_W: [f64; 10] = [
    0.152_753_387_130_725_85,
    0.149_172_986_472_603_75,
    0.142_096_109_318_382_05,
    0.131_688_638_449_176_63,
    0.118_194_531_961_518_42,
    0.101_930_119_817_240_44,
    0.083_276_741_576_704_75,
    0.062_672_048_334_109_06,
    0.040_601_429_800_386_94,
    0.017_614_007_139_152_12,
];

/// ∫_a^b f(x) dx by composite 20-point Gauss–Legendre on `panels` equal panels.
pub(crate) fn gauss_legendre<F: Fn(f64) -> f64>(f: F, a: f64, b: f64, panels: usize) -> f64 {
    let n = panels.max(1);
    let h = (b - a) / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        let c = a + (i as f64 + 0.5) * h;
        let half = 0.5 * h;
        for (x, w) in GL_X.iter().zip(GL_W.iter()) {
            sum += w * (f(c - half * x) + f(c + half * x));
        }
    }
    sum * 0.5 * h
}

/// Root of `f` on [a, b] by bisection (f(a), f(b) of opposite sign or zero), to the last bit.
/// Returns the midpoint of the final bracket. Precondition (caller): a bracket exists.
pub(crate) fn bisect<F: Fn(f64) -> f64>(f: F, mut a: f64, mut b: f64) -> f64 {
    let mut fa = f(a);
    if fa == 0.0 {
        return a;
    }
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a.min(b) || m >= a.max(b) {
            break;
        }
        let fm = f(m);
        if fm == 0.0 {
            return m;
        }
        if (fm < 0.0) == (fa < 0.0) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn inv_known_value_and_series_branch() {
        // inv 20° = 0.014904383867336446 (tables)
        assert_relative_eq!(
            inv(20f64.to_radians()),
            0.014_904_383_867_336_446,
            max_relative = 1e-14
        );
        // series and closed form agree at the switch point
        for a in [0.1999f64, 0.2, 0.2001] {
            let direct = a.tan() - a;
            assert_relative_eq!(inv(a), direct, max_relative = 1e-14);
        }
        // tiny angles: leading term
        assert_relative_eq!(inv(1e-6), 1e-18 / 3.0, max_relative = 1e-12);
        assert_eq!(inv(-0.3), -inv(0.3));
    }

    #[test]
    fn inverse_round_trip() {
        let mut a = 1e-4;
        while a < 1.55 {
            let back = inv_inverse(inv(a));
            assert_relative_eq!(back, a, max_relative = 1e-13);
            a *= 1.07;
        }
        assert_relative_eq!(inv_inverse(inv(-0.4)), -0.4, max_relative = 1e-14);
        // large argument
        let v = 100.0;
        assert_relative_eq!(inv(inv_inverse(v)), v, max_relative = 1e-12);
        assert_eq!(inv_inverse(0.0), 0.0);
        assert!(inv_inverse(f64::NAN).is_nan());
    }

    #[test]
    fn involute_integral_matches_quadrature() {
        let rb = 0.0338;
        let (r1, r2) = (0.034, 0.0412);
        let exact = inv_r_antiderivative(r2, rb) - inv_r_antiderivative(r1, rb);
        let num = gauss_legendre(|r| inv(pressure_angle_at(r, rb)) * r, r1, r2, 8);
        assert_relative_eq!(exact, num, max_relative = 1e-12);
    }

    #[test]
    fn gauss_legendre_is_exact_for_degree_39() {
        for k in [0, 1, 7, 20, 39] {
            let num = gauss_legendre(|x| x.powi(k), 0.0, 1.0, 1);
            assert_relative_eq!(num, 1.0 / f64::from(k + 1), max_relative = 1e-13);
        }
    }

    #[test]
    fn bisect_finds_root() {
        let r = bisect(|x| x * x - 2.0, 0.0, 2.0);
        assert_relative_eq!(r, 2f64.sqrt(), max_relative = 1e-15);
    }
}
