//! First-order loss vs seed 003's moment-balance sliding-loss ratio (physics.md §7).
//!
//! **Derivation \[derived\].** One tooth pair at distance s from the pitch point (n = s/(r_b1 tan α_wt)),
//! normal force F (inclined by β_b in the plane of action), friction μF perpendicular to the plane
//! of action with lever arm ρ1 = r_b1 tan α_wt (1 + n) about gear 1. Moment balance of gear 1:
//! `T1 = F·(r_b1 cos β_b + κ μ ρ1)`, κ = sign(v_1t − v_2t) if gear 1 drives, −sign(v_1t − v_2t)
//! if it is driven (friction on gear 1 opposes its surface's relative sliding). The friction power
//! is `P = μ F v_g`, v_g = |s| ω_rel, ω_rel = ω1 + ω2 (external), |ω1 − ω2| (internal). Hence,
//! holding T1 fixed, `P = μ F0 v_g / (1 + κ μ ρ1/(r_b1 cos β_b))` with F0 = T1/(r_b1 cos β_b) the
//! frictionless normal force; the ratio to P_in = T1 ω1 is
//!
//! `φ = μ |n| tan α_wt (ω_rel/ω1) / (cos β_b + κ μ tan α_wt (1 + n))`.
//!
//! For a driving gear 1 on the approach side (n < 0, v_1t < v_2t, κ = −1), spur, external,
//! ω_rel/ω1 = 1 + 1/u, this is exactly seed 003's ratio (flow chart, fig. 4.1 step 5):
//! `φ = −n tan α μ (1 + 1/u)/(1 − (n + 1) tan α μ)`. The seed writes only this branch (its literal
//! form is negative for n > 0); on the recess side the same balance gives the denominator
//! `1 + (n + 1) tan α μ`. Both branches differ from the first-order `φ = μ |n| tan α (1 + 1/u)`
//! by O(μ²).

/// How the friction power of a contact element is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LossForm {
    /// `P_k = μ_k F_k v_g,k` with F_k from the frictionless moment balance [std].
    #[default]
    FirstOrder,
    /// Seed 003's moment-balance ratio: each element carries its share of T1 including its friction
    /// moment, `P_k = μ_k F_k v_g,k / (1 + κ μ_k ρ1/(r_b1 cos β_b))` [seed 003, derived above].
    MomentBalance,
}

/// Smallest admissible value of the moment-balance denominator `1 + κ μ ρ1/(r_b1 cos β_b)`.
/// It only binds for μ·tan α_wt(1 + n) close to 1 (self-locking, far outside gear practice).
pub const MIN_MOMENT_DENOMINATOR: f64 = 0.05;

/// Moment-balance correction factor `1/(1 + κ μ ρ1/(r_b1 cos β_b))`; `rho1_ratio` = ρ1/(r_b1 cos β_b).
#[inline]
pub fn correction_factor(mu: f64, kappa: f64, rho1_ratio: f64) -> f64 {
    1.0 / (1.0 + kappa * mu * rho1_ratio).max(MIN_MOMENT_DENOMINATOR)
}

/// First-order sliding-loss ratio of one pair carrying all of T1:
/// `φ = μ |n| tan α_wt (ω_rel/ω1)/cos β_b` [std].
pub fn first_order_ratio(n: f64, tan_alpha: f64, mu: f64, speed_ratio: f64, cos_beta_b: f64) -> f64 {
    mu * n.abs() * tan_alpha * speed_ratio / cos_beta_b
}

/// Moment-balance sliding-loss ratio of one pair carrying all of T1 (module doc):
/// `φ = μ |n| tan α_wt (ω_rel/ω1)/(cos β_b + κ μ tan α_wt (1 + n))`.
/// `speed_ratio` = ω_rel/ω1 (1 + 1/u external, 1 − 1/u internal), `kappa` ∈ {−1, 0, 1}.
pub fn moment_balance_ratio(
    n: f64,
    tan_alpha: f64,
    mu: f64,
    speed_ratio: f64,
    cos_beta_b: f64,
    kappa: f64,
) -> f64 {
    let den = (cos_beta_b + kappa * mu * tan_alpha * (1.0 + n)).max(MIN_MOMENT_DENOMINATOR * cos_beta_b);
    mu * n.abs() * tan_alpha * speed_ratio / den
}

/// Seed 003's ratio, literally (fig. 4.1 step 5, spur, external): `φ = −n tan α μ (1 + 1/u)/(1 − (n + 1) tan α μ)`.
/// Meaningful for the approach side n ≤ 0 of a driving gear 1 (negative for n > 0).
pub fn seed_ratio(n: f64, tan_alpha: f64, mu: f64, u: f64) -> f64 {
    -n * tan_alpha * mu * (1.0 + 1.0 / u) / (1.0 - (n + 1.0) * tan_alpha * mu)
}

/// κ for gear 1 driving (`drive1 = true`) or driven: sign(v_1t − v_2t) = sign(s)·sign(ω_rel,signed),
/// flipped when gear 1 is driven.
#[inline]
pub fn kappa(sign_s: f64, sign_rel: f64, drive1: bool) -> f64 {
    let k = sign_s * sign_rel;
    if drive1 {
        k
    } else {
        -k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_equals_seed_on_approach_side() {
        let ta = 20f64.to_radians().tan();
        for &n in &[-0.48, -0.3, -0.1, -0.01] {
            for &mu in &[0.02, 0.06, 0.1] {
                let seed = seed_ratio(n, ta, mu, 1.0);
                let mb = moment_balance_ratio(n, ta, mu, 2.0, 1.0, -1.0);
                assert!((seed - mb).abs() < 1e-15 * (1.0 + seed.abs()), "n={n} mu={mu}");
            }
        }
    }

    #[test]
    fn first_order_and_moment_balance_agree_to_mu_squared() {
        let ta = 20f64.to_radians().tan();
        for &(n, kap) in &[
            (-0.48_f64, -1.0_f64),
            (-0.2, -1.0),
            (0.24, 1.0),
            (0.48, 1.0),
            (0.3, -1.0),
        ] {
            for &cb in &[1.0, 33.5f64.to_radians().cos()] {
                // analytic limit of (φ_MB − φ_FO)/μ² as μ → 0
                let limit = -kap * n.abs() * ta * ta * 2.0 * (1.0 + n) / (cb * cb);
                let mut last = f64::NAN;
                for &mu in &[1e-2, 1e-3, 1e-4, 1e-5] {
                    let d = (moment_balance_ratio(n, ta, mu, 2.0, cb, kap)
                        - first_order_ratio(n, ta, mu, 2.0, cb))
                        / (mu * mu);
                    assert!(d.is_finite() && d.abs() < 10.0, "bounded: {d}");
                    last = d;
                }
                assert!(
                    (last - limit).abs() < 1e-3 * limit.abs().max(1e-3),
                    "{last} vs {limit}"
                );
            }
        }
    }

    #[test]
    fn correction_factor_matches_ratio_form() {
        // φ_MB = φ_FO * correction_factor(μ, κ, ρ1/(r_b1 cos β_b)) with ρ1/r_b1 = tan α (1 + n)
        let ta = 0.4;
        let (n, mu, cb) = (0.3, 0.07, 0.9);
        for kap in [-1.0, 0.0, 1.0] {
            let lhs = moment_balance_ratio(n, ta, mu, 1.5, cb, kap);
            let rhs = first_order_ratio(n, ta, mu, 1.5, cb) * correction_factor(mu, kap, ta * (1.0 + n) / cb);
            assert!((lhs - rhs).abs() < 1e-15);
        }
    }

    #[test]
    fn kappa_signs() {
        assert_eq!(kappa(-1.0, 1.0, true), -1.0); // approach, gear 1 drives
        assert_eq!(kappa(1.0, 1.0, true), 1.0);
        assert_eq!(kappa(1.0, 1.0, false), -1.0);
    }
}
