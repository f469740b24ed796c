//! Path of contact and the precomputed contact-path tables (physics.md §2, §7).
//!
//! Position on the path: s, measured from the pitch point C along the transverse line of action,
//! positive towards gear 1's tip (away from gear 1's tangency point T1).
//!
//! **External mesh [std]:** T1T2 = a_w sin α_wt = (r_b1 + r_b2) tan α_wt; ρ1 = r_b1 tan α_wt + s,
//! ρ2 = r_b2 tan α_wt − s; end of contact at gear 1's tip, s_E = √(r_a1² − r_b1²) − r_b1 tan α_wt;
//! start at gear 2's tip, s_A = r_b2 tan α_wt − √(r_a2² − r_b2²).
//!
//! **Internal mesh (gear 2 = ring) \[derived\]:** both tangency points lie on the same side of C,
//! T1 between T2 and C, T1T2 = T2C − T1C = (r_b2 − r_b1) tan α_wt = a_w cos α_wt tan α_wt
//! = a_w sin α_wt (a_w = r_w2 − r_w1, a_w cos α_wt = r_b2 − r_b1). A point at s is ρ1 = r_b1 tan α_wt + s
//! from T1 and ρ2 = r_b2 tan α_wt + s from T2 (concave ring flank). The ring's tip circle
//! (r_a2 < r_w2) meets the line of action at ρ2 = √(r_a2² − r_b2²) < r_b2 tan α_wt, i.e. on the
//! other side of C: s_A = √(r_a2² − r_b2²) − r_b2 tan α_wt < 0; s_E as for the external mesh.
//! Reduced radius R = ρ1ρ2/(ρ2 − ρ1). Secondary (tip-to-tip) interference of internal meshes is not
//! checked here (geometry module).

use super::load_sharing::LoadSharing;
use super::{SlidingError, SlidingMeshInput};

/// Geometry of the path of contact (lengths in m along the transverse line of action).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPath {
    /// Start of contact A (gear 2's tip), s_A (m, usually < 0).
    pub s_a: f64,
    /// End of contact E (gear 1's tip), s_E (m, usually > 0).
    pub s_e: f64,
    /// Transverse base pitch p_bt (m).
    pub p_bt: f64,
    /// T1C = r_b1 tan α_wt (m): ρ1 at the pitch point.
    pub t1c: f64,
    /// T2C = r_b2 tan α_wt (m): ρ2 at the pitch point.
    pub t2c: f64,
    /// Internal mesh (gear 2 is a ring gear).
    pub internal: bool,
}

impl ContactPath {
    /// Path of contact from the primitive mesh scalars. Checks interference (path beyond a
    /// tangency point) and that the ring's tip circle lies outside its base circle.
    pub fn new(inp: &SlidingMeshInput) -> Result<Self, SlidingError> {
        let tan_a = inp.operating_pressure_angle.tan();
        let t1c = inp.base_radius1 * tan_a;
        let t2c = inp.base_radius2 * tan_a;
        let ra1 = inp.tip_radius1;
        let ra2 = inp.tip_radius2;
        let rb1 = inp.base_radius1;
        let rb2 = inp.base_radius2;
        if ra1 <= rb1 {
            return Err(SlidingError::Geometry(format!(
                "tip radius of gear 1 ({ra1} m) must exceed its base radius ({rb1} m)"
            )));
        }
        if ra2 <= rb2 {
            return Err(SlidingError::Geometry(format!(
                "tip radius of gear 2 ({ra2} m) must exceed its base radius ({rb2} m){}",
                if inp.internal {
                    " (ring: the involute must reach the tip circle)"
                } else {
                    ""
                }
            )));
        }
        let s_e = (ra1 * ra1 - rb1 * rb1).sqrt() - t1c;
        let s_a = if inp.internal {
            (ra2 * ra2 - rb2 * rb2).sqrt() - t2c
        } else {
            t2c - (ra2 * ra2 - rb2 * rb2).sqrt()
        };
        if s_a < -t1c * (1.0 + 1e-12) {
            return Err(SlidingError::Geometry(format!(
                "involute interference: contact would start {} m before the tangency point T1 \
                 (tip circle of gear 2 too large)",
                -t1c - s_a
            )));
        }
        if !inp.internal && s_e > t2c * (1.0 + 1e-12) {
            return Err(SlidingError::Geometry(format!(
                "involute interference: contact would end {} m beyond the tangency point T2 \
                 (tip circle of gear 1 too large)",
                s_e - t2c
            )));
        }
        if s_e <= s_a {
            return Err(SlidingError::Geometry(
                "empty path of contact (tip circles do not reach the line of action)".into(),
            ));
        }
        Ok(Self {
            s_a,
            s_e,
            p_bt: inp.transverse_base_pitch,
            t1c,
            t2c,
            internal: inp.internal,
        })
    }

    /// Length of the path of contact g_α = AE (m).
    pub fn length(&self) -> f64 {
        self.s_e - self.s_a
    }
    /// Transverse contact ratio ε_α = g_α/p_bt.
    pub fn eps_alpha(&self) -> f64 {
        self.length() / self.p_bt
    }
    /// Addendum contact ratio of gear 1, ε1 = CE/p_bt (negative if C lies beyond E).
    pub fn eps1(&self) -> f64 {
        self.s_e / self.p_bt
    }
    /// Addendum contact ratio of gear 2, ε2 = AC/p_bt (negative if C lies before A).
    pub fn eps2(&self) -> f64 {
        -self.s_a / self.p_bt
    }
    /// Curvature radius of gear 1's flank at s (m).
    pub fn rho1(&self, s: f64) -> f64 {
        self.t1c + s
    }
    /// Curvature radius of gear 2's flank at s (m; magnitude, concave for a ring).
    pub fn rho2(&self, s: f64) -> f64 {
        if self.internal {
            self.t2c + s
        } else {
            self.t2c - s
        }
    }
    /// Transverse reduced radius ρ1ρ2/(ρ1 + ρ2) (external) or ρ1ρ2/(ρ2 − ρ1) (internal) (m).
    pub fn reduced_radius_t(&self, s: f64) -> f64 {
        let (r1, r2) = (self.rho1(s), self.rho2(s));
        if self.internal {
            r1 * r2 / (r2 - r1)
        } else {
            r1 * r2 / (r1 + r2)
        }
    }
    /// Seed 003's dimensionless position n = s/(r_b1 tan α_wt).
    pub fn n(&self, s: f64) -> f64 {
        s / self.t1c
    }
}

/// One time sample of the base-pitch period: reference pair position and quadrature weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Position of the reference pair (spur) or of the reference tooth's leading end (helical), m.
    pub s_ref: f64,
    /// Quadrature weight; the weights of all samples sum to 1 (average over one base pitch).
    pub weight: f64,
    /// Index of the first element of this sample in the element table.
    pub first: usize,
    /// Number of elements (pairs, or pair × slice) in contact at this sample.
    pub count: usize,
}

/// One contact element: a tooth pair (spur) or a slice of a contact line (helical), at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactElement {
    /// Position from the pitch point (m).
    pub s: f64,
    /// Contact-line length represented (m).
    pub length: f64,
    /// ρ1, ρ2 (m, transverse).
    pub rho1: f64,
    /// See `rho1`.
    pub rho2: f64,
    /// Reduced radius in the normal section, R_t/cos β_b (m).
    pub reduced_radius: f64,
    /// Normal force per unit |T1| when gear 1 drives (1/m).
    pub force_fwd: f64,
    /// Normal force per unit |T1| when gear 2 drives (1/m).
    pub force_rev: f64,
    // --- derived, for the evaluation loop ---
    /// weight·force_fwd (1/m).
    pub pw_fwd: f64,
    /// weight·force_rev (1/m).
    pub pw_rev: f64,
    /// Line load per unit |T1|, force_fwd/length (1/m²).
    pub q_fwd: f64,
    /// force_rev/length (1/m²).
    pub q_rev: f64,
    /// |s| (m).
    pub abs_s: f64,
    /// sign(s) ∈ {−1, 0, 1}.
    pub sign_s: f64,
    /// ρ1/(r_b1 cos β_b) (moment-balance lever ratio).
    pub rho1_ratio: f64,
}

/// Mesh constants the element builder needs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ElementFrame {
    pub rb1: f64,
    pub cos_bb: f64,
}

impl ElementFrame {
    pub(crate) fn element(
        &self,
        path: &ContactPath,
        s: f64,
        length: f64,
        forces: (f64, f64),
        weight: f64,
    ) -> ContactElement {
        let (force_fwd, force_rev) = forces;
        let sign_s = if s > 0.0 {
            1.0
        } else if s < 0.0 {
            -1.0
        } else {
            0.0
        };
        ContactElement {
            s,
            length,
            rho1: path.rho1(s),
            rho2: path.rho2(s),
            reduced_radius: path.reduced_radius_t(s) / self.cos_bb,
            force_fwd,
            force_rev,
            pw_fwd: weight * force_fwd,
            pw_rev: weight * force_rev,
            q_fwd: force_fwd / length,
            q_rev: force_rev / length,
            abs_s: s.abs(),
            sign_s,
            rho1_ratio: path.rho1(s) / (self.rb1 * self.cos_bb),
        }
    }
}

/// 4-point Gauss–Legendre nodes and weights on [−1, 1].
const GL_X: [f64; 4] = [
    -0.861_136_311_594_052_6,
    -0.339_981_043_584_856_3,
    0.339_981_043_584_856_3,
    0.861_136_311_594_052_6,
];
const GL_W: [f64; 4] = [
    0.347_854_845_137_453_9,
    0.652_145_154_862_546_1,
    0.652_145_154_862_546_1,
    0.347_854_845_137_453_9,
];

/// Quadrature over one base pitch of the reference position u = s_ref − s_A ∈ [0, p_bt):
/// composite 4-point Gauss–Legendre with panel edges on every breakpoint of the integrand
/// (pair entering/leaving: u ≡ g_α − j·p_bt; a pair at the pitch point: u ≡ −s_A), so the
/// integrand is smooth on every panel. Returns (s_ref, weight) with Σ weight = 1.
pub(crate) fn base_pitch_quadrature(path: &ContactPath, nodes: usize) -> Vec<(f64, f64)> {
    let p = path.p_bt;
    let g = path.length();
    let tol = 1e-12 * p;
    let mut cuts = vec![0.0, p];
    let mut j = 1.0;
    while g - j * p > tol {
        let u = (g - j * p).rem_euclid(p);
        cuts.push(u);
        j += 1.0;
    }
    if path.s_a < 0.0 && path.s_e > 0.0 {
        cuts.push((-path.s_a).rem_euclid(p));
    }
    cuts.sort_by(|a, b| a.total_cmp(b));
    cuts.dedup_by(|a, b| (*a - *b).abs() <= tol);
    let intervals: Vec<(f64, f64)> = cuts
        .windows(2)
        .map(|w| (w[0], w[1]))
        .filter(|(a, b)| b - a > tol)
        .collect();
    let panels_total = nodes.div_ceil(GL_X.len()).max(intervals.len());
    let mut out = Vec::with_capacity(panels_total * GL_X.len() + 4 * intervals.len());
    for &(a, b) in &intervals {
        let n_pan = (((b - a) / p) * panels_total as f64).round().max(1.0) as usize;
        let h = (b - a) / n_pan as f64;
        for k in 0..n_pan {
            let lo = a + k as f64 * h;
            for (x, w) in GL_X.iter().zip(GL_W.iter()) {
                let u = lo + 0.5 * h * (1.0 + x);
                out.push((path.s_a + u, 0.5 * h * w / p));
            }
        }
    }
    out
}

/// Spur contact table: at each quadrature sample, every pair in contact at s = s_ref + k·p_bt,
/// with its load share for both power-flow directions. `b` = face width (m).
pub(crate) fn build_spur(
    path: &ContactPath,
    frame: &ElementFrame,
    sharing: LoadSharing,
    b: f64,
    nodes: usize,
) -> Result<(Vec<Sample>, Vec<ContactElement>), SlidingError> {
    let p = path.p_bt;
    let g = path.length();
    let eps = path.eps_alpha();
    if eps < 1.0 {
        return Err(SlidingError::ContactRatio {
            eps_alpha: eps,
            detail: "spur mesh with ε_α < 1: no continuous contact",
        });
    }
    if eps >= 2.0 && !sharing.supports_high_contact_ratio() {
        return Err(SlidingError::ContactRatio {
            eps_alpha: eps,
            detail: "this load-sharing model is defined for 1 <= ε_α < 2 only (use Uniform)",
        });
    }
    let quad = base_pitch_quadrature(path, nodes);
    let mut samples = Vec::with_capacity(quad.len());
    let mut elements = Vec::with_capacity(quad.len() * (eps.ceil() as usize + 1));
    let mut pos = [0.0_f64; 8];
    for &(s_ref, weight) in &quad {
        let mut n = 0;
        let mut s = s_ref;
        while s <= path.s_e && n < pos.len() {
            pos[n] = s;
            n += 1;
            s += p;
        }
        if n == 0 || s <= path.s_e {
            return Err(SlidingError::ContactRatio {
                eps_alpha: eps,
                detail: "spur tables support 1 <= ε_α < 8 pairs in contact",
            });
        }
        let first = elements.len();
        for &s in &pos[..n] {
            let (fwd, rev) = if sharing.supports_high_contact_ratio() {
                (1.0 / n as f64, 1.0 / n as f64)
            } else {
                (
                    sharing.share(s - path.s_a, g, p),
                    sharing.share(path.s_e - s, g, p),
                )
            };
            let f = 1.0 / frame.rb1; // normal force per unit torque, spur (cos β_b = 1)
            elements.push(frame.element(path, s, b, (fwd * f, rev * f), weight));
        }
        samples.push(Sample {
            s_ref,
            weight,
            first,
            count: n,
        });
    }
    Ok((samples, elements))
}

/// Minimum over a mesh cycle of the total length of the lines of contact, m [derived]: path of
/// contact of length `path_length` g_α, transverse base pitch `p_bt`, face width `b`, base helix
/// angle `beta_b`. A tooth whose line enters the zone at s (along the path) holds the part of
/// [s, s + b·tan β_b] inside [0, g_α], of length overlap/sin β_b along the line (b for a spur
/// tooth inside the zone); the total over the teeth k·p_bt apart is piecewise linear in s with
/// its breakpoints at −b·tan β_b, g_α − b·tan β_b, 0 and g_α (mod p_bt), where its minimum lies.
/// Spur: ⌊ε_α⌋·b. The same rigid line model as GEARpie's `LOAD_SHARING.LINES` (which samples it
/// on a grid).
pub fn min_contact_length(path_length: f64, p_bt: f64, b: f64, beta_b: f64) -> f64 {
    if !(path_length > 0.0 && p_bt > 0.0 && b > 0.0) {
        return 0.0;
    }
    if beta_b < super::SPUR_BETA_B {
        return (path_length / p_bt).floor() * b;
    }
    let w = b * beta_b.tan();
    let sin_b = beta_b.sin();
    let total = |s: f64| -> f64 {
        let k0 = ((-w - s) / p_bt).floor() as i64;
        let k1 = ((path_length - s) / p_bt).ceil() as i64;
        (k0..=k1)
            .map(|k| {
                let lo = s + k as f64 * p_bt;
                ((lo + w).min(path_length) - lo.max(0.0)).max(0.0)
            })
            .sum::<f64>()
            / sin_b
    };
    [-w, path_length - w, 0.0, path_length]
        .into_iter()
        .map(|x| total(x.rem_euclid(p_bt)))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spur_path(z: f64, m: f64, alpha: f64) -> ContactPath {
        let inp = crate::physics::losses::sliding::cases::equal_pair(z as u32, m, alpha, 0.0, 0.5e-6);
        ContactPath::new(&inp).unwrap()
    }

    #[test]
    fn seed003_n_range_from_geometry() {
        // z 30/30, α 20°, standard addendum, standard centre distance: n_E = −n_A ≈ 0.4757 → 0.48
        for m in [0.002, 0.003, 0.004] {
            let p = spur_path(30.0, m, 20f64.to_radians());
            let (na, ne) = (p.n(p.s_a), p.n(p.s_e));
            assert!((ne - 0.4757).abs() < 5e-4, "n_E = {ne}");
            assert!((na + ne).abs() < 1e-12);
            assert!(((ne * 100.0).round() / 100.0 - 0.48).abs() < 1e-12);
            // base pitch in n units ≈ 0.58 = 0.24 − (−0.34) (seed 003, meshing angle 14.88°)
            assert!((p.p_bt / p.t1c - 0.58).abs() < 0.006);
            // seed 003: at a meshing angle of 14.88° (gear 1 rolled from A) tooth 1 is at n = 0.24
            // and tooth 2 at n = −0.34; roll angle θ moves the contact by r_b1 θ along the path
            let rb1 = p.t1c / 20f64.to_radians().tan();
            let s1 = p.s_a + rb1 * 14.88f64.to_radians();
            assert!((p.n(s1) - 0.24).abs() < 0.005, "{}", p.n(s1));
            assert!((p.n(s1 - p.p_bt) + 0.34).abs() < 0.005, "{}", p.n(s1 - p.p_bt));
        }
    }

    #[test]
    fn quadrature_weights_and_breakpoints() {
        let p = spur_path(30.0, 0.003, 20f64.to_radians());
        let q = base_pitch_quadrature(&p, 64);
        let sum: f64 = q.iter().map(|x| x.1).sum();
        assert!((sum - 1.0).abs() < 1e-14);
        assert!(q.len() >= 64);
        // all nodes inside [s_A, s_A + p)
        assert!(q.iter().all(|&(s, _)| s > p.s_a && s < p.s_a + p.p_bt));
        // integrates |s - c| exactly for a kink on a breakpoint (pitch point)
        let exact = {
            let (a, b) = (p.s_a, p.s_a + p.p_bt);
            (a * a + b * b) / 2.0 / p.p_bt
        };
        let num: f64 = q.iter().map(|&(s, w)| w * s.abs()).sum();
        assert!((num - exact).abs() < 1e-15, "{num} {exact}");
    }

    #[test]
    fn rejects_interference() {
        let m = 0.003;
        let alpha = 20f64.to_radians();
        let rp = 0.5 * m * 12.0;
        let rb = rp * alpha.cos();
        let inp = SlidingMeshInput {
            base_radius1: rb,
            base_radius2: 10.0 * rb,
            operating_pressure_angle: alpha,
            tip_radius1: rp + m,
            tip_radius2: 10.0 * rp + 3.0 * m,
            centre_distance: 11.0 * rp,
            face_width: 0.02,
            base_helix_angle: 0.0,
            transverse_base_pitch: std::f64::consts::PI * m * alpha.cos(),
            internal: false,
            z1: 12,
            z2: 120,
            roughness_ra1: 0.5e-6,
            roughness_ra2: 0.5e-6,
        };
        assert!(matches!(ContactPath::new(&inp), Err(SlidingError::Geometry(_))));
    }

    #[test]
    fn internal_path_geometry() {
        // pinion z 24, ring z 72, m 2 mm, α 20°, x = 0, standard ring tip r_a2 = r2 − m.
        let (m, alpha) = (0.002, 20f64.to_radians());
        let (r1, r2) = (0.024, 0.072);
        let inp = SlidingMeshInput {
            base_radius1: r1 * alpha.cos(),
            base_radius2: r2 * alpha.cos(),
            operating_pressure_angle: alpha,
            tip_radius1: r1 + m,
            tip_radius2: r2 - m,
            centre_distance: r2 - r1,
            face_width: 0.02,
            base_helix_angle: 0.0,
            transverse_base_pitch: std::f64::consts::PI * m * alpha.cos(),
            internal: true,
            z1: 24,
            z2: 72,
            roughness_ra1: 0.5e-6,
            roughness_ra2: 0.5e-6,
        };
        let p = ContactPath::new(&inp).unwrap();
        // T1T2 = a_w sin α
        assert!(((p.t2c - p.t1c) - (r2 - r1) * alpha.sin()).abs() < 1e-15);
        assert!(p.s_a < 0.0 && p.s_e > 0.0);
        // the contact point at s_A lies on the ring's tip circle (distance from O2 = r_a2)
        let rho2 = p.rho2(p.s_a);
        assert!(((inp.base_radius2.powi(2) + rho2 * rho2).sqrt() - (r2 - m)).abs() < 1e-15);
        // and the same point seen from O1 is inside the pinion's tip circle
        let rho1 = p.rho1(p.s_a);
        assert!((inp.base_radius1.powi(2) + rho1 * rho1).sqrt() < r1 + m);
        // internal meshes have a long path (ε_α ≈ 1.93 here)
        assert!(p.eps_alpha() > 1.6 && p.eps_alpha() < 2.0, "{}", p.eps_alpha());
        // concave-convex reduced radius is larger than ρ1
        assert!(p.reduced_radius_t(0.0) > p.rho1(0.0));
    }

    #[test]
    fn min_contact_length_matches_a_fine_scan_and_the_spur_count() {
        // spur: ⌊ε_α⌋ lines of length b
        assert_eq!(min_contact_length(1.44, 1.0, 0.014, 0.0), 0.014);
        assert_eq!(min_contact_length(2.1, 1.0, 0.014, 0.0), 0.028);
        // helical: the breakpoint minimum equals a fine scan of the phase, and lies between the
        // bounds (ε_α·ε_β − 1)·b/(ε_β cos β_b) … ε_α·b/cos β_b
        for (g, p, b, bb) in [
            (1.4, 1.0, 3.0, 0.25),
            (1.7, 1.0, 0.9, 0.3),
            (2.3, 1.0, 5.0, 0.2),
            (1.1, 1.0, 0.5, 0.6),
        ] {
            let w = b * f64::tan(bb);
            let scan = (0..20_000)
                .map(|i| {
                    let s = i as f64 / 20_000.0 * p;
                    (-10..=10)
                        .map(|k| {
                            let lo = s + k as f64 * p;
                            ((lo + w).min(g) - lo.max(0.0)).max(0.0)
                        })
                        .sum::<f64>()
                        / f64::sin(bb)
                })
                .fold(f64::INFINITY, f64::min);
            let exact = min_contact_length(g, p, b, bb);
            assert!(
                exact <= scan + 1e-12 && scan - exact < 1e-3 * scan,
                "{exact} {scan}"
            );
            assert!(exact < g / p * b / f64::cos(bb));
        }
    }
}
