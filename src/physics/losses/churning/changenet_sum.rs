//! The Changenet–Velex churning of one gear summed over its immersions (a fixed-axis gear: one;
//! a planet: the nodes of its orbit average, `scene::planet_churning`), as a law of the oil alone
//! at a fixed speed [derived from the laws in [`super::changenet`]].
//!
//! With L = ln ν (ν in m²/s) and ω fixed:
//! - low law (Re_c ≤ Re_c,low, i.e. L ≥ ln(ω r_p b/Re_c,low)):
//!   `P = ρ ω^(3 + 2a_Fr + a_Re) ν^(−a_Re) Σ_i w_i low_unit_i`;
//! - high law (Re_c ≥ Re_c,high): `P = ρ ω^(3 + 2b_Fr) Σ_i w_i high_unit_i`;
//! - bridge (between): per immersion `ln(P_i/ρ) = a_i + 3 ln ω + 2a_Fr L + t (d_i + 2(b_Fr − a_Fr) L)`,
//!   `t = (ln Re_c − ln Re_c,low)/ln(Re_c,high/Re_c,low)`.
//!
//! The immersions of one gear share r_p, b, the exponents and the regime limits, so the sums
//! over i are made once per scene, the powers of ω once per drive-cycle sample
//! ([`ChangenetSum::at_speed`]: one logarithm, two exponentials), and each right-hand side of the
//! sample pays one exponential (low law), none (high law) or one per immersion (bridge). The
//! values are [`ChangenetGear::power`]'s to rounding (test below).

use super::changenet::ChangenetGear;

/// Σ_i w_i P_i over immersions of one gear, precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct ChangenetSum {
    low_unit: f64,
    low_speed_exp: f64,
    low_nu_exp: f64,
    high_unit: f64,
    high_speed_exp: f64,
    ln_rp_b: f64,
    ln_re_c_low: f64,
    ln_re_c_high: f64,
    inv_ln_span: f64,
    /// 2 a_Fr and 2 (b_Fr − a_Fr): the bridge's ν exponents.
    bridge_nu: [f64; 2],
    /// Per wet immersion: (w_i, a_i, d_i).
    bridge: Vec<(f64, f64, f64)>,
}

/// A [`ChangenetSum`] at one speed: what the right-hand sides of a sample share.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChangenetAtSpeed {
    /// ln ω.
    pub ln_w: f64,
    /// ln ν at and above which the low law holds.
    pub ln_nu_low: f64,
    /// ln ν at and below which the high law holds.
    pub ln_nu_high: f64,
    /// The low law's P/ρ at ν = 1 m²/s, m⁵/s³.
    pub low: f64,
    /// The high law's P/ρ, m⁵/s³.
    pub high: f64,
}

impl ChangenetSum {
    /// The sum of `parts` (gear, weight); `None` when they are not immersions of one gear (r_p,
    /// b, exponents, regime limits or g differ), use the crossing join, or the list is empty.
    pub fn new(parts: &[(ChangenetGear, f64)]) -> Option<Self> {
        let (first, _) = parts.first()?;
        // The crossing join has no closed sum here: those gears are evaluated one by one.
        if parts
            .iter()
            .any(|(g, _)| g.join() != super::changenet::ChangenetJoin::Bridge)
        {
            return None;
        }
        let t0 = first.sum_terms();
        let [rp, b, lf, lr, hf, re_lo, re_hi, _] = t0.form;
        let mut sum = ChangenetSum {
            low_unit: 0.0,
            low_speed_exp: 3.0 + 2.0 * lf + lr,
            low_nu_exp: -lr,
            high_unit: 0.0,
            high_speed_exp: 3.0 + 2.0 * hf,
            ln_rp_b: (rp * b).ln(),
            ln_re_c_low: re_lo.ln(),
            ln_re_c_high: re_hi.ln(),
            inv_ln_span: 1.0 / (re_hi / re_lo).ln(),
            bridge_nu: [2.0 * lf, 2.0 * (hf - lf)],
            bridge: Vec::new(),
        };
        for (g, w) in parts {
            let t = g.sum_terms();
            if t.form != t0.form {
                return None;
            }
            sum.low_unit += w * t.low_unit;
            sum.high_unit += w * t.high_unit;
            if let Some((a, d)) = t.bridge {
                sum.bridge.push((*w, a, d));
            }
        }
        Some(sum)
    }

    /// The law at speed `omega` (rad/s, sign irrelevant, non-zero).
    pub fn at_speed(&self, omega: f64) -> ChangenetAtSpeed {
        let ln_w = omega.abs().ln();
        let [e_low, e_high] = self.speed_exponents();
        self.at_ratio(
            &self.ratio_terms(1.0),
            ln_w,
            [(e_low * ln_w).exp(), (e_high * ln_w).exp()],
        )
    }

    /// Exponents of ω in the low and the high law's power at fixed oil (3 + 2a_Fr + a_Re and
    /// 3 + 2b_Fr).
    pub fn speed_exponents(&self) -> [f64; 2] {
        [self.low_speed_exp, self.high_speed_exp]
    }

    /// What [`Self::at_ratio`] needs of a gear turning at `ratio` times a reference speed
    /// (`ratio` > 0): [ln ratio, ratio^e_low, ratio^e_high].
    pub fn ratio_terms(&self, ratio: f64) -> [f64; 3] {
        let ln_r = ratio.abs().ln();
        [
            ln_r,
            (self.low_speed_exp * ln_r).exp(),
            (self.high_speed_exp * ln_r).exp(),
        ]
    }

    /// The law at ω = ratio · ω_ref from the ratio's terms ([`Self::ratio_terms`]), ln ω_ref and
    /// ω_ref's powers [ω_ref^e_low, ω_ref^e_high] ([`Self::speed_exponents`]): gears that share the
    /// exponents share the reference speed's powers.
    pub fn at_ratio(&self, ratio: &[f64; 3], ln_w_ref: f64, w_ref_pow: [f64; 2]) -> ChangenetAtSpeed {
        let ln_w = ratio[0] + ln_w_ref;
        let ln_w_rp_b = ln_w + self.ln_rp_b;
        ChangenetAtSpeed {
            ln_w,
            ln_nu_low: ln_w_rp_b - self.ln_re_c_low,
            ln_nu_high: ln_w_rp_b - self.ln_re_c_high,
            low: self.low_unit * ratio[1] * w_ref_pow[0],
            high: self.high_unit * ratio[2] * w_ref_pow[1],
        }
    }

    /// P/ρ (m⁵/s³) at speed `s` and L = ln ν.
    pub fn power_per_density(&self, s: &ChangenetAtSpeed, ln_nu: f64) -> f64 {
        if ln_nu >= s.ln_nu_low {
            return s.low * (self.low_nu_exp * ln_nu).exp();
        }
        if ln_nu <= s.ln_nu_high {
            return s.high;
        }
        let t = (s.ln_nu_low - ln_nu) * self.inv_ln_span;
        let common = 3.0 * s.ln_w + self.bridge_nu[0] * ln_nu;
        let slope = self.bridge_nu[1] * ln_nu;
        self.bridge
            .iter()
            .map(|&(w, a, d)| w * (a + common + t * (d + slope)).exp())
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ChangenetParams, OilState};
    use super::*;

    /// The sum over immersions (one dry, weights as a planet's orbit average) equals the
    /// weighted sum of `ChangenetGear::power` to rounding in the low law, the bridge and the high
    /// law.
    #[test]
    fn sum_matches_the_gears_in_every_regime() {
        let p = ChangenetParams::default();
        let depths = [0.0, 5e-3, 20e-3, 60e-3];
        let parts: Vec<(ChangenetGear, f64)> = depths
            .iter()
            .enumerate()
            .map(|(i, &h)| {
                (
                    ChangenetGear::new(&fzg_wheel(h), &p).unwrap(),
                    0.3 + 0.2 * i as f64,
                )
            })
            .collect();
        let sum = ChangenetSum::new(&parts).unwrap();
        let (mut low, mut high, mut bridge) = (0, 0, 0);
        for w in [0.3, 2.0, 17.0, 50.0, 140.0, 400.0, 1500.0] {
            let s = sum.at_speed(-w);
            for nu_cst in [
                2.0, 5.0, 7.0, 10.0, 14.0, 20.0, 32.0, 45.0, 70.0, 100.0, 460.0, 3000.0,
            ] {
                let o = OilState {
                    density: 870.0,
                    kinematic_viscosity: nu_cst * 1e-6,
                };
                let rc = parts[1].0.critical_reynolds(w, &o);
                let direct: f64 = parts.iter().map(|(g, wt)| wt * g.power(w, &o).total).sum();
                let p = o.density * sum.power_per_density(&s, o.kinematic_viscosity.ln());
                assert!(
                    (p / direct - 1.0).abs() < 1e-12,
                    "w {w} ν {nu_cst}: {p} vs {direct}"
                );
                match rc {
                    r if r <= 6000.0 => low += 1,
                    r if r >= 9000.0 => high += 1,
                    _ => bridge += 1,
                }
            }
        }
        assert!(low > 5 && high > 5 && bridge > 2, "{low} {high} {bridge}");
    }

    /// Immersions of different gears (another r_p) do not sum.
    #[test]
    fn different_gears_do_not_sum() {
        let p = ChangenetParams::default();
        let a = ChangenetGear::new(&fzg_wheel(10e-3), &p).unwrap();
        let b = ChangenetGear::new(&blok_gear(), &p).unwrap();
        assert!(ChangenetSum::new(&[(a, 1.0), (b, 1.0)]).is_none());
        assert!(ChangenetSum::new(&[]).is_none());
    }
}
