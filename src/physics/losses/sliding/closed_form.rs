//! Fast closed form: ISO/TR 14179-2 `P = P_in·μ_mz·H_V` with Ohlendorf's loss factor (physics.md §7).
//!
//! **Ohlendorf [std]:** `H_V = π(u + 1)/(z1·u·cos β_b)·(1 − ε_α + ε1² + ε2²)`, ε1 = CE/p_bt,
//! ε2 = AC/p_bt (addendum contact ratios), valid for ε_α < 2. For an internal mesh u + 1 → u − 1
//! (u = z2/z1 > 0; ISO writes u < 0).
//!
//! **What it is \[derived\]:** with first-order friction, constant μ and 50:50 sharing, the mesh
//! loss over one base pitch is `P/P_in = μ (1 ± 1/u)/(r_b1 cos β_b)·(1/p_bt)·∫_A^E |s|·LS(s) ds`.
//! With F(x) = sign(x)x²/2 (units of p_bt) and A = −ε2, B = ε1 − 1, D = 1 − ε2, E = ε1:
//! `∫|s| LS ds / p_bt² = ½[F(E) − F(A) − F(B) + F(D)]`, so
//! `H_V = π(u ± 1)/(z1 u cos β_b)·[F(E) − F(A) − F(B) + F(D)]`.
//! For 0 ≤ ε1, ε2 ≤ 1 (pitch point in single contact) the bracket is exactly
//! `1 − ε_α + ε1² + ε2²` (Ohlendorf). Outside that range Ohlendorf's polynomial is not the 50:50
//! integral any more; [`uniform_sharing_hv`] is the general form.
//!
//! **Helical gears \[derived\]:** in a helical mesh with the load spread uniformly along all contact
//! lines (no per-slice 50:50 sharing: a slice in single contact carries the same line load as each
//! pair of a slice in double contact), and a constant total line length (ε_β integer), the same
//! integral gives `H_V,hel = π(u ± 1)/(z1 u cos β_b)·(sign(ε1)ε1² + sign(ε2)ε2²)/ε_α`
//! ([`uniform_line_load_hv`]). For the seed 003 gear (ε1 = ε2 = 0.827) it is 16 % above Ohlendorf's
//! value. Ohlendorf's factor treats each transverse slice of a helical gear as a spur gear with
//! 50:50 sharing; it is the limit of the helical model for ε_β → 0, not for ε_β ≥ 1.

use super::SlidingError;

/// F(x) = sign(x)·x²/2 = ∫_0^x |t| dt.
fn f_abs(x: f64) -> f64 {
    0.5 * x * x.abs()
}

/// Speed factor (u ± 1)/u: 1 + 1/u external, 1 − 1/u internal.
fn speed_factor(u: f64, internal: bool) -> f64 {
    if internal {
        1.0 - 1.0 / u
    } else {
        1.0 + 1.0 / u
    }
}

/// Ohlendorf's H_V (as in ISO/TR 14179-2). Requires 1 ≤ ε_α < 2 and 0 ≤ ε1, ε2 ≤ 1
/// (where it equals the 50:50 integral; see the module doc).
pub fn ohlendorf_hv(
    u: f64,
    z1: f64,
    cos_beta_b: f64,
    eps1: f64,
    eps2: f64,
    internal: bool,
) -> Result<f64, SlidingError> {
    let ea = eps1 + eps2;
    if !(1.0..2.0).contains(&ea) || !(0.0..=1.0).contains(&eps1) || !(0.0..=1.0).contains(&eps2) {
        return Err(SlidingError::ContactRatio {
            eps_alpha: ea,
            detail: "Ohlendorf's H_V needs 1 <= ε_α < 2 and 0 <= ε1, ε2 <= 1",
        });
    }
    Ok(
        std::f64::consts::PI * speed_factor(u, internal) / (z1 * cos_beta_b)
            * (1.0 - ea + eps1 * eps1 + eps2 * eps2),
    )
}

/// H_V for 50:50 sharing, any 1 ≤ ε_α < 2 and any position of the pitch point (module doc).
pub fn uniform_sharing_hv(u: f64, z1: f64, cos_beta_b: f64, eps1: f64, eps2: f64, internal: bool) -> f64 {
    let bracket = f_abs(eps1) - f_abs(-eps2) - f_abs(eps1 - 1.0) + f_abs(1.0 - eps2);
    std::f64::consts::PI * speed_factor(u, internal) / (z1 * cos_beta_b) * bracket
}

/// H_V of a helical mesh with uniform load along all contact lines and constant total line length
/// (exact for integer ε_β; module doc).
pub fn uniform_line_load_hv(u: f64, z1: f64, cos_beta_b: f64, eps1: f64, eps2: f64, internal: bool) -> f64 {
    let ea = eps1 + eps2;
    let bracket = 2.0 * (f_abs(eps1) - f_abs(-eps2)) / ea;
    std::f64::consts::PI * speed_factor(u, internal) / (z1 * cos_beta_b) * bracket
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn general_form_equals_ohlendorf_in_its_range() {
        for &(e1, e2) in &[(0.8268, 0.8268), (0.9, 0.5), (0.3, 0.99), (1.0, 0.6)] {
            for internal in [false, true] {
                let o = ohlendorf_hv(2.5, 23.0, 0.9, e1, e2, internal).unwrap();
                let g = uniform_sharing_hv(2.5, 23.0, 0.9, e1, e2, internal);
                assert!((o - g).abs() < 1e-15, "{o} {g}");
            }
        }
    }

    #[test]
    fn ohlendorf_range_checked() {
        assert!(ohlendorf_hv(1.0, 30.0, 1.0, 1.1, 0.6, false).is_err()); // ε1 > 1
        assert!(ohlendorf_hv(1.0, 30.0, 1.0, 0.4, 0.4, false).is_err()); // ε_α < 1
        assert!(ohlendorf_hv(1.0, 30.0, 1.0, 1.0, 1.0, false).is_err()); // ε_α = 2
                                                                         // outside the range the general form differs from the polynomial
        let (e1, e2) = (1.2, 0.5);
        let poly = std::f64::consts::PI * 2.0 / 30.0 * (1.0 - 1.7 + e1 * e1 + e2 * e2);
        assert!((uniform_sharing_hv(1.0, 30.0, 1.0, e1, e2, false) - poly).abs() > 1e-3);
    }

    #[test]
    fn helical_uniform_line_load_vs_ohlendorf_seed003() {
        let (e1, e2) = (0.82675, 0.82675);
        let h = uniform_line_load_hv(1.0, 30.0, 1.0, e1, e2, false);
        let o = ohlendorf_hv(1.0, 30.0, 1.0, e1, e2, false).unwrap();
        assert!((h / o - 1.1585).abs() < 2e-3, "{}", h / o);
    }
}
