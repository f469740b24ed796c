//! The SKF (2004) frictional-moment model of rolling bearings:
//!
//! ```text
//! M = φ_ish·φ_rs·M_rr + M_sl + M_seal + M_drag                       [N·mm]
//! M_rr = G_rr·(ν·n)^0.6                                               rolling
//! φ_ish = 1 / (1 + 1.84e-9·(n·d_m)^1.28·ν^0.64)                       inlet shear heating
//! φ_rs  = exp(−K_rs·ν·n·(d + D)·√(K_z / (2(D − d))))                  replenishment/starvation
//! M_sl = G_sl·μ_sl,  μ_sl = φ_bl·μ_bl + (1 − φ_bl)·μ_EHL               sliding
//! φ_bl = exp(−2.6e-8·(n·ν)^1.4·d_m)                                   film weighting
//! M_seal = K_S1·d_s^β + K_S2                                          integral contact seals
//! M_drag = 0.4·V_M·K_ball·d_m^5·n² + 1.093e-7·n²·d_m³·(n·d_m²·f_t/ν)^−1.379·R_s   oil bath (balls;
//!          rollers: first term 4·V_M·K_roll·C_w·B·d_m^4·n², below)
//! ```
//!
//! with n in r/min, ν in mm²/s, lengths in mm, loads in N.
//!
//! Source: SKF, "The SKF model for calculating the frictional moment" (SKF publication,
//! cdn.skfmediahub.skf.com), as implemented by two open peers that agree term by term and were
//! used here to read the formulas and constants (no code copied; docs/physics.md §Bearings lists
//! them): a MATLAB gearbox-loss script citing the document ("Formeln nach SKF") and a Python
//! deep-groove-ball-bearing model (`BEARING_CONSTANTS`). The `G_rr`/`G_sl` forms implemented:
//!
//! - deep-groove ball bearings, F_a = 0: `G_rr = R1·d_m^1.96·F_r^0.54`,
//!   `G_sl = S1·d_m^−0.26·F_r^(5/3)`; F_a > 0: `α_F = 24.6·(F_a/C_0)^0.24` (deg),
//!   `G_rr = R1·d_m^1.96·(F_r + R2/sin α_F·F_a)^0.54`,
//!   `G_sl = S1·d_m^−0.145·(F_r^5 + S2·d_m^1.5/sin α_F·F_a^4)^(1/3)`;
//! - angular-contact and four-point-contact ball bearings: `F_g = R3·d_m^4·n²` (rolling),
//!   `F_g,s = S3·d_m^4·n²` (sliding), `G_rr = R1·d_m^1.97·(F_r + F_g + R2·F_a)^0.54`,
//!   `G_sl = S1·d_m^0.26·((F_r + F_g,s)^(4/3) + S2·F_a^(4/3))`;
//! - cylindrical roller bearings: `G_rr = R1·d_m^2.41·F_r^0.31`, `G_sl = S1·d_m^0.9·F_a + S2·d_m·F_r`;
//! - tapered roller bearings: `G_rr = R1·d_m^2.38·(F_r + R2·Y·F_a)^0.31`,
//!   `G_sl = S1·d_m^0.82·(F_r + S2·Y·F_a)` (Y: the bearing's axial load factor).
//!
//! The forms are those of SKF's table "Geometric and load dependent variables for rolling and
//! sliding frictional moments – radial bearings" (SKF Rolling Bearings catalogue, friction
//! chapter, as shown at yumpu.com/en/document/view/55668573/skf-rolling-bearings/106), the same
//! in the peers. Roller bearings in an oil bath: `M_drag = 4·V_M·K_roll·C_w·B·d_m^4·n² + (the
//! common term)`, `K_roll = K_L·K_z·(d + D)/(D − d)·1e-12`, `l_D = 5·K_L·B/d_m`,
//! `C_w = 2.789e-10·l_D³ − 2.786e-4·l_D² + 0.0195·l_D + 0.6439` (as read from two open peers,
//! docs/physics.md §Bearings). Needle roller bearings have no row in any source found: they use
//! [`super::Palmgren`].

use super::{BearingError, BearingLoad, BearingMoment, BearingOil, BearingSize, LoadTerms};
use crate::physics::units::{MM_PER_M, N_M_PER_N_MM};

/// Exponents of the speed n in [`LoadTerms::speed`]: (n d_m)^1.28, n^0.6, n^1.4 and the drag's
/// n²·n^−1.379 (the SKF model's, module docs).
pub const SPEED_EXPONENTS: [f64; 4] = [1.28, 0.6, 1.4, 2.0 - 1.379];

/// `[|ω|^e for e in SPEED_EXPONENTS]` from one logarithm (ω = 0: all 0).
pub fn speed_exponent_powers(omega: f64) -> [f64; 4] {
    let ln_w = omega.abs().ln();
    SPEED_EXPONENTS.map(|e| (e * ln_w).exp())
}

/// Which `G_rr`/`G_sl` forms of the SKF table apply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkfKind {
    /// Deep-groove ball bearing (radial form; axial form with α_F when F_a > 0).
    DeepGrooveBall,
    /// Single-row angular-contact ball bearing (axial form with the ball centrifugal load F_g).
    AngularContactBall,
    /// Four-point-contact ball bearing (QJ): the angular-contact form with its own row.
    FourPointContactBall,
    /// Cylindrical roller bearing (caged or full complement, by the row's constants).
    CylindricalRoller,
    /// Single-row tapered roller bearing (needs the bearing's axial load factor Y).
    TaperedRoller,
}

impl SkfKind {
    /// Roller bearing (line contact): roller drag form.
    pub fn is_roller(self) -> bool {
        matches!(self, SkfKind::CylindricalRoller | SkfKind::TaperedRoller)
    }
}

/// Geometry constants of one bearing series (SKF table, catalogue units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkfConstants {
    /// R1.
    pub r1: f64,
    /// R2.
    pub r2: f64,
    /// R3 (angular and four-point contact: centrifugal term of G_rr; 0 otherwise).
    pub r3: f64,
    /// S1.
    pub s1: f64,
    /// S2.
    pub s2: f64,
    /// S3 (angular and four-point contact: centrifugal term of G_sl; 0 otherwise).
    pub s3: f64,
    /// Bearing-type constant K_z of φ_rs and the drag term (3.1 deep groove, 4.4 angular
    /// contact, 5.1 caged cylindrical roller, 6.0 tapered roller, per the catalogue rows).
    pub k_z: f64,
    /// Roller-bearing drag constant K_L (0 for ball bearings).
    pub k_l: f64,
}

/// An SKF bearing model with everything that does not change precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct Skf {
    kind: SkfKind,
    c: SkfConstants,
    /// d_m in mm.
    dm: f64,
    /// Static load rating C_0, N (for α_F of a deep-groove bearing under axial load).
    c0: f64,
    /// Sliding friction coefficients in boundary and full-film lubrication.
    mu_bl: f64,
    mu_ehl: f64,
    /// Integral seals K_S1·d_s^β + K_S2, N·mm (0 without contact seals).
    m_seal: f64,
    /// Drag: 0.4·V_M·K_ball·d_m^5 (× n²) and 1.093e-7·d_m³·R_s (× n²·(n d_m² f_t/ν)^−1.379) and
    /// d_m²·f_t; all zero for a bearing above the oil.
    drag1: f64,
    drag2: f64,
    dm2_ft: f64,
    /// (d_m² f_t)^−1.379 of the drag term (0 without drag).
    dm2_ft_pow: f64,
    /// The d_m powers of G_rr and G_sl ([`dm_powers`]).
    dm_pow: [f64; 4],
    /// ln d_m, for (n·d_m)^1.28 as exp(1.28·(ln n + ln d_m)).
    ln_dm: f64,
    /// K_rs·(d + D)·√(K_z/(2(D − d))): φ_rs = exp(−this·ν·n).
    rs: f64,
}

/// The powers of d_m in G_rr and G_sl, fixed per bearing (computed once, not per cycle sample):
/// [G_rr, G_sl, G_sl of a deep-groove bearing under axial load, d_m^1.5 of that form].
fn dm_powers(kind: SkfKind, dm: f64) -> [f64; 4] {
    match kind {
        SkfKind::DeepGrooveBall => [dm.powf(1.96), dm.powf(-0.26), dm.powf(-0.145), dm.powf(1.5)],
        SkfKind::AngularContactBall | SkfKind::FourPointContactBall => {
            [dm.powf(1.97), dm.powf(0.26), 0.0, 0.0]
        }
        SkfKind::CylindricalRoller => [dm.powf(2.41), dm.powf(0.9), 0.0, 0.0],
        SkfKind::TaperedRoller => [dm.powf(2.38), dm.powf(0.82), 0.0, 0.0],
    }
}

/// Which edition of SKF's oil-bath drag term.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DragForm {
    /// The current SKF publication (module docs): `0.4·V_M·K_ball·d_m^5·n²` (balls) or
    /// `4·V_M·K_roll·C_w·B·d_m^4·n²` (rollers), plus the rotating-volume term
    /// `1.093e-7·n²·d_m³·(n·d_m²·f_t/ν)^−1.379·R_s`.
    #[default]
    Current,
    /// The older edition, as the FZG group's bearing code writes it (cfernandesFEUP/
    /// Gear-Calculation `GearC/bearings.py` @0e4a135, `beart`): `V_M·K_ball·d_m^5·n²` (balls,
    /// K_ball without the row count: i_rw = 1 there) or `10·V_M·K_roll·B·d_m^4·n²` (rollers), no
    /// rotating-volume term. The SKF catalogue edition itself was not readable. That code's `pl`
    /// doubles the term (`Mdrag = 2*(Kdrag*n**2)`, reason not stated); this form does not.
    Older,
}

/// Lubrication method (sets K_rs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lubrication {
    /// Low-level oil bath, splash or oil jet: K_rs = 3e-8.
    OilBath,
    /// Grease or oil-air: K_rs = 6e-8.
    Grease,
}

/// Everything [`Skf::new`] needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkfInput {
    /// Form of the table.
    pub kind: SkfKind,
    /// Series constants.
    pub constants: SkfConstants,
    /// Boundary dimensions.
    pub size: BearingSize,
    /// Static load rating C_0, N (> 0).
    pub c0: f64,
    /// Lubrication.
    pub lubrication: Lubrication,
    /// μ_bl (SKF: 0.12 for n ≠ 0 as both peers use it).
    pub mu_bl: f64,
    /// μ_EHL (0.05 for mineral oil per the SKF online calculator, as the MATLAB peer notes).
    pub mu_ehl: f64,
    /// Integral contact seals (K_S1, K_S2, β, d_s in m), if any.
    pub seal: Option<(f64, f64, f64, f64)>,
    /// Oil level above the lowest point of the outer-ring raceway... as SKF's H: height of the
    /// oil level above the bearing's lowest point, m (≤ 0: no drag).
    pub oil_level: f64,
    /// V_M of the drag term (SKF diagram; dimensionless).
    pub drag_vm: f64,
    /// Edition of the drag term.
    pub drag_form: DragForm,
    /// Rows of rolling elements i_rw.
    pub rows: f64,
    /// Width B, m (roller drag term; unused for ball bearings).
    pub width: f64,
    /// Axial load factor Y of a tapered roller bearing (catalogue value; unused otherwise).
    pub axial_factor_y: f64,
}

impl Skf {
    /// Build the model; errors name the input that is out of range.
    pub fn new(i: &SkfInput) -> Result<Skf, BearingError> {
        let (d, big_d) = (i.size.bore * MM_PER_M, i.size.outside * MM_PER_M);
        if !(d > 0.0 && big_d > d) {
            return Err(BearingError(format!(
                "bore {d} mm and outside diameter {big_d} mm: need 0 < d < D"
            )));
        }
        let mut c = i.constants;
        for (name, v) in [("R1", c.r1), ("S1", c.s1), ("K_z", c.k_z)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(BearingError(format!("{name} = {v}: must be > 0")));
            }
        }
        if i.kind == SkfKind::TaperedRoller {
            let y = i.axial_factor_y;
            if !(y.is_finite() && y > 0.0) {
                return Err(BearingError(format!(
                    "axial load factor Y = {y}: a tapered roller bearing needs Y > 0"
                )));
            }
            // R2·Y and S2·Y are constants of the bearing: fold Y in once.
            c.r2 *= y;
            c.s2 *= y;
        }
        let dm = 0.5 * (d + big_d);
        let m_seal = i
            .seal
            .map_or(0.0, |(k1, k2, beta, ds)| k1 * (ds * MM_PER_M).powf(beta) + k2);
        // Drag: SKF with t from the oil level H over d_m (H clamped to 1.2 d_m, where
        // the bearing is fully immersed).
        let h = (i.oil_level * MM_PER_M).clamp(0.0, 1.2 * dm);
        let (drag1, drag2, dm2_ft) = if h > 0.0 {
            let t = 2.0 * ((0.6 * dm - h) / (0.6 * dm)).clamp(-1.0, 1.0).acos();
            let f_t = if t <= std::f64::consts::PI {
                (0.5 * t).sin()
            } else {
                1.0
            };
            let f_a = 0.05 * c.k_z * (big_d + d) / (big_d - d);
            let r_s = 0.36 * dm * dm * (t - t.sin()) * f_a;
            let first = if i.kind.is_roller() {
                let b = i.width * MM_PER_M;
                if !(b > 0.0 && c.k_l > 0.0) {
                    return Err(BearingError(format!(
                        "roller drag needs the width B ({b} mm) and K_L ({}) > 0",
                        c.k_l
                    )));
                }
                let k_roll = c.k_l * c.k_z * (d + big_d) / (big_d - d) * 1e-12;
                match i.drag_form {
                    DragForm::Current => {
                        let l_d = 5.0 * c.k_l * b / dm;
                        let c_w =
                            (2.789e-10 * l_d.powi(3) - 2.786e-4 * l_d * l_d + 0.0195 * l_d + 0.6439).max(0.0);
                        4.0 * i.drag_vm * k_roll * c_w * b * dm.powi(4)
                    }
                    DragForm::Older => 10.0 * i.drag_vm * k_roll * b * dm.powi(4),
                }
            } else {
                let k_ball = i.rows * c.k_z * (d + big_d) / (big_d - d) * 1e-12;
                match i.drag_form {
                    DragForm::Current => 0.4 * i.drag_vm * k_ball * dm.powi(5),
                    DragForm::Older => i.drag_vm * k_ball * dm.powi(5),
                }
            };
            match i.drag_form {
                DragForm::Current => (first, 1.093e-7 * dm.powi(3) * r_s, dm * dm * f_t),
                DragForm::Older => (first, 0.0, 0.0),
            }
        } else {
            (0.0, 0.0, 0.0)
        };
        Ok(Skf {
            kind: i.kind,
            c,
            dm,
            c0: i.c0,
            mu_bl: i.mu_bl,
            mu_ehl: i.mu_ehl,
            m_seal,
            drag1,
            drag2,
            dm2_ft,
            dm2_ft_pow: if dm2_ft > 0.0 { dm2_ft.powf(-1.379) } else { 0.0 },
            dm_pow: dm_powers(i.kind, dm),
            ln_dm: dm.ln(),
            rs: match i.lubrication {
                Lubrication::OilBath => 3e-8,
                Lubrication::Grease => 6e-8,
            } * (d + big_d)
                * (c.k_z / (2.0 * (big_d - d))).sqrt(),
        })
    }

    /// G_rr and G_sl at speed `n` (r/min) and `load`.
    pub fn load_terms(&self, n: f64, load: BearingLoad) -> LoadTerms {
        self.load_terms_with(n, load, None)
    }

    /// As [`Self::load_terms`], with the speed powers `speed` ([`LoadTerms::speed`] at `n`) when
    /// already known (e.g. from [`Self::speed_powers`] per unit speed times the powers of the
    /// speed, [`SPEED_EXPONENTS`]).
    pub fn load_terms_with(&self, n: f64, load: BearingLoad, speed: Option<[f64; 4]>) -> LoadTerms {
        let (fr, fa) = (load.radial.abs(), load.axial.abs());
        let (c, dm, p) = (&self.c, self.dm, &self.dm_pow);
        let (g_rr, g_sl) = match self.kind {
            SkfKind::DeepGrooveBall if fa > 0.0 && self.c0 > 0.0 => {
                let sin_af = (24.6 * (fa / self.c0).powf(0.24)).min(90.0).to_radians().sin();
                (
                    c.r1 * p[0] * (fr + c.r2 / sin_af * fa).powf(0.54),
                    c.s1 * p[2] * (fr.powi(5) + c.s2 * p[3] / sin_af * fa.powi(4)).cbrt(),
                )
            }
            SkfKind::DeepGrooveBall => {
                // Both powers of F_r from one logarithm (F_r = 0: ln = −∞, both powers 0).
                let ln_fr = fr.ln();
                (
                    c.r1 * p[0] * (0.54 * ln_fr).exp(),
                    c.s1 * p[1] * (5.0 / 3.0 * ln_fr).exp(),
                )
            }
            SkfKind::AngularContactBall | SkfKind::FourPointContactBall => {
                let dm4n2 = dm.powi(4) * n * n;
                (
                    c.r1 * p[0] * (fr + c.r3 * dm4n2 + c.r2 * fa).powf(0.54),
                    c.s1 * p[1] * ((fr + c.s3 * dm4n2).powf(4.0 / 3.0) + c.s2 * fa.powf(4.0 / 3.0)),
                )
            }
            SkfKind::CylindricalRoller => (c.r1 * p[0] * fr.powf(0.31), c.s1 * p[1] * fa + c.s2 * dm * fr),
            // r2 and s2 carry Y (folded in by `new`).
            SkfKind::TaperedRoller => (
                c.r1 * p[0] * (fr + c.r2 * fa).powf(0.31),
                c.s1 * p[1] * (fr + c.s2 * fa),
            ),
        };
        LoadTerms {
            n_rpm: n,
            g_rr,
            g_sl,
            speed: speed.unwrap_or_else(|| self.speed_powers(n)),
        }
    }

    /// `[(n d_m)^1.28, n^0.6, n^1.4, n²·(n d_m² f_t)^−1.379]` at `n` (r/min). Each is a power of
    /// n ([`SPEED_EXPONENTS`]) times a constant, so the powers at `c·n` are those at `c` times the
    /// powers of n.
    pub fn speed_powers(&self, n: f64) -> [f64; 4] {
        // The powers of n from one logarithm (exp is about half the cost of powf; the values
        // agree to rounding). n = 0 gives ln n = −∞ and every positive power 0, as powf does.
        let ln_n = n.ln();
        let drag = if self.drag2 > 0.0 && n > 0.0 {
            // n²·(n·f_t dm²)^-1.379 written as one power of n: at vanishing speed n² underflows
            // to 0 while (n·f_t dm²)^-1.379 overflows, and 0·∞ is NaN.
            ((2.0 - 1.379) * ln_n).exp() * self.dm2_ft_pow
        } else {
            0.0
        };
        [
            (1.28 * (ln_n + self.ln_dm)).exp(),
            (0.6 * ln_n).exp(),
            (1.4 * ln_n).exp(),
            drag,
        ]
    }

    /// Frictional moment at the oil state `oil` with the load terms `t`: two exponentials and
    /// arithmetic (the powers of ν and n are precomputed). No allocation.
    pub fn moment(&self, t: &LoadTerms, oil: BearingOil) -> BearingMoment {
        let n = t.n_rpm;
        if n == 0.0 {
            return BearingMoment::default();
        }
        let [ndm128, n06, n14, drag_n] = t.speed;
        let phi_ish = 1.0 / (1.0 + 1.84e-9 * ndm128 * oil.p064);
        let phi_rs = (-self.rs * oil.nu * n).exp();
        let m_rr = phi_ish * phi_rs * t.g_rr * n06 * oil.p060;
        let phi_bl = (-2.6e-8 * n14 * oil.p140 * self.dm).exp();
        let mu_sl = phi_bl * self.mu_bl + (1.0 - phi_bl) * self.mu_ehl;
        let m_drag = n * n * self.drag1 + self.drag2 * drag_n * oil.p1379;
        BearingMoment {
            rolling: N_M_PER_N_MM * m_rr,
            sliding: N_M_PER_N_MM * t.g_sl * mu_sl,
            seal: N_M_PER_N_MM * self.m_seal,
            drag: N_M_PER_N_MM * m_drag,
        }
    }
}
