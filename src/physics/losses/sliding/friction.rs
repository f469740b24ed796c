//! Friction-coefficient laws for lubricated gear contacts (physics.md §7).
//!
//! Every law takes SI inputs (N/m, m/s, m, Pa·s) and converts internally to the units in which it
//! was published; the conversion constants are below and each law has a test in its native units.
//!
//! Drozdov & Gavrikov (seed 003 table 4.1) is **not implemented**: the scan of the table is garbled
//! (only fragments such as `0.47 − 0.13·10^? P_max − 0.4·10^-3 ν0` and `V_s + V_r + 13.4` survive) and
//! no readable source of the full formula was found (see DOCS.md). It is listed as missing.

use super::SlidingError;
use crate::physics::units::{MM_PER_M, MPA_S_PER_PA_S, M_PER_MM, UM_PER_M};

/// Newtons per pound-force (exact by definition of the lbf).
pub const NEWTON_PER_LBF: f64 = 4.448_221_615_260_5;
/// Metres per inch (exact).
pub const METRE_PER_INCH: f64 = 0.0254;
/// Metres per micro-inch (exact).
pub const METRE_PER_MICROINCH: f64 = 0.0254e-6;

/// Local state of one contact element, all SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Normal load per unit length of contact line w (N/m).
    pub line_load: f64,
    /// Sliding speed v_g (m/s).
    pub sliding_speed: f64,
    /// Sum (entrainment) speed v_Σ = ω1ρ1 + ω2ρ2 (m/s).
    pub sum_speed: f64,
    /// Reduced radius of curvature R in the normal section (m).
    pub reduced_radius: f64,
    /// Dynamic viscosity of the oil η (Pa·s).
    pub viscosity: f64,
    /// Composite roughness Ra = (Ra1 + Ra2)/2 (m).
    pub roughness: f64,
}

/// Benedict & Kelley (1961) \[recalled\]:
/// `μ = c·(50/(50 − S))·log10(K·W/(η0·v_g·v_Σ²))`, US units: W lbf/in, η0 cP, v_g and v_Σ in/s,
/// S composite roughness in µin; c = 0.0127, K = 3.17e8.
///
/// The log argument is clamped to `[arg_min, arg_max]`: the formula diverges at the pitch point
/// (v_g → 0, where μ·v_g → 0 anyway, so the upper clamp only keeps μ finite there) and turns
/// negative at light load/high speed (the lower clamp keeps μ ≥ c·C_R·log10(arg_min)).
/// A NaN argument (0/0) is mapped to `arg_min`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenedictKelley {
    /// Leading coefficient c (0.0127).
    pub coefficient: f64,
    /// Constant K inside the logarithm (3.17e8).
    pub constant: f64,
    /// Lower clamp of the log argument (default 10, i.e. μ ≥ c·C_R).
    pub arg_min: f64,
    /// Upper clamp of the log argument (default 1e10, i.e. μ ≤ 10·c·C_R).
    pub arg_max: f64,
}

impl Default for BenedictKelley {
    fn default() -> Self {
        Self {
            coefficient: 0.0127,
            constant: 3.17e8,
            arg_min: 10.0,
            arg_max: 1e10,
        }
    }
}

impl BenedictKelley {
    /// Roughness factor C_R = 50/(50 − S), S = composite roughness in µin. Requires S < 50 µin
    /// (1.27 µm): the published fit has a pole there.
    pub fn roughness_factor(&self, roughness: f64) -> Result<f64, SlidingError> {
        let s_uin = roughness / METRE_PER_MICROINCH;
        if !(s_uin.is_finite() && (0.0..50.0).contains(&s_uin)) {
            return Err(SlidingError::InvalidInput {
                field: "roughness (Benedict & Kelley)",
                value: roughness,
                expected: "0 <= (Ra1+Ra2)/2 < 1.27e-6 m (50 µin; the law has a pole there)",
            });
        }
        Ok(50.0 / (50.0 - s_uin))
    }

    /// μ for one contact, with the roughness factor precomputed by [`Self::roughness_factor`].
    pub fn mu(&self, c: &ContactState, roughness_factor: f64) -> f64 {
        let w_lbf_in = c.line_load * METRE_PER_INCH / NEWTON_PER_LBF;
        let eta_cp = c.viscosity * MPA_S_PER_PA_S;
        let vg = c.sliding_speed / METRE_PER_INCH;
        let vs = c.sum_speed / METRE_PER_INCH;
        let raw = self.constant * w_lbf_in / (eta_cp * vg * vs * vs);
        let arg = if raw.is_nan() || raw < self.arg_min {
            self.arg_min
        } else if raw > self.arg_max {
            self.arg_max
        } else {
            raw
        };
        self.coefficient * roughness_factor * arg.log10()
    }
}

/// ISO TC60 draft (as quoted in seed 003 table 4.1) \[recalled\]:
/// `μ = c·(w·Ra/(η·R·v_Σ))^e`, w N/mm, Ra µm, η mPa·s, R mm, v_Σ m/s; c = 0.12, e = 0.25.
/// (In SI the bracket is dimensionless: bracket_native = 1e-3·bracket_SI.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoTc60 {
    /// Coefficient c (0.12).
    pub coefficient: f64,
    /// Exponent e (0.25).
    pub exponent: f64,
}

impl Default for IsoTc60 {
    fn default() -> Self {
        Self {
            coefficient: 0.12,
            exponent: 0.25,
        }
    }
}

impl IsoTc60 {
    /// μ for one contact. Precondition: η, R, v_Σ > 0 (guaranteed inside the mesh path).
    pub fn mu(&self, c: &ContactState) -> f64 {
        let w_n_mm = c.line_load * M_PER_MM; // N/m × m/mm = N/mm
        let ra_um = c.roughness * UM_PER_M;
        let eta_mpas = c.viscosity * MPA_S_PER_PA_S;
        let r_mm = c.reduced_radius * MM_PER_M;
        let x = (w_n_mm * ra_um / (eta_mpas * r_mm * c.sum_speed)).max(0.0);
        // x^0.25 as two square roots (same value to rounding, several times faster than powf)
        let xe = if self.exponent == 0.25 {
            x.sqrt().sqrt()
        } else {
            x.powf(self.exponent)
        };
        self.coefficient * xe
    }
}

/// Schlenk's mean coefficient, ISO/TR 14179-2 [std]:
/// `μ_mz = 0.048·(F_bt/b/(v_ΣC·ρ_redC))^0.2·η^−0.05·Ra^0.25·X_L`,
/// F_bt/b N/mm, v_ΣC m/s, ρ_redC mm, η mPa·s, Ra µm. X_L: the oil's lubricant factor
/// (`physics::oil::lubricant_factor`). The load per length and the radius it is divided by
/// follow [`ContactLineLoad`] (the mesh computes both: `SlidingMesh::mu_mz`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schlenk {
    /// Coefficient (0.048).
    pub coefficient: f64,
    /// Lubricant factor X_L (1.0 mineral oil).
    pub x_l: f64,
    /// Which load per length and radius enter the bracket.
    pub line_load: ContactLineLoad,
}

impl Default for Schlenk {
    fn default() -> Self {
        Self {
            coefficient: 0.048,
            x_l: 1.0,
            line_load: ContactLineLoad::default(),
        }
    }
}

/// The load per length and the radius of curvature in Schlenk's bracket `w/(v_ΣC·ρ_C)`.
///
/// The two agree on spur gears with ε_α < 2 (l_min = b, β_b = 0); on a helical mesh the bracket
/// of `FaceWidth` over that of `ContactLine` is cos²β_b·l_min/b (μ ∝ its 0.2 power).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactLineLoad {
    /// ISO/TR 14179-2 [std]: w = F_bt/b (transverse load over the face width) with the
    /// normal-section ρ_redC = ρ_t,C/cos β_b.
    FaceWidth,
    /// The FZG group's form, GEARpie `CLASSES/CONTACT.py` (cfernandesFEUP/GEARpie @cb30c91,
    /// `CoF`): w = F_bn/l_min, the normal load over the minimum total length of the contact lines
    /// over a mesh cycle, with the transverse ρ_t,C. Their lubricant factors X_L were fitted with
    /// this form (docs/validation.md, "Contact-line load").
    #[default]
    ContactLine,
}

impl Schlenk {
    /// μ_mz from SI inputs: `load_per_width` = F_bt/b (N/m), `sum_speed_c` = v_ΣC (m/s),
    /// `reduced_radius_c` = ρ_redC (m, normal section), `viscosity` η (Pa·s), `roughness` Ra (m).
    /// Precondition: v_ΣC, ρ_redC, η > 0.
    pub fn mu_mz(
        &self,
        load_per_width: f64,
        sum_speed_c: f64,
        reduced_radius_c: f64,
        viscosity: f64,
        roughness: f64,
    ) -> f64 {
        let f_n_mm = load_per_width * M_PER_MM; // N/m × m/mm = N/mm
        let rho_mm = reduced_radius_c * MM_PER_M;
        let eta_mpas = viscosity * MPA_S_PER_PA_S;
        let ra_um = roughness * UM_PER_M;
        let x = (f_n_mm / (sum_speed_c * rho_mm)).max(0.0);
        self.coefficient
            * x.powf(0.2)
            * eta_mpas.powf(-SCHLENK_VISCOSITY_EXPONENT)
            * ra_um.powf(0.25)
            * self.x_l
    }
}

/// Exponent of the viscosity in Schlenk's μ_mz (ISO/TR 14179-2): μ_mz ∝ η^(−0.05).
pub const SCHLENK_VISCOSITY_EXPONENT: f64 = 0.05;

/// Choice of friction law for the detailed model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionLaw {
    /// Constant μ (dimensionless).
    Constant(f64),
    /// Benedict & Kelley \[recalled\], local per contact element.
    BenedictKelley(BenedictKelley),
    /// ISO TC60 draft \[recalled\], local per contact element.
    IsoTc60(IsoTc60),
    /// Schlenk / ISO/TR 14179-2 μ_mz [std]: one mean value for the whole mesh (pitch-point data).
    Schlenk(Schlenk),
}

impl FrictionLaw {
    /// Check the law's coefficients (finite, non-negative; B&K clamps 0 < arg_min <= arg_max).
    pub fn validate(&self) -> Result<(), SlidingError> {
        let bad = |field: &'static str, value: f64, expected: &'static str| {
            Err(SlidingError::InvalidInput {
                field,
                value,
                expected,
            })
        };
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        match *self {
            FrictionLaw::Constant(mu) if !ok(mu) => bad("constant μ", mu, "finite and >= 0"),
            FrictionLaw::BenedictKelley(b) => {
                if !(ok(b.coefficient) && ok(b.constant) && b.constant > 0.0) {
                    bad(
                        "Benedict & Kelley coefficients",
                        b.coefficient,
                        "finite, >= 0 (K > 0)",
                    )
                } else if !(b.arg_min.is_finite() && b.arg_min > 0.0 && b.arg_max >= b.arg_min) {
                    bad("Benedict & Kelley clamp", b.arg_min, "0 < arg_min <= arg_max")
                } else {
                    Ok(())
                }
            }
            FrictionLaw::IsoTc60(l) if !(ok(l.coefficient) && ok(l.exponent)) => {
                bad("ISO TC60 coefficients", l.coefficient, "finite and >= 0")
            }
            FrictionLaw::Schlenk(l) if !(ok(l.coefficient) && ok(l.x_l)) => {
                bad("Schlenk coefficient / X_L", l.x_l, "finite and >= 0")
            }
            _ => Ok(()),
        }
    }
}

impl Default for FrictionLaw {
    fn default() -> Self {
        FrictionLaw::IsoTc60(IsoTc60::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(w: f64, vg: f64, vs: f64, r: f64, eta: f64, ra: f64) -> ContactState {
        ContactState {
            line_load: w,
            sliding_speed: vg,
            sum_speed: vs,
            reduced_radius: r,
            viscosity: eta,
            roughness: ra,
        }
    }

    #[test]
    fn iso_tc60_native_units() {
        // w 100 N/mm, Ra 0.5 µm, η 20 mPa·s, R 10 mm, v_Σ 10 m/s, given in SI.
        let c = state(1e5, 1.0, 10.0, 0.01, 0.02, 0.5e-6);
        let expect = 0.12 * (100.0_f64 * 0.5 / (20.0 * 10.0 * 10.0)).powf(0.25);
        assert!((IsoTc60::default().mu(&c) - expect).abs() < 1e-14);
        // dimensionless in SI: bracket_native = 1e-3 * bracket_SI
        let si: f64 = 1e5 * 0.5e-6 / (0.02 * 0.01 * 10.0);
        assert!((expect - 0.12 * (1e-3 * si).powf(0.25)).abs() < 1e-14);
    }

    #[test]
    fn iso_tc60_fast_root_equals_powf() {
        let c = state(1.3e5, 1.0, 7.0, 0.008, 0.03, 0.7e-6);
        let fast = IsoTc60::default().mu(&c);
        let slow = IsoTc60 {
            exponent: f64::from_bits(0.25f64.to_bits() + 1), // next float: takes the powf branch
            ..IsoTc60::default()
        };
        assert!((fast / slow.mu(&c) - 1.0).abs() < 1e-15);
        let other = IsoTc60 {
            exponent: 0.3,
            ..IsoTc60::default()
        };
        assert!((other.mu(&c) / fast - 1.0).abs() > 1e-3);
    }

    #[test]
    fn benedict_kelley_native_units() {
        // W 1000 lbf/in, η 10 cP, v_g 100 in/s, v_Σ 1000 in/s, S 20 µin.
        let w = 1000.0 * NEWTON_PER_LBF / METRE_PER_INCH;
        let c = state(w, 100.0 * 0.0254, 1000.0 * 0.0254, 0.01, 0.010, 20.0 * 0.0254e-6);
        let bk = BenedictKelley::default();
        let cr = bk.roughness_factor(c.roughness).unwrap();
        assert!((cr - 50.0 / 30.0).abs() < 1e-12);
        let expect = 0.0127 * (50.0 / 30.0) * (3.17e8_f64 * 1000.0 / (10.0 * 100.0 * 1e6)).log10();
        assert!(
            (bk.mu(&c, cr) - expect).abs() < 1e-13,
            "{} {}",
            bk.mu(&c, cr),
            expect
        );
    }

    #[test]
    fn benedict_kelley_clamps() {
        let bk = BenedictKelley::default();
        // v_g = 0: argument infinite -> upper clamp, finite μ
        let c = state(1e5, 0.0, 10.0, 0.01, 0.02, 0.4e-6);
        let mu = bk.mu(&c, 1.0);
        assert!((mu - 0.0127 * 10.0).abs() < 1e-14);
        // 0/0 (no load, no sliding): lower clamp, not NaN
        let c0 = state(0.0, 0.0, 10.0, 0.01, 0.02, 0.4e-6);
        assert!((bk.mu(&c0, 1.0) - 0.0127).abs() < 1e-14);
        // light load, fast: raw log negative -> lower clamp
        let c1 = state(1.0, 50.0, 100.0, 0.01, 0.005, 0.4e-6);
        assert!((bk.mu(&c1, 1.0) - 0.0127).abs() < 1e-14);
        // roughness pole
        assert!(bk.roughness_factor(1.3e-6).is_err());
        assert!(bk.roughness_factor(f64::NAN).is_err());
    }

    #[test]
    fn schlenk_native_units() {
        // F/b 500 N/mm, v 10 m/s, ρ 5 mm, η 30 mPa·s, Ra 0.5 µm, X_L 0.8
        let s = Schlenk {
            x_l: 0.8,
            ..Schlenk::default()
        };
        let mu = s.mu_mz(5e5, 10.0, 0.005, 0.030, 0.5e-6);
        let expect =
            0.048 * (500.0_f64 / (10.0 * 5.0)).powf(0.2) * 30.0_f64.powf(-0.05) * 0.5_f64.powf(0.25) * 0.8;
        assert!((mu - expect).abs() < 1e-14);
    }

    #[test]
    fn law_validation() {
        assert!(FrictionLaw::default().validate().is_ok());
        assert!(FrictionLaw::Constant(-0.1).validate().is_err());
        let bk = BenedictKelley {
            arg_min: 0.0,
            ..BenedictKelley::default()
        };
        assert!(FrictionLaw::BenedictKelley(bk).validate().is_err());
        let s = Schlenk {
            x_l: f64::NAN,
            ..Schlenk::default()
        };
        assert!(FrictionLaw::Schlenk(s).validate().is_err());
    }

    #[test]
    fn laws_monotone_in_load() {
        let lo = state(5e4, 1.0, 10.0, 0.01, 0.02, 0.5e-6);
        let hi = state(2e5, 1.0, 10.0, 0.01, 0.02, 0.5e-6);
        let tc = IsoTc60::default();
        assert!(tc.mu(&hi) > tc.mu(&lo));
        let bk = BenedictKelley::default();
        assert!(bk.mu(&hi, 2.0) > bk.mu(&lo, 2.0));
        // ISO TC60: μ ∝ w^0.25 exactly
        assert!((tc.mu(&hi) / tc.mu(&lo) - 4.0_f64.powf(0.25)).abs() < 1e-12);
    }
}
