//! Minimal transverse description of an external involute gear tooth, enough for pocket
//! geometry: involute flanks from the base circle (or from the root circle when r_b ≤ r_f) to the
//! tip, and the circular-arc root model of seed 004 (§III.c.3, eq. 3–12).
//!
//! Conventions. Points of a gear are written with a *clock angle* c measured from the gear's
//! symmetry axis of the tooth space (or tooth) under study; the caller places the gear. All
//! angles in rad, lengths in m. The involute of a base circle r_b is parametrised by its *roll*
//! `t = tan α_r = √(r²/r_b² − 1)`; its polar angle measured from the point where it leaves the base
//! circle is `inv α_r = t − atan t` [std].

use super::{positive, PocketingError};
use std::f64::consts::PI;

/// Involute function `inv α = tan α − α` [std].
pub fn inv(alpha: f64) -> f64 {
    alpha.tan() - alpha
}

/// Polar angle of the involute point of roll `t` from the involute's start: `t − atan t`
/// (= inv α with t = tan α) [std].
pub fn inv_roll(t: f64) -> f64 {
    t - t.atan()
}

/// Roll `t = √(r²/r_b² − 1)` of the involute point at radius `r ≥ r_b` [std] (0 below r_b).
pub fn roll_at(r_base: f64, r: f64) -> f64 {
    let q = r / r_base;
    (q * q - 1.0).max(0.0).sqrt()
}

/// Shape of the tooth-space bottom between the two involute starts (seed 004 §III.c.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RootShape {
    /// `r_b ≤ r_f`: the involute runs down to the root circle; the bottom is a root-circle arc
    /// (seed 004, third profile type, their gear 3).
    InvoluteToRoot,
    /// One circular fillet per side, tangent to the (radial) involute start at the base circle and
    /// to the root circle, `ρ_c = (r_b² − r_f²)/(2 r_f)`, half-angle
    /// `ζ = acos(2 r_b r_f/(r_b² + r_f²))` (seed 004 eq. 12); a root-circle arc between them.
    Arc {
        /// Fillet radius ρ_c (m).
        fillet_radius: f64,
        /// Angle ζ between the involute start and the fillet centre, seen from the gear centre.
        zeta: f64,
    },
    /// The fillet of `Arc` does not fit (ζ > half space angle at the base circle η): a radial
    /// segment from the base circle down to radius `segment_end_radius`, then a fillet of radius
    /// `ρ = r_f sin η/(1 − sin η)` tangent to that segment and to the root circle at the space
    /// centre line (seed 004 eq. 4–10 with k = 1: the two fillets meet on the centre line).
    SegmentArc {
        /// Fillet radius ρ (m).
        fillet_radius: f64,
        /// Radius where the radial segment meets the fillet (m).
        segment_end_radius: f64,
    },
}

/// Transverse description of one gear's teeth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToothProfile {
    /// Number of teeth.
    pub z: f64,
    /// Reference radius `r = m_t z/2` (m).
    pub r_ref: f64,
    /// Base radius `r_b = r cos α_t` (m).
    pub r_base: f64,
    /// Tip radius (m).
    pub r_tip: f64,
    /// Root radius (m).
    pub r_root: f64,
    /// Transverse pressure angle α_t at the reference circle (rad).
    pub alpha_t: f64,
    /// Half tooth angle at the base circle `τ = s_t/(2r) + inv α_t` (rad) [std].
    pub half_tooth_base: f64,
    /// Half space angle at the base circle `η = π/z − τ` (rad) [std].
    pub half_space_base: f64,
    /// Roll of the lowest involute point (0 when the involute starts at the base circle).
    pub roll_form: f64,
    /// Roll of the tip corner `t_a = √(r_a²/r_b² − 1)`.
    pub roll_tip: f64,
    /// Space bottom model.
    pub root: RootShape,
    /// `½∮ p × dp` (origin at the gear centre) along the space bottom from the start of one
    /// flank's involute to the start of the other (rotation invariant; m²). Negative for the
    /// counter-clockwise traversal used in `areas.rs` (the bottom is crossed clockwise about the
    /// gear centre).
    pub bottom_integral: f64,
}

/// Cross product of two plane vectors.
pub(crate) fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Point at radius `r`, clock angle `c` (from +y toward +x) about the origin.
pub(crate) fn clock_point(r: f64, c: f64) -> [f64; 2] {
    let (s, co) = c.sin_cos();
    [r * s, r * co]
}

/// `½∫ p × dp` along the short circular arc of centre `e` from point `p` to point `q`
/// (both on the circle of radius `rho`) [derived: p = e + ρ(cos θ, sin θ) gives
/// ½ e × (q − p) + ½ ρ² Δθ].
pub(crate) fn arc_integral(e: [f64; 2], rho: f64, p: [f64; 2], q: [f64; 2]) -> f64 {
    let a = [p[0] - e[0], p[1] - e[1]];
    let b = [q[0] - e[0], q[1] - e[1]];
    let dtheta = cross(a, b).atan2(a[0] * b[0] + a[1] * b[1]);
    0.5 * cross(e, [q[0] - p[0], q[1] - p[1]]) + 0.5 * rho * rho * dtheta
}

impl ToothProfile {
    /// Profile from the usual gear data: `z`, normal module `m_n` (m), normal pressure angle
    /// `α_n`, reference helix angle `β` (rad), profile shift `x`, tip and root radii (m).
    ///
    /// Transverse values [std, physics.md §2]: `α_t = atan(tan α_n/cos β)`, `m_t = m_n/cos β`,
    /// `r = m_t z/2`, `r_b = r cos α_t`, `s_t = m_n(π/2 + 2x tan α_n)/cos β`.
    pub fn new(
        z: u32,
        module: f64,
        pressure_angle: f64,
        helix_angle: f64,
        x: f64,
        r_tip: f64,
        r_root: f64,
    ) -> Result<Self, PocketingError> {
        if z < 5 {
            return Err(PocketingError::InvalidInput(
                "z",
                format!("at least 5 teeth required, got {z}"),
            ));
        }
        let m_n = positive("module", module)?;
        if !(pressure_angle.is_finite() && pressure_angle > 0.0 && pressure_angle < 0.8) {
            return Err(PocketingError::InvalidInput(
                "pressure_angle",
                format!("must be in (0, 0.8) rad, got {pressure_angle}"),
            ));
        }
        if !(helix_angle.is_finite() && helix_angle.abs() < 1.1) {
            return Err(PocketingError::InvalidInput(
                "helix_angle",
                format!("must be finite with |β| < 1.1 rad, got {helix_angle}"),
            ));
        }
        if !(x.is_finite() && x.abs() <= 2.0) {
            return Err(PocketingError::InvalidInput(
                "x",
                format!("profile shift must be in [−2, 2], got {x}"),
            ));
        }
        let cb = helix_angle.cos();
        let alpha_t = (pressure_angle.tan() / cb).atan();
        let m_t = m_n / cb;
        let zf = z as f64;
        let r_ref = 0.5 * m_t * zf;
        let s_t = m_n * (0.5 * PI + 2.0 * x * pressure_angle.tan()) / cb;
        let tau = s_t / (2.0 * r_ref) + inv(alpha_t);
        Self::from_half_tooth_angle(zf, r_ref, alpha_t, tau, r_tip, r_root)
    }

    /// Profile from the half tooth angle at the base circle `τ` (used to thin teeth).
    pub fn from_half_tooth_angle(
        z: f64,
        r_ref: f64,
        alpha_t: f64,
        tau: f64,
        r_tip: f64,
        r_root: f64,
    ) -> Result<Self, PocketingError> {
        let r_tip = positive("tip_radius", r_tip)?;
        let r_root = positive("root_radius", r_root)?;
        let r_base = r_ref * alpha_t.cos();
        if r_tip <= r_root {
            return Err(PocketingError::InvalidInput(
                "tip_radius",
                format!("tip radius {r_tip} m must exceed root radius {r_root} m"),
            ));
        }
        if r_tip <= r_base * (1.0 + 1e-9) {
            return Err(PocketingError::InvalidInput(
                "tip_radius",
                format!("tip radius {r_tip} m must exceed the base radius {r_base} m"),
            ));
        }
        let eta = PI / z - tau;
        let roll_tip = roll_at(r_base, r_tip);
        if tau - inv_roll(roll_tip) <= 0.0 {
            return Err(PocketingError::InvalidInput(
                "tip_radius",
                format!("teeth are pointed below the tip radius {r_tip} m"),
            ));
        }
        let (root, roll_form) = if r_base <= r_root {
            let tf = roll_at(r_base, r_root);
            if eta + inv_roll(tf) <= 0.0 {
                return Err(PocketingError::InvalidInput(
                    "x",
                    "tooth space closed at the root circle".into(),
                ));
            }
            (RootShape::InvoluteToRoot, tf)
        } else {
            if eta <= 0.0 {
                return Err(PocketingError::InvalidInput(
                    "x",
                    "tooth space closed at the base circle".into(),
                ));
            }
            let zeta = (2.0 * r_base * r_root / (r_base * r_base + r_root * r_root)).acos();
            if zeta <= eta {
                (
                    RootShape::Arc {
                        fillet_radius: (r_base * r_base - r_root * r_root) / (2.0 * r_root),
                        zeta,
                    },
                    0.0,
                )
            } else {
                let se = eta.sin();
                let rho = r_root * se / (1.0 - se);
                (
                    RootShape::SegmentArc {
                        fillet_radius: rho,
                        segment_end_radius: (r_root + rho) * eta.cos(),
                    },
                    0.0,
                )
            }
        };
        let mut p = Self {
            z,
            r_ref,
            r_base,
            r_tip,
            r_root,
            alpha_t,
            half_tooth_base: tau,
            half_space_base: eta,
            roll_form,
            roll_tip,
            root,
            bottom_integral: 0.0,
        };
        p.bottom_integral = 2.0 * p.right_bottom_integral();
        Ok(p)
    }

    /// Same teeth thinned by the base-circle arc `dt` per tooth (both flanks by dt/2).
    pub fn thinned(&self, dt: f64) -> Result<Self, PocketingError> {
        Self::from_half_tooth_angle(
            self.z,
            self.r_ref,
            self.alpha_t,
            self.half_tooth_base - 0.5 * dt / self.r_base,
            self.r_tip,
            self.r_root,
        )
    }

    /// Radius of the lowest involute point (base or root circle).
    pub fn r_form(&self) -> f64 {
        self.r_base.max(self.r_root)
    }

    /// Transverse tooth thickness (arc) at radius `r ∈ [r_b, r_a]`: `2r(τ − inv α_r)` [std].
    pub fn thickness_at(&self, r: f64) -> f64 {
        2.0 * r * (self.half_tooth_base - inv_roll(roll_at(self.r_base, r)))
    }

    /// Right half of the space bottom (space centred on clock angle 0), from the centre line to
    /// the start of the right flank's involute: `½∫ p × dp` [derived, piecewise arcs/segments].
    fn right_bottom_integral(&self) -> f64 {
        let eta = self.half_space_base;
        let rf = self.r_root;
        match self.root {
            RootShape::InvoluteToRoot => {
                // Root arc from clock 0 to clock η_f = η + inv α_f, clockwise: ½ r_f² (−η_f).
                -0.5 * rf * rf * (eta + inv_roll(self.roll_form))
            }
            RootShape::Arc { fillet_radius, zeta } => {
                let cd = eta - zeta;
                let root = -0.5 * rf * rf * cd;
                let e = clock_point(rf + fillet_radius, cd);
                let d = clock_point(rf, cd);
                let b = clock_point(self.r_base, eta);
                root + arc_integral(e, fillet_radius, d, b)
            }
            RootShape::SegmentArc {
                fillet_radius,
                segment_end_radius,
            } => {
                let e = clock_point(rf + fillet_radius, 0.0);
                let d = clock_point(rf, 0.0);
                let c = clock_point(segment_end_radius, eta);
                // radial segment C→B passes through the centre's ray: ½ C × B = 0
                arc_integral(e, fillet_radius, d, c)
            }
        }
    }

    /// Points of the right half of the space bottom (space centred on clock 0), from the centre
    /// line to the involute start, `n` points per piece (for tests and plots).
    pub fn right_bottom_points(&self, n: usize) -> Vec<[f64; 2]> {
        let n = n.max(2);
        let eta = self.half_space_base;
        let rf = self.r_root;
        let mut pts = Vec::new();
        let arc_pts = |pts: &mut Vec<[f64; 2]>, e: [f64; 2], rho: f64, a0: f64, a1: f64| {
            for i in 0..=n {
                let a = a0 + (a1 - a0) * i as f64 / n as f64;
                pts.push([e[0] + rho * a.cos(), e[1] + rho * a.sin()]);
            }
        };
        let root_arc = |pts: &mut Vec<[f64; 2]>, c1: f64| {
            for i in 0..=n {
                pts.push(clock_point(rf, c1 * i as f64 / n as f64));
            }
        };
        match self.root {
            RootShape::InvoluteToRoot => root_arc(&mut pts, eta + inv_roll(self.roll_form)),
            RootShape::Arc { fillet_radius, zeta } => {
                let cd = eta - zeta;
                root_arc(&mut pts, cd);
                let e = clock_point(rf + fillet_radius, cd);
                let d = clock_point(rf, cd);
                let b = clock_point(self.r_base, eta);
                let a0 = (d[1] - e[1]).atan2(d[0] - e[0]);
                let a1 = a0
                    + cross([d[0] - e[0], d[1] - e[1]], [b[0] - e[0], b[1] - e[1]])
                        .atan2((d[0] - e[0]) * (b[0] - e[0]) + (d[1] - e[1]) * (b[1] - e[1]));
                arc_pts(&mut pts, e, fillet_radius, a0, a1);
            }
            RootShape::SegmentArc {
                fillet_radius,
                segment_end_radius,
            } => {
                let e = clock_point(rf + fillet_radius, 0.0);
                let d = clock_point(rf, 0.0);
                let c = clock_point(segment_end_radius, eta);
                let a0 = (d[1] - e[1]).atan2(d[0] - e[0]);
                let a1 = a0
                    + cross([d[0] - e[0], d[1] - e[1]], [c[0] - e[0], c[1] - e[1]])
                        .atan2((d[0] - e[0]) * (c[0] - e[0]) + (d[1] - e[1]) * (c[1] - e[1]));
                arc_pts(&mut pts, e, fillet_radius, a0, a1);
                for i in 0..=n {
                    let r = segment_end_radius + (self.r_base - segment_end_radius) * i as f64 / n as f64;
                    pts.push(clock_point(r, eta));
                }
            }
        }
        pts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shoelace(pts: &[[f64; 2]]) -> f64 {
        // ½ Σ p_i × p_{i+1} along an open polyline (fan integral about the origin)
        pts.windows(2).map(|w| 0.5 * cross(w[0], w[1])).sum()
    }

    #[test]
    fn thickness_at_reference_circle_matches_standard_formula() {
        for &(z, m, x, beta) in &[
            (16u32, 4.5e-3, 0.1817, 0.0),
            (24, 4.5e-3, 0.1715, 0.0),
            (76, 4e-3, 0.0, 0.0),
            (13, 3e-3, 0.3, 0.0),
            (31, 3e-3, -0.1, 0.25),
        ] {
            let a = 20f64.to_radians();
            let r = 0.5 * m * z as f64 / f64::cos(beta);
            let p = ToothProfile::new(z, m, a, beta, x, r + m * (1.0 + x), r - m * (1.25 - x)).unwrap();
            // flank points at the reference radius from the polar involute form, right flank at
            // clock +θ, left at −θ around the tooth centre: θ = τ − inv(acos(r_b/r))
            let alpha_r = (p.r_base / r).acos();
            let half = p.half_tooth_base - (alpha_r.tan() - alpha_r);
            let s_arc = 2.0 * r * half;
            let s_std = m * (0.5 * std::f64::consts::PI + 2.0 * x * a.tan()) / beta.cos();
            assert!((s_arc - s_std).abs() < 1e-12, "z {z}: {s_arc} vs {s_std}");
            assert!((p.thickness_at(r) - s_std).abs() < 1e-12);
            // base pitch = tooth + space at the base circle
            let pb = 2.0 * p.r_base * (p.half_tooth_base + p.half_space_base);
            assert!((pb - 2.0 * std::f64::consts::PI * p.r_base / z as f64).abs() < 1e-14);
        }
    }

    #[test]
    fn root_shapes_are_tangent_and_integrals_match_polylines() {
        let a = 20f64.to_radians();
        let cases = [
            (16u32, 4.5e-3, 0.1817), // segment + arc
            (24, 4.5e-3, 0.1715),    // single arc
            (76, 4e-3, 0.0),         // involute to root
            (40, 10e-3, -0.2),       // seed 004 gear 2: arc
            (20, 10e-3, 0.0),        // seed 004 gear 1: segment + arc
        ];
        let mut kinds = [0usize; 3];
        for &(z, m, x) in &cases {
            let r = 0.5 * m * z as f64;
            let p = ToothProfile::new(z, m, a, 0.0, x, r + m * (1.0 + x), r - m * (1.25 - x)).unwrap();
            let eta = p.half_space_base;
            match p.root {
                RootShape::InvoluteToRoot => kinds[0] += 1,
                RootShape::Arc { fillet_radius, zeta } => {
                    kinds[1] += 1;
                    let e = clock_point(p.r_root + fillet_radius, eta - zeta);
                    let b = clock_point(p.r_base, eta);
                    let eb = [b[0] - e[0], b[1] - e[1]];
                    // |EB| = ρ, EB ⟂ OB (tangent to the radial involute start)
                    assert!(((eb[0].hypot(eb[1])) - fillet_radius).abs() < 1e-13);
                    assert!((eb[0] * b[0] + eb[1] * b[1]).abs() < 1e-15);
                }
                RootShape::SegmentArc {
                    fillet_radius,
                    segment_end_radius,
                } => {
                    kinds[2] += 1;
                    let e = clock_point(p.r_root + fillet_radius, 0.0);
                    let c = clock_point(segment_end_radius, eta);
                    let ec = [c[0] - e[0], c[1] - e[1]];
                    assert!(((ec[0].hypot(ec[1])) - fillet_radius).abs() < 1e-13);
                    assert!((ec[0] * c[0] + ec[1] * c[1]).abs() < 1e-15);
                    assert!(segment_end_radius < p.r_base);
                }
            }
            // closed form vs fine polyline (Richardson on the chord error)
            let s1 = shoelace(&p.right_bottom_points(2000));
            let s2 = shoelace(&p.right_bottom_points(4000));
            let rich = (4.0 * s2 - s1) / 3.0;
            let exact = 0.5 * p.bottom_integral;
            assert!(
                (rich - exact).abs() < 1e-10 * exact.abs(),
                "z {z}: {rich} vs {exact}"
            );
        }
        assert_eq!(kinds, [1, 2, 2]);
    }

    #[test]
    fn invalid_profiles_are_rejected() {
        let a = 20f64.to_radians();
        assert!(ToothProfile::new(3, 1e-3, a, 0.0, 0.0, 3e-3, 1e-3).is_err());
        assert!(ToothProfile::new(20, -1e-3, a, 0.0, 0.0, 11e-3, 8e-3).is_err());
        // pointed teeth: huge tip radius
        assert!(ToothProfile::new(10, 1e-3, a, 0.0, 0.0, 8e-3, 3.75e-3).is_err());
        // tip below root
        assert!(ToothProfile::new(20, 1e-3, a, 0.0, 0.0, 8e-3, 9e-3).is_err());
        assert!(ToothProfile::new(20, 1e-3, a, 0.0, 0.0, 11e-3, 8.75e-3).is_ok());
    }
}
