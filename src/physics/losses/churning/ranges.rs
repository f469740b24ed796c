//! Where a churning model is used outside the range it was fitted or derived on.
//!
//! Checked: the ranges the models themselves define, Stavytskyi's comparison gears and the
//! dip-lubrication speed; the fitted ranges of geometry and immersion of Changenet & Velex 2007
//! and of Seetharaman–Kahraman could not be found in a source (docs/physics.md §5 "Tested
//! ranges" says what was searched), so they are not invented here.
//!
//! - Changenet–Velex: `Re_c = ω r_p b/ν` between the two laws (6000–9000 by default): the paper
//!   gives no law there; the power comes from the log-linear bridge (docs/physics.md §5). And,
//!   at every point, the two laws more than [`LAW_FACTOR_MAX`] apart at the bridge ends for the
//!   current oil, with the factor: the result then jumps by about that factor where the bridge
//!   is crossed.
//! - Stavytskyi: the geometry of Blok's comparison gears ([`STAVYTSKYI_TESTED`], seed 001).
//! - Stavytskyi: above the filling limit (V₃ = 0) the Coriolis term has collapsed; that regime
//!   follows from reconstruction R3 (absolute bath pressure), and the paper reports only a
//!   "slight" fall at 5000–7000 rpm, so the computed fall is not backed by the paper.
//! - Seetharaman–Kahraman: face Reynolds number above the laminar–turbulent transition: the mixed
//!   plate law there is derived (White), not part of seed 000's fitted or tested range.

use super::{ChangenetJoin, ChurningGear, GearChurning, OilState};
use crate::physics::units::MM_PER_M;

/// One kind of out-of-range use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RangeCheck {
    /// Changenet–Velex between its low and high Re_c laws.
    ChangenetBridge,
    /// Changenet–Velex whose two laws differ by more than [`LAW_FACTOR_MAX`] at the bridge ends
    /// for the current oil (whatever the speed: the result then depends steeply on the oil
    /// temperature wherever the bridge is crossed).
    ChangenetLawFactor,
    /// Stavytskyi above the filling limit speed.
    StavytskyiAboveFillingLimit,
    /// Seetharaman–Kahraman with turbulent faces.
    SeetharamanTurbulentFaces,
    /// Any model: the gear's pitch-line speed above the dip-lubrication range
    /// ([`DIP_PITCH_SPEED_MAX`]).
    DipSpeed,
    /// Changenet–Velex with the crossing join using a law outside its Re_c regime (the low law
    /// above `re_c_high` or the high law below `re_c_low`).
    ChangenetCrossingOutside,
}

/// Highest pitch-line speed of dip (splash) lubrication, m/s: "suitable for up to 12.5 m/s
/// (2500 ft/min) peripheral speed" for a typical helical gear unit with guards and tanks for
/// individual gears, M. J. Neale (ed.), *The Tribology Handbook*, section C16 "Dip, splash
/// systems" (a high-speed unit with a guard: "normally satisfactory up to 25 m/s"). No fitted
/// speed range of the Changenet–Velex laws was found (the paper was not accessible); the
/// measurements behind the three churning models are dip-lubrication tests, so a gear churning
/// faster than dip lubrication is used is outside what they describe.
pub const DIP_PITCH_SPEED_MAX: f64 = 12.5;

/// The out-of-range use of any churning model at pitch-line speed `v` (m/s, sign irrelevant):
/// above [`DIP_PITCH_SPEED_MAX`], with the speed.
pub fn above_dip_speed(v: f64) -> Option<(RangeCheck, f64)> {
    (v.abs() > DIP_PITCH_SPEED_MAX).then_some((RangeCheck::DipSpeed, v.abs()))
}

impl RangeCheck {
    /// Every check, in output order.
    pub const ALL: [RangeCheck; 6] = [
        RangeCheck::ChangenetBridge,
        RangeCheck::ChangenetLawFactor,
        RangeCheck::StavytskyiAboveFillingLimit,
        RangeCheck::SeetharamanTurbulentFaces,
        RangeCheck::DipSpeed,
        RangeCheck::ChangenetCrossingOutside,
    ];

    /// Position in [`Self::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The range, in words.
    pub fn range(self) -> &'static str {
        match self {
            RangeCheck::ChangenetBridge => {
                "Changenet–Velex Re_c between the low and high laws (6000–9000): no law in the paper, log-linear bridge"
            }
            RangeCheck::ChangenetLawFactor => {
                "Changenet–Velex low and high laws more than a factor 2 apart at the bridge ends \
                 (Re_c 6000 and 9000) for this oil: the log-linear bridge changes the power by that \
                 factor within 1.5× in Re_c (a few kelvin of oil temperature)"
            }
            RangeCheck::StavytskyiAboveFillingLimit => {
                "Stavytskyi above the filling limit: Coriolis term collapsed (reconstruction R3, not backed by the paper)"
            }
            RangeCheck::SeetharamanTurbulentFaces => {
                "Seetharaman–Kahraman faces above the laminar transition Re_L: derived mixed plate law"
            }
            RangeCheck::ChangenetCrossingOutside => {
                "Changenet–Velex joined where its laws cross (changenet_join = \"crossing\"): a law used outside \
                 its Re_c regime (the low law above 9000 or the high law below 6000)"
            }
            RangeCheck::DipSpeed => {
                "pitch-line speed above 12.5 m/s, the upper end of dip lubrication (Tribology Handbook C16): \
                 faster than the dip-lubrication tests behind the churning models"
            }
        }
    }

    /// Name of the quantity whose seen range is reported.
    pub fn quantity(self) -> &'static str {
        match self {
            RangeCheck::ChangenetBridge => "Re_c",
            RangeCheck::ChangenetLawFactor => "law factor",
            RangeCheck::StavytskyiAboveFillingLimit => "speed rpm",
            RangeCheck::SeetharamanTurbulentFaces => "Re_L",
            RangeCheck::DipSpeed => "pitch-line speed m/s",
            RangeCheck::ChangenetCrossingOutside => "Re_c",
        }
    }
}

/// The range of the gears Stavytskyi's model was compared with (Blok 1962, seed 001 §3 and
/// table 1): module 1.5–5 mm, face width 14–24 mm, 20–102 teeth, nominal pitch diameter
/// 90–159 mm, helix 25°, at one relative immersion h/r_a = 0.55 ("the relative depth of gear
/// immersion in the oil bath is 0.55"). The speeds and oils of the comparison are in the paper's
/// Fig. 1, which the seed does not reproduce: not checked.
pub const STAVYTSKYI_TESTED: &str =
    "Stavytskyi compared with Blok's gears only: module 1.5–5 mm, face width 14–24 mm, \
     20–102 teeth, pitch diameter 90–159 mm, at immersion h/r_a 0.55 only (seed 001 §3, table 1)";

/// What lies outside [`STAVYTSKYI_TESTED`] for gear `g` (empty when inside). The immersion is
/// listed when h/r_a differs from 0.55 by more than 0.005 (its printed precision).
pub fn stavytskyi_geometry(g: &ChurningGear) -> Vec<String> {
    let mut v = Vec::new();
    let m = g.normal_module * MM_PER_M;
    if !(1.5..=5.0).contains(&m) {
        v.push(format!("module {m:.2} mm"));
    }
    let b = g.face_width * MM_PER_M;
    if !(14.0..=24.0).contains(&b) {
        v.push(format!("face width {b:.1} mm"));
    }
    if !(20..=102).contains(&g.teeth) {
        v.push(format!("{} teeth", g.teeth));
    }
    let d = 2e3 * g.pitch_radius;
    if !(90.0..=159.0).contains(&d) {
        v.push(format!("pitch diameter {d:.1} mm"));
    }
    let h = (g.immersion_depth / g.tip_radius).clamp(0.0, 2.0);
    if (h - 0.55).abs() > 0.005 {
        v.push(format!("immersion h/r_a {h:.2}"));
    }
    v
}

/// Largest factor between the two Changenet–Velex laws at the bridge ends that is not warned
/// (a choice: the bridge then changes C_m by at most 2 over 1.5× in Re_c, P ∝ ω^(3 ± 1.7)).
pub const LAW_FACTOR_MAX: f64 = 2.0;

impl GearChurning {
    /// For Changenet–Velex: [`RangeCheck::ChangenetLawFactor`] with the factor
    /// ([`super::ChangenetGear::law_factor`]) when it exceeds [`LAW_FACTOR_MAX`] at `oil` and the
    /// gear dips and turns; `None` otherwise and for the other models.
    pub fn law_disagreement(&self, omega: f64, oil: &OilState) -> Option<(RangeCheck, f64)> {
        match self {
            GearChurning::Changenet(g)
                if omega != 0.0 && g.is_immersed() && g.join() == ChangenetJoin::Bridge =>
            {
                let f = g.law_factor(oil);
                (f > LAW_FACTOR_MAX).then_some((RangeCheck::ChangenetLawFactor, f))
            }
            _ => None,
        }
    }

    /// The out-of-range use at ω (rad/s) and `oil`, with the value of [`RangeCheck::quantity`];
    /// `None` inside the range (or not immersed, or at rest).
    pub fn out_of_range(&self, omega: f64, oil: &OilState) -> Option<(RangeCheck, f64)> {
        let w = omega.abs();
        if w == 0.0 || !self.is_immersed() {
            return None;
        }
        match self {
            GearChurning::Changenet(g) => {
                let re_c = g.critical_reynolds(w, oil);
                let (lo, hi) = g.bridge();
                match g.join() {
                    ChangenetJoin::Bridge => {
                        (re_c > lo && re_c < hi).then_some((RangeCheck::ChangenetBridge, re_c))
                    }
                    ChangenetJoin::Crossing => {
                        let (cl, ch) = g.law_coefficients(w, oil);
                        ((cl <= ch && re_c > hi) || (ch < cl && re_c < lo))
                            .then_some((RangeCheck::ChangenetCrossingOutside, re_c))
                    }
                }
            }
            GearChurning::Stavytskyi(g) => (g.filling_velocity(w, oil) == 0.0).then_some((
                RangeCheck::StavytskyiAboveFillingLimit,
                w * 30.0 / std::f64::consts::PI,
            )),
            GearChurning::Seetharaman(g) => {
                let re = g.face_reynolds(w, oil);
                g.turbulent_faces(re)
                    .then_some((RangeCheck::SeetharamanTurbulentFaces, re))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::super::{ChurningConfig, ChurningModel, GearChurning};
    use super::*;

    fn model(m: ChurningModel) -> GearChurning {
        let cfg = ChurningConfig {
            model: m,
            ..Default::default()
        };
        GearChurning::new(&cfg, &fzg_wheel(0.05918)).unwrap()
    }

    #[test]
    fn stavytskyi_geometry_outside_blok_is_listed() {
        // FZG wheel: m 4.5 mm, b 14 mm, 24 teeth, d 108 mm inside; immersed to 0.55 r_a inside.
        let r_a = fzg_wheel(0.05).tip_radius;
        assert!(stavytskyi_geometry(&fzg_wheel(0.55 * r_a)).is_empty());
        // to its centre: only the immersion is outside
        assert_eq!(
            stavytskyi_geometry(&fzg_wheel(r_a)),
            vec!["immersion h/r_a 1.00".to_string()]
        );
        let g = ChurningGear {
            face_width: 40e-3,
            normal_module: 1e-3,
            ..fzg_wheel(0.55 * r_a)
        };
        assert_eq!(stavytskyi_geometry(&g).len(), 2);
        let g = ChurningGear {
            pitch_radius: 0.1,
            ..fzg_wheel(0.55 * r_a)
        };
        assert_eq!(
            stavytskyi_geometry(&g),
            vec!["pitch diameter 200.0 mm".to_string()]
        );
    }

    #[test]
    fn changenet_bridge_is_reported_only_inside_the_band() {
        let g = model(ChurningModel::Changenet);
        let oil = oil();
        let GearChurning::Changenet(c) = g else {
            unreachable!()
        };
        // speed at Re_c = 7500 and at 3000 / 12000
        let w = |re: f64| re / c.critical_reynolds(1.0, &oil);
        let (k, v) = g.out_of_range(w(7500.0), &oil).unwrap();
        assert_eq!(k, RangeCheck::ChangenetBridge);
        assert!((v - 7500.0).abs() < 1e-6);
        assert!(g.out_of_range(w(3000.0), &oil).is_none());
        assert!(g.out_of_range(w(12000.0), &oil).is_none());
        assert!(g.out_of_range(0.0, &oil).is_none());
    }

    #[test]
    fn dip_speed_is_reported_above_its_limit_only() {
        assert!(above_dip_speed(12.5).is_none());
        assert!(above_dip_speed(-3.0).is_none());
        assert_eq!(above_dip_speed(-14.0), Some((RangeCheck::DipSpeed, 14.0)));
    }

    #[test]
    fn stavytskyi_above_the_filling_limit_is_reported() {
        let g = model(ChurningModel::Stavytskyi);
        let oil = oil();
        let GearChurning::Stavytskyi(s) = g else {
            unreachable!()
        };
        let w0 = s.filling_limit_speed(&oil).unwrap();
        assert!(g.out_of_range(0.9 * w0, &oil).is_none());
        let (k, rpm) = g.out_of_range(1.1 * w0, &oil).unwrap();
        assert_eq!(k, RangeCheck::StavytskyiAboveFillingLimit);
        assert!((rpm - 1.1 * w0 * 30.0 / std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn seetharaman_turbulent_faces_are_reported() {
        let g = model(ChurningModel::Seetharaman);
        let oil = oil();
        let GearChurning::Seetharaman(s) = g else {
            unreachable!()
        };
        let w_t = 5e5 / s.face_reynolds(1.0, &oil);
        assert!(g.out_of_range(0.5 * w_t, &oil).is_none());
        assert_eq!(
            g.out_of_range(2.0 * w_t, &oil).map(|x| x.0),
            Some(RangeCheck::SeetharamanTurbulentFaces)
        );
    }

    #[test]
    fn changenet_law_factor_is_warned_above_two_only() {
        let g = model(ChurningModel::Changenet);
        let GearChurning::Changenet(c) = g else {
            unreachable!()
        };
        // thin and thick oil: the factor changes as ν^0.56 at each end; warn only above 2
        let mut seen = (false, false);
        for nu in [3e-6, 30e-6, 300e-6, 3000e-6] {
            let o = OilState {
                density: 870.0,
                kinematic_viscosity: nu,
            };
            let f = c.law_factor(&o);
            match g.law_disagreement(100.0, &o) {
                Some((k, v)) => {
                    assert_eq!(k, RangeCheck::ChangenetLawFactor);
                    assert_eq!(v, f);
                    assert!(f > LAW_FACTOR_MAX);
                    seen.0 = true;
                }
                None => {
                    assert!(f <= LAW_FACTOR_MAX, "nu {nu}: {f}");
                    seen.1 = true;
                }
            }
            assert!(g.law_disagreement(0.0, &o).is_none());
        }
        // the FZG wheel meets both cases over these oils
        assert_eq!(seen, (true, true));
        assert!(model(ChurningModel::Seetharaman)
            .law_disagreement(100.0, &oil())
            .is_none());
    }
}
