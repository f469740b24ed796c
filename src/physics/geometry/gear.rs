//! Single-gear geometry: [`GearSpec`] (input) and [`GearGeometry`] (derived quantities).
//!
//! All lengths in m, angles in rad. Sources: ISO 21771 / ISO 53 relations as summarised in
//! `spec/physics.md` §2 [std], unless tagged otherwise.
//!
//! # Internal (ring) gears: sign conventions
//!
//! ISO 21771 describes an internal gear with a *negative* number of teeth (and hence negative
//! d, d_a, d_b, d_f) and keeps all external-gear formulas. Here the ring has a **positive**
//! `z` and positive diameters, and the formulas are rewritten with `z → −z, d → −d` **and
//! `x → −x`**, i.e. `x_ring(here) = −x_ring(ISO 21771)`. With this choice:
//!
//! * a positive ring shift moves the generating tool (and the ring's tooth tips and roots)
//!   **away from the ring axis**: the ring's teeth get thinner and its tip diameter larger;
//! * the ring's tooth *space* is the tooth of the external gear with the same `z, m_n, α_n, β`
//!   and the same `x` (space width at the reference circle `m_t(π/2 + 2x tan α_n)`);
//! * `d_a = d − 2 m_n (h_aP − x − k)`, `d_f = d + 2 m_n (h_fP + x)`, so `d_a < d < d_f`;
//! * ring tooth thickness on the reference circle `s_t = m_t (π/2 − 2 x tan α_n)`;
//! * the internal-mesh relation `inv α_wt = inv α_t + 2 tan α_n (x2 − x1)/(z2 − z1)` of
//!   `physics.md` §2 holds as written (this is also the convention of most textbooks that use
//!   a positive ring tooth count, e.g. the KHK technical reference).

use std::f64::consts::{FRAC_PI_2, PI};

use super::error::{finite, positive, GeometryError};
use super::involute::{inv, pressure_angle_at};
use super::profile::{ProfileInput, ToothProfile};

/// Input description of one cylindrical involute gear (SI units, angles in rad).
///
/// Construct with [`GearSpec::new`] (ISO 53 basic-rack defaults) and adjust the public fields
/// or use the `with_*` setters.
#[derive(Debug, Clone, PartialEq)]
pub struct GearSpec {
    /// Number of teeth (positive also for an internal gear).
    pub z: u32,
    /// Normal module m_n \[m\].
    pub mn: f64,
    /// Normal pressure angle α_n \[rad\].
    pub alpha_n: f64,
    /// Helix angle β on the reference cylinder, magnitude \[rad\] (0 = spur). Hand not needed.
    pub beta: f64,
    /// Profile shift coefficient x [-] (for a ring see the module docs: `x = −x_ISO`).
    pub x: f64,
    /// Face width b \[m\].
    pub b: f64,
    /// True for an internal (ring) gear.
    pub internal: bool,
    /// Tip diameter override \[m\]; takes precedence over the nominal value.
    pub tip_diameter: Option<f64>,
    /// Root diameter override \[m\]; takes precedence over the nominal value.
    pub root_diameter: Option<f64>,
    /// Addendum factor h_aP* of the gear (basic rack dedendum) [-], default 1.0.
    pub ha_p: f64,
    /// Dedendum factor h_fP* of the gear (= tool addendum) [-], default 1.25.
    pub hf_p: f64,
    /// Tool tip radius factor ρ_fP* [-] (radius ρ_fP* m_n in the normal section), default 0.25.
    pub rho_fp: f64,
    /// Tip shortening factor k [-], default 0.
    pub k: f64,
}

impl GearSpec {
    /// External gear with the ISO 53 defaults h_aP* = 1, h_fP* = 1.25, ρ_fP* = 0.25, k = 0
    /// and no tip/root override. `mn`, `b` in m; `alpha_n`, `beta` in rad.
    pub fn new(z: u32, mn: f64, alpha_n: f64, beta: f64, x: f64, b: f64) -> Self {
        GearSpec {
            z,
            mn,
            alpha_n,
            beta,
            x,
            b,
            internal: false,
            tip_diameter: None,
            root_diameter: None,
            ha_p: 1.0,
            hf_p: 1.25,
            rho_fp: 0.25,
            k: 0.0,
        }
    }

    /// Make it an internal (ring) gear.
    pub fn with_internal(mut self, internal: bool) -> Self {
        self.internal = internal;
        self
    }
    /// Tip diameter override \[m\].
    pub fn with_tip_diameter(mut self, d_a: f64) -> Self {
        self.tip_diameter = Some(d_a);
        self
    }
    /// Root diameter override \[m\].
    pub fn with_root_diameter(mut self, d_f: f64) -> Self {
        self.root_diameter = Some(d_f);
        self
    }
    /// Basic-rack factors: addendum h_aP*, dedendum h_fP*, tool tip radius ρ_fP*.
    pub fn with_rack(mut self, ha_p: f64, hf_p: f64, rho_fp: f64) -> Self {
        self.ha_p = ha_p;
        self.hf_p = hf_p;
        self.rho_fp = rho_fp;
        self
    }
    /// Tip shortening factor k.
    pub fn with_tip_shortening(mut self, k: f64) -> Self {
        self.k = k;
        self
    }

    /// Same gear with every length multiplied by `f` (module, face width, overrides).
    /// Used by the unit-scaling tests and handy for mm → m conversion (`f = 1e-3`).
    pub fn scaled(&self, f: f64) -> Self {
        let mut s = self.clone();
        s.mn *= f;
        s.b *= f;
        s.tip_diameter = s.tip_diameter.map(|d| d * f);
        s.root_diameter = s.root_diameter.map(|d| d * f);
        s
    }

    fn check(&self) -> Result<(), GeometryError> {
        if self.z < 2 {
            return Err(GeometryError::InvalidParameter {
                name: "z",
                value: f64::from(self.z),
                requirement: "number of teeth must be at least 2",
            });
        }
        positive("mn", self.mn)?;
        positive("b", self.b)?;
        finite("x", self.x)?;
        finite("k", self.k)?;
        if !(self.alpha_n > 0.0 && self.alpha_n < FRAC_PI_2) {
            return Err(GeometryError::InvalidParameter {
                name: "alpha_n",
                value: self.alpha_n,
                requirement: "normal pressure angle must lie in (0, π/2) rad",
            });
        }
        if !(self.beta >= 0.0 && self.beta < FRAC_PI_2) {
            return Err(GeometryError::InvalidParameter {
                name: "beta",
                value: self.beta,
                requirement: "helix angle magnitude must lie in [0, π/2) rad",
            });
        }
        if !(self.ha_p.is_finite() && self.ha_p >= 0.0) {
            return Err(GeometryError::InvalidParameter {
                name: "ha_p",
                value: self.ha_p,
                requirement: "addendum factor must be finite and >= 0",
            });
        }
        positive("hf_p", self.hf_p)?;
        if !(self.rho_fp.is_finite() && self.rho_fp >= 0.0) {
            return Err(GeometryError::InvalidParameter {
                name: "rho_fp",
                value: self.rho_fp,
                requirement: "tool tip radius factor must be finite and >= 0",
            });
        }
        if let Some(d) = self.tip_diameter {
            positive("tip_diameter", d)?;
        }
        if let Some(d) = self.root_diameter {
            positive("root_diameter", d)?;
        }
        Ok(())
    }
}

/// Derived geometry of one gear (SI). Built once; all fields are plain numbers.
///
/// Transverse quantities carry the subscript t. "Thickness"/"width" are arc lengths on the
/// named circle. For a ring, "tooth" is the ring's own tooth (material pointing inwards) and
/// "tip" is its inner circle.
#[derive(Debug, Clone, PartialEq)]
pub struct GearGeometry {
    /// The input this was built from.
    pub spec: GearSpec,
    /// Transverse pressure angle `α_t = atan(tan α_n / cos β)` \[rad\].
    pub alpha_t: f64,
    /// Base helix angle `β_b = asin(sin β cos α_n)` \[rad\].
    pub beta_b: f64,
    /// Transverse module `m_t = m_n / cos β` \[m\].
    pub m_t: f64,
    /// Reference diameter `d = m_t z` \[m\].
    pub d: f64,
    /// Base diameter `d_b = d cos α_t` \[m\].
    pub d_b: f64,
    /// Tip diameter \[m\] (override or nominal; ring: the inner circle).
    pub d_a: f64,
    /// Root diameter \[m\] (override or nominal; ring: the outer circle).
    pub d_f: f64,
    /// Form diameter: where the involute meets the root fillet \[m\].
    pub d_form: f64,
    /// Transverse pitch `p_t = π m_t` \[m\].
    pub p_t: f64,
    /// Transverse base pitch `p_bt = π m_t cos α_t` \[m\].
    pub p_bt: f64,
    /// Normal pitch `p_n = π m_n` \[m\].
    pub p_n: f64,
    /// Normal base pitch `p_bn = π m_n cos α_n` \[m\].
    pub p_bn: f64,
    /// Transverse tooth thickness on the reference circle \[m\]:
    /// external `m_t(π/2 + 2x tan α_n)`, ring `m_t(π/2 − 2x tan α_n)`.
    pub s_t: f64,
    /// Normal tooth thickness on the reference cylinder `s_n = s_t cos β` \[m\].
    pub s_n: f64,
    /// Transverse tooth thickness (arc) on the tip circle \[m\].
    pub s_at: f64,
    /// Transverse space width (arc) on the tip circle \[m\] (the opening of a tooth space).
    pub e_at: f64,
    /// Tooth height `|d_a − d_f|/2` \[m\].
    pub h: f64,
    /// Effective tool dedendum factor `h_fP,eff` implied by the actual root diameter [-].
    pub hf_p_eff: f64,
    /// Tool tip (fillet) radius actually used \[m\] (`ρ_fP* m_n` unless reduced).
    pub rho_f: f64,
    /// True if `ρ_fP* m_n` did not fit in the tool tooth / tooth space and was reduced to the
    /// largest value that fits (full-radius root).
    pub rho_reduced: bool,
    /// Undercut limit of the profile shift (external only)
    /// `x_min = h_FfP* − z sin²α_t /(2 cos β)`, `h_FfP* = h_fP,eff − ρ_fP*(1 − sin α_n)`.
    pub x_min: Option<f64>,
    /// True if the tooth is undercut (`x < x_min`): a warning, not an error.
    pub undercut: bool,
    profile: ToothProfile,
}

impl GearGeometry {
    /// Derive the geometry of one gear. Errors for physically impossible data: root circle at
    /// or below zero, tip circle not beyond the form/base circle, pointed teeth, tool or fillet
    /// that cannot exist. Undercut is only flagged.
    pub fn new(spec: &GearSpec) -> Result<GearGeometry, GeometryError> {
        spec.check()?;
        let z = f64::from(spec.z);
        let mn = spec.mn;
        let (cb, sb) = (spec.beta.cos(), spec.beta.sin());
        // [std] ISO 21771 basic relations.
        let alpha_t = (spec.alpha_n.tan() / cb).atan();
        let beta_b = (sb * spec.alpha_n.cos()).asin();
        let m_t = mn / cb;
        let d = m_t * z;
        let d_b = d * alpha_t.cos();
        let p_t = PI * m_t;
        let p_bt = p_t * alpha_t.cos();
        let p_n = PI * mn;
        let p_bn = p_n * spec.alpha_n.cos();
        let tan_an = spec.alpha_n.tan();
        let (d_a, d_f, s_t) = if spec.internal {
            (
                spec.tip_diameter
                    .unwrap_or(d - 2.0 * mn * (spec.ha_p - spec.x - spec.k)),
                spec.root_diameter.unwrap_or(d + 2.0 * mn * (spec.hf_p + spec.x)),
                m_t * (FRAC_PI_2 - 2.0 * spec.x * tan_an),
            )
        } else {
            (
                spec.tip_diameter
                    .unwrap_or(d + 2.0 * mn * (spec.ha_p + spec.x - spec.k)),
                spec.root_diameter.unwrap_or(d - 2.0 * mn * (spec.hf_p - spec.x)),
                m_t * (FRAC_PI_2 + 2.0 * spec.x * tan_an),
            )
        };
        check_diameters(spec, d, d_a, d_f, d_b)?;
        let hf_p_eff = if spec.internal {
            (d_f - d) / (2.0 * mn) - spec.x
        } else {
            (d / 2.0 + spec.x * mn - d_f / 2.0) / mn
        };
        let profile = ToothProfile::build(&ProfileInput {
            internal: spec.internal,
            z: spec.z,
            mn,
            alpha_n: spec.alpha_n,
            alpha_t,
            beta: spec.beta,
            x: spec.x,
            r: d / 2.0,
            r_b: d_b / 2.0,
            r_a: d_a / 2.0,
            r_f: d_f / 2.0,
            s_t,
            hf_p_eff,
            rho: spec.rho_fp * mn,
        })?;
        let r_a = d_a / 2.0;
        let psi_a = profile.half_thickness_angle(r_a);
        let s_at = 2.0 * r_a * psi_a;
        let e_at = 2.0 * PI * r_a / z - s_at;
        check_tip_land(d_a, s_at, e_at)?;
        let (x_min, undercut) = if spec.internal {
            (None, false)
        } else {
            let rho_star = profile.rho() / mn;
            let hffp = hf_p_eff - rho_star * (1.0 - spec.alpha_n.sin());
            let x_min = hffp - z * alpha_t.sin().powi(2) / (2.0 * cb);
            (Some(x_min), profile.undercut())
        };
        Ok(GearGeometry {
            spec: spec.clone(),
            alpha_t,
            beta_b,
            m_t,
            d,
            d_b,
            d_a,
            d_f,
            d_form: 2.0 * profile.r_form(),
            p_t,
            p_bt,
            p_n,
            p_bn,
            s_t,
            s_n: s_t * cb,
            s_at,
            e_at,
            h: (d_a - d_f).abs() / 2.0,
            hf_p_eff,
            rho_f: profile.rho(),
            rho_reduced: profile.rho_reduced(),
            x_min,
            undercut,
            profile,
        })
    }

    /// Number of teeth.
    pub fn z(&self) -> u32 {
        self.spec.z
    }
    /// True for a ring gear.
    pub fn is_internal(&self) -> bool {
        self.spec.internal
    }
    /// Reference radius \[m\].
    pub fn r(&self) -> f64 {
        self.d / 2.0
    }
    /// Base radius \[m\].
    pub fn r_b(&self) -> f64 {
        self.d_b / 2.0
    }
    /// Tip radius \[m\].
    pub fn r_a(&self) -> f64 {
        self.d_a / 2.0
    }
    /// Root radius \[m\].
    pub fn r_f(&self) -> f64 {
        self.d_f / 2.0
    }
    /// Form radius (involute/fillet junction) \[m\].
    pub fn r_form(&self) -> f64 {
        self.d_form / 2.0
    }
    /// Face width \[m\].
    pub fn b(&self) -> f64 {
        self.spec.b
    }

    /// Angular half-thickness of the tooth on the involute at radius `r` \[rad\] [std]:
    /// external `ψ(r) = s_t/d + inv α_t − inv α_r`, ring `ψ(r) = s_t/d − inv α_t + inv α_r`
    /// with `cos α_r = r_b / r`. Precondition: `r ≥ r_b` (clamped to the base circle below).
    pub fn half_thickness_angle(&self, r: f64) -> f64 {
        self.profile.half_thickness_angle(r)
    }

    /// Transverse tooth thickness (arc) on the involute at radius `r` \[m\]: `2 r ψ(r)`.
    pub fn tooth_thickness_at(&self, r: f64) -> f64 {
        2.0 * r * self.half_thickness_angle(r)
    }

    /// Transverse space width (arc) on the involute at radius `r` \[m\]: `2πr/z − s(r)`.
    pub fn space_width_at(&self, r: f64) -> f64 {
        2.0 * PI * r / f64::from(self.spec.z) - self.tooth_thickness_at(r)
    }

    /// Pressure angle of the involute at radius `r` \[rad\] (`acos(r_b/r)`).
    pub fn pressure_angle_at(&self, r: f64) -> f64 {
        pressure_angle_at(r, self.r_b())
    }

    /// The transverse tooth profile (built once in [`GearGeometry::new`]).
    pub fn profile(&self) -> &ToothProfile {
        &self.profile
    }

    /// `inv α_t` (convenience for the mesh).
    pub(crate) fn inv_alpha_t(&self) -> f64 {
        inv(self.alpha_t)
    }
}

/// The diameters of a gear are possible: root and tip circles positive, the tip beyond the root
/// (inside it for a ring) and beyond the base circle (so that there is an involute).
fn check_diameters(spec: &GearSpec, d: f64, d_a: f64, d_f: f64, d_b: f64) -> Result<(), GeometryError> {
    let mn = spec.mn;
    let mm = |v: f64| v * 1e3;
    if !(d_f > 0.0) {
        return Err(GeometryError::Impossible(format!(
            "root diameter d_f = {:.6} mm is not positive (d = {:.6} mm, m_n = {:.6} mm, x = {})",
            mm(d_f),
            mm(d),
            mm(mn),
            spec.x
        )));
    }
    if !(d_a > 0.0) {
        return Err(GeometryError::Impossible(format!(
            "tip diameter d_a = {:.6} mm is not positive",
            mm(d_a)
        )));
    }
    if spec.internal {
        if !(d_f > d_a) {
            return Err(GeometryError::Impossible(format!(
                "ring gear: root diameter {:.6} mm must exceed tip diameter {:.6} mm",
                mm(d_f),
                mm(d_a)
            )));
        }
        if !(d_a > d_b) {
            return Err(GeometryError::Impossible(format!(
                "ring gear: tip circle d_a = {:.6} mm lies inside the base circle d_b = {:.6} mm (no involute there)",
                mm(d_a),
                mm(d_b)
            )));
        }
    } else {
        if !(d_a > d_f) {
            return Err(GeometryError::Impossible(format!(
                "tip diameter {:.6} mm must exceed root diameter {:.6} mm",
                mm(d_a),
                mm(d_f)
            )));
        }
        if !(d_a > d_b) {
            return Err(GeometryError::Impossible(format!(
                "tip circle d_a = {:.6} mm lies inside the base circle d_b = {:.6} mm",
                mm(d_a),
                mm(d_b)
            )));
        }
    }
    Ok(())
}

/// The tooth is not pointed and leaves a space on the tip circle: thickness `s_at` and space
/// width `e_at` on the tip circle of diameter `d_a` positive.
fn check_tip_land(d_a: f64, s_at: f64, e_at: f64) -> Result<(), GeometryError> {
    let mm = |v: f64| v * 1e3;
    if !(s_at > 0.0) {
        return Err(GeometryError::Impossible(format!(
            "tooth is pointed: thickness on the tip circle d_a = {:.6} mm would be {:.6} mm",
            mm(d_a),
            mm(s_at)
        )));
    }
    if !(e_at > 0.0) {
        return Err(GeometryError::Impossible(format!(
            "no tooth space left on the tip circle d_a = {:.6} mm (space width {:.6} mm)",
            mm(d_a),
            mm(e_at)
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn deg(a: f64) -> f64 {
        a.to_radians()
    }

    #[test]
    fn basic_relations_spur() {
        let g = GearGeometry::new(&GearSpec::new(16, 4.5e-3, deg(20.0), 0.0, 0.1817, 14e-3)).unwrap();
        assert_relative_eq!(g.d, 72e-3, max_relative = 1e-14);
        assert_relative_eq!(g.d_b, 72e-3 * deg(20.0).cos(), max_relative = 1e-14);
        assert_relative_eq!(g.d_a, 72e-3 + 2.0 * 4.5e-3 * 1.1817, max_relative = 1e-14);
        assert_relative_eq!(
            g.d_f,
            72e-3 - 2.0 * 4.5e-3 * (1.25 - 0.1817),
            max_relative = 1e-14
        );
        assert_relative_eq!(g.p_bt, PI * 4.5e-3 * deg(20.0).cos(), max_relative = 1e-14);
        assert_relative_eq!(g.h, 2.25 * 4.5e-3, max_relative = 1e-12);
        assert!(!g.undercut);
        // x_min = h_FfP − z sin²α/2 with h_FfP = 1.25 − 0.25 (1 − sin 20°)
        let xmin = 1.25 - 0.25 * (1.0 - deg(20.0).sin()) - 8.0 * deg(20.0).sin().powi(2);
        assert_relative_eq!(g.x_min.unwrap(), xmin, max_relative = 1e-12);
    }

    #[test]
    fn helical_relations() {
        let (an, b) = (deg(20.0), deg(33.5));
        let g = GearGeometry::new(&GearSpec::new(30, 3e-3, an, b, 0.0, 20e-3)).unwrap();
        assert_relative_eq!(g.alpha_t.tan(), an.tan() / b.cos(), max_relative = 1e-14);
        assert_relative_eq!(g.beta_b.sin(), b.sin() * an.cos(), max_relative = 1e-14);
        // base pitch relation p_bn = p_bt cos β_b [std]
        assert_relative_eq!(g.p_bn, g.p_bt * g.beta_b.cos(), max_relative = 1e-13);
        // base-cylinder relation tan β_b = tan β cos α_t [std]
        assert_relative_eq!(g.beta_b.tan(), b.tan() * g.alpha_t.cos(), max_relative = 1e-13);
        assert_relative_eq!(g.s_n, 3e-3 * PI / 2.0, max_relative = 1e-14);
    }

    #[test]
    fn overrides_take_precedence() {
        let s = GearSpec::new(16, 4.5e-3, deg(20.0), 0.0, 0.1817, 14e-3)
            .with_tip_diameter(82.46e-3)
            .with_root_diameter(61.0e-3);
        let g = GearGeometry::new(&s).unwrap();
        assert_eq!(g.d_a, 82.46e-3);
        assert_eq!(g.d_f, 61.0e-3);
        assert_relative_eq!(
            g.hf_p_eff,
            (36e-3 + 0.1817 * 4.5e-3 - 30.5e-3) / 4.5e-3,
            max_relative = 1e-12
        );
    }

    #[test]
    fn ring_conventions() {
        let m = 1.5e-3;
        let x = 0.2;
        let g =
            GearGeometry::new(&GearSpec::new(71, m, deg(20.0), 0.0, x, 20e-3).with_internal(true)).unwrap();
        assert!(g.d_a < g.d && g.d < g.d_f);
        assert_relative_eq!(g.d_a, g.d - 2.0 * m * (1.0 - x), max_relative = 1e-14);
        assert_relative_eq!(g.d_f, g.d + 2.0 * m * (1.25 + x), max_relative = 1e-14);
        // ring space width at the reference circle = tooth thickness of the external gear
        // with the same z and x
        let e = GearGeometry::new(&GearSpec::new(71, m, deg(20.0), 0.0, x, 20e-3)).unwrap();
        assert_relative_eq!(g.space_width_at(g.r()), e.s_t, max_relative = 1e-12);
        assert_relative_eq!(g.s_t + e.s_t, g.p_t, max_relative = 1e-14);
        // thicker ring teeth towards the root
        assert!(g.tooth_thickness_at(g.r_f() * 0.999) > g.tooth_thickness_at(g.r_a()));
        assert!(g.x_min.is_none() && !g.undercut);
    }

    #[test]
    fn impossible_data_are_errors() {
        let an = deg(20.0);
        // root circle below zero
        let s = GearSpec::new(2, 1e-3, an, 0.0, 0.0, 1e-2);
        assert!(matches!(GearGeometry::new(&s), Err(GeometryError::Impossible(_))));
        // tip inside base circle (override)
        let s = GearSpec::new(30, 2e-3, an, 0.0, 0.0, 1e-2).with_tip_diameter(55e-3);
        assert!(GearGeometry::new(&s).is_err());
        // pointed tooth: huge shift
        let s = GearSpec::new(12, 2e-3, an, 0.0, 1.5, 1e-2);
        let e = GearGeometry::new(&s).unwrap_err();
        assert!(e.to_string().contains("pointed"), "{e}");
        // invalid parameters
        assert!(GearGeometry::new(&GearSpec::new(20, -1.0, an, 0.0, 0.0, 1e-2)).is_err());
        assert!(GearGeometry::new(&GearSpec::new(20, 1e-3, 0.0, 0.0, 0.0, 1e-2)).is_err());
        assert!(GearGeometry::new(&GearSpec::new(20, 1e-3, an, 2.0, 0.0, 1e-2)).is_err());
        assert!(GearGeometry::new(&GearSpec::new(20, 1e-3, an, 0.0, f64::NAN, 1e-2)).is_err());
        // ring whose tip circle is inside its base circle
        let s = GearSpec::new(20, 2e-3, an, 0.0, -0.8, 1e-2).with_internal(true);
        assert!(GearGeometry::new(&s).is_err());
    }

    #[test]
    fn undercut_is_a_flag() {
        let g = GearGeometry::new(&GearSpec::new(9, 2e-3, deg(20.0), 0.0, 0.0, 1e-2)).unwrap();
        assert!(g.undercut);
        assert!(g.x_min.unwrap() > 0.0);
        let g = GearGeometry::new(&GearSpec::new(9, 2e-3, deg(20.0), 0.0, 0.6, 1e-2)).unwrap();
        assert!(!g.undercut);
    }

    #[test]
    fn lengths_scale_with_module() {
        let s = GearSpec::new(23, 3.0, deg(20.0), deg(15.0), 0.3, 25.0);
        let mm = GearGeometry::new(&s).unwrap();
        let m = GearGeometry::new(&s.scaled(1e-3)).unwrap();
        for (a, b) in [
            (mm.d_a, m.d_a),
            (mm.d_f, m.d_f),
            (mm.d_form, m.d_form),
            (mm.s_at, m.s_at),
            (mm.e_at, m.e_at),
            (mm.p_bt, m.p_bt),
        ] {
            assert_relative_eq!(a * 1e-3, b, max_relative = 1e-11);
        }
        assert_relative_eq!(mm.x_min.unwrap(), m.x_min.unwrap(), max_relative = 1e-12);
    }
}
