//! Pocket geometry as a function of the driver rotation φ1 (seed 004, re-derived; closed form).
//!
//! # Frame and kinematics
//!
//! One *family* of pockets: the space of gear S entered by a tooth of gear T. Family
//! [`PocketFamilyKind::SpaceOfGear2`] has S = gear 2, T = gear 1; `SpaceOfGear1` the converse.
//! Frame: centre of S at the origin, centre of T at (0, a_w). S points are written
//! `r(sin c, cos c)` and T points `O_T + r(sin c', −cos c')` with clock angles c, c' (both grow
//! toward +x near the mesh). The space of S is centred on c = u, the tooth of T on c' = v, with
//! rolling `r_bT·v = r_bS·u` (both pitch points move together). u = v = 0 is the symmetric
//! position (tooth centred in the space, line of centres through both symmetry axes), which is
//! the origin of φ1 used everywhere (seed 004 "initial position brought back by β1").
//! Family SpaceOfGear2: φ1 = v, u = φ1 z1/z2; family SpaceOfGear1: φ1 = u.
//!
//! Backlash is split equally between the two flank pairs (tooth centred in the space): the
//! distance between the two flanks of one side along its line of action is then the constant
//! `δ = j_bn/2` [derived: `δ = r_bT(inv α_w − τ_T) + r_bS(inv α_w + η_S)`, τ/η half tooth/space
//! angles at the base circle]. With zero backlash δ = 0 and both pairs are conjugate. A slightly
//! negative backlash (rounded input data, |j_bn| < 1e-3 m_n) is removed by thinning both teeth
//! equally; more is reported as interference.
//!
//! # Radial gaps (seed 004 eq. 20–36, re-derived)
//!
//! For the right (+x) flank pair the candidates are, all from involute properties:
//! * both flanks cross their line of action inside their involute ranges (rolls
//!   `t_S = α_w − u − η_S`, `t_T = v + τ_T + α_w`): gap δ (0 = contact). The contact interval
//!   therefore has the length g_α/r_b1 in φ1 [std path of contact];
//! * tip corner Q of one gear to the involute of the other: the normal from Q to an involute is
//!   the tangent from Q to its base circle, so the distance is *tangent length minus arc length*
//!   `√(ρ² − r_b²) − r_b t_G = r_b·(θ_inv(ρ) − θ_Q)` (polar-angle offset at the same radius),
//!   foot roll `t_G = θ_Q + acos(r_b/ρ) − θ_0` (seed 004 eq. 27–28);
//!
//! and the gap is the smallest candidate whose foot lies on the involute. The left pair is the
//! mirror image (x → −x maps u → −u), so `g1(φ) = g2(−φ)` exactly and `A(φ) = A(−φ)`.
//! Naming as seed 004: S_r2 is the leading pair (+x side, in contact first when φ1 grows),
//! S_r1 the trailing pair.
//!
//! # Axial area (closed-form Green integral)
//!
//! The pocket is bounded by the S space (left flank, bottom, right flank up to the gap feet), the
//! two gap segments and the T tooth (flanks from the gap feet down to the tip, tip arc).
//! `A = ½∮ (x dy − y dx)` piece by piece: an involute of roll t₁→t₂ about its own centre gives
//! `±r_b²(t₂³ − t₁³)/6` (seed 004 eq. 39–42, `0.5 r_b² θ³/3`); a piece about a shifted centre C
//! adds `½ C × (q₂ − q₁)`; arcs `½ R² Δθ`, segments `½ p × q`. No numerical quadrature.
//!
//! The pocket exists on `|φ1| ≤ φ_max`: while the tip-land midpoint of the entering tooth is
//! inside the tip circle of the space's gear (`cos v = (a² + r_aT² − r_aS²)/(2 a r_aT)`; for seed
//! 004's 76/76 pair this gives ±13.0°, exactly the range of its figures 11–12), and, should that
//! come first, while both gaps have a foot on an involute (beyond, a gap would join two tip
//! corners). Outside, [`PocketFamily::state`] returns `None`.

use super::teeth::{cross, inv, inv_roll, PocketTeeth};
use super::{PocketMeshInput, PocketingError};

/// Which pockets: the space of which gear, entered by a tooth of the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PocketFamilyKind {
    /// Space of gear 2 entered by a tooth of gear 1 (driver).
    SpaceOfGear2,
    /// Space of gear 1 entered by a tooth of gear 2 (seed 004's figures 5–6).
    SpaceOfGear1,
}

/// How the minimal distance of one flank pair is realised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapKind {
    /// Both flanks meet their line of action: gap = δ (0 = contact).
    LineOfAction,
    /// Tip corner of the entering tooth (gear T) to the space flank (gear S).
    ToothTipToSpaceFlank,
    /// Tip corner of the space's tooth (gear S) to the entering tooth's flank (gear T).
    SpaceTipToToothFlank,
}

/// Gap of one flank pair: value and the rolls of its two end points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideGap {
    /// Minimal distance between the two flanks (m).
    pub gap: f64,
    /// Roll of the gap end point on the S flank.
    pub roll_s: f64,
    /// Roll of the gap end point on the T flank.
    pub roll_t: f64,
    /// Which candidate realises the minimum.
    pub kind: GapKind,
}

/// Pocket state at one driver angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketState {
    /// Axial leakage area = pocket transverse cross-section A_axial (m²).
    pub area: f64,
    /// Pocket volume V = A_axial·b (m³), spur.
    pub volume: f64,
    /// Gap of the trailing flank pair (m).
    pub gap1: f64,
    /// Gap of the leading flank pair (m).
    pub gap2: f64,
    /// Radial leakage surface S_r1 = gap1·b (m²).
    pub s_r1: f64,
    /// Radial leakage surface S_r2 = gap2·b (m²).
    pub s_r2: f64,
    /// Total leakage area A_out = 2 A_axial + S_r1 + S_r2 (m²), physics.md §6.
    pub a_out: f64,
    /// Gap kinds (trailing, leading).
    pub kinds: [GapKind; 2],
}

/// Mesh-level data shared by both families.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshProfiles {
    /// Gear 1 teeth (possibly thinned to remove a rounding-level negative backlash).
    pub gear1: PocketTeeth,
    /// Gear 2 teeth.
    pub gear2: PocketTeeth,
    /// Operating transverse pressure angle α_wt (rad).
    pub alpha_w: f64,
    /// Normal backlash j_bn (m), ≥ 0.
    pub backlash: f64,
    /// Centre distance a_w (m).
    pub centre_distance: f64,
    /// Face width (m).
    pub face_width: f64,
}

impl MeshProfiles {
    /// Build and check both profiles and the operating pressure angle
    /// `cos α_wt = a cos α_t / a_w` [std, physics.md §2].
    pub fn new(inp: &PocketMeshInput) -> Result<Self, PocketingError> {
        let b = super::positive("face_width", inp.face_width)?;
        let g1 = PocketTeeth::new(
            inp.z1,
            inp.module,
            inp.pressure_angle,
            inp.helix_angle,
            inp.x1,
            inp.tip_radius1,
            inp.root_radius1,
            inp.rho_fp1,
            b,
        )?;
        let g2 = PocketTeeth::new(
            inp.z2,
            inp.module,
            inp.pressure_angle,
            inp.helix_angle,
            inp.x2,
            inp.tip_radius2,
            inp.root_radius2,
            inp.rho_fp2,
            b,
        )?;
        let aw = super::positive("centre_distance", inp.centre_distance)?;
        let cw = (g1.r_ref + g2.r_ref) * g1.alpha_t.cos() / aw;
        if !(cw > 0.0 && cw < 1.0) {
            return Err(PocketingError::InvalidInput(
                "centre_distance",
                format!("cos α_wt = {cw} is not in (0, 1)"),
            ));
        }
        let alpha_w = cw.acos();
        if aw - g1.r_tip - g2.r_root <= 0.0 || aw - g2.r_tip - g1.r_root <= 0.0 {
            return Err(PocketingError::Interference(
                "a tip circle reaches the mating root circle (no tip clearance)".into(),
            ));
        }
        if aw <= g1.r_tip.max(g2.r_tip) || g1.r_tip + g2.r_tip <= aw {
            return Err(PocketingError::InvalidInput(
                "centre_distance",
                "tip circles must overlap and not contain the mating centre".into(),
            ));
        }
        // δ = j_bn / 2 [derived, module doc]
        let half =
            g1.r_base * (inv(alpha_w) - g1.half_tooth_base) + g2.r_base * (inv(alpha_w) + g2.half_space_base);
        let (gear1, gear2, backlash) = if half >= 0.0 {
            (g1, g2, 2.0 * half)
        } else if -2.0 * half < 1e-3 * inp.module {
            // rounding-level interference: thin both teeth by j/2 each (base-circle arc)
            (g1.thinned(-half)?, g2.thinned(-half)?, 0.0)
        } else {
            return Err(PocketingError::Interference(format!(
                "negative normal backlash {:.3e} m: centre distance too small for the profile \
                 shifts",
                2.0 * half
            )));
        };
        Ok(Self {
            gear1,
            gear2,
            alpha_w,
            backlash,
            centre_distance: aw,
            face_width: b,
        })
    }

    /// Length of the path of contact `g_α = √(r_a1² − r_b1²) + √(r_a2² − r_b2²) − a_w sin α_wt`
    /// [std, physics.md §2].
    pub fn path_of_contact(&self) -> f64 {
        let (g1, g2) = (&self.gear1, &self.gear2);
        (g1.r_tip.powi(2) - g1.r_base.powi(2)).sqrt() + (g2.r_tip.powi(2) - g2.r_base.powi(2)).sqrt()
            - self.centre_distance * self.alpha_w.sin()
    }
}

/// Closed-form pocket geometry of one family.
#[derive(Debug, Clone, PartialEq)]
pub struct PocketFamily {
    /// Which family.
    pub kind: PocketFamilyKind,
    /// Teeth of the gear owning the space (S).
    pub space: PocketTeeth,
    /// Teeth of the gear owning the entering tooth (T).
    pub tooth: PocketTeeth,
    a: f64,
    alpha_w: f64,
    /// dv/du = z_S/z_T.
    k: f64,
    /// du/dφ1.
    u_per_phi: f64,
    /// Gap along the line of action, δ = j_bn/2 (m).
    half_backlash: f64,
    face_width: f64,
    u_max: f64,
    /// u where the leading gap changes kind, sorted, in (−u_max, u_max).
    switches: Vec<f64>,
    /// true when φ_max is set by the tooth entry (normal case), false when by the gap validity.
    entry_limited: bool,
}

const ROLL_TOL: f64 = 1e-12;

/// Scan points per half pitch (π/z_S) when locating the end of the pocket phase and the gap-kind
/// switches; each bracket is then bisected to round-off. 64 finds the same ends and switches as
/// 512 on every test gear and bundled model
/// (`coarse_scan_finds_the_same_phase_and_switches`) at 1/8 of the closed-form evaluations.
const SCAN_STEPS_PER_HALF_PITCH: usize = 64;

fn within(t: f64, lo: f64, hi: f64) -> bool {
    t >= lo - ROLL_TOL && t <= hi + ROLL_TOL
}

impl PocketFamily {
    /// Build the family's geometry from the mesh input.
    pub fn new(inp: &PocketMeshInput, kind: PocketFamilyKind) -> Result<Self, PocketingError> {
        let mp = MeshProfiles::new(inp)?;
        Self::from_profiles(&mp, kind)
    }

    /// Build from already checked mesh profiles.
    pub fn from_profiles(mp: &MeshProfiles, kind: PocketFamilyKind) -> Result<Self, PocketingError> {
        Self::from_profiles_scanned(mp, kind, SCAN_STEPS_PER_HALF_PITCH)
    }

    /// As [`Self::from_profiles`] with `steps` scan points per half pitch of S for the phase end
    /// and the gap-kind switches (each then bisected to round-off).
    pub(crate) fn from_profiles_scanned(
        mp: &MeshProfiles,
        kind: PocketFamilyKind,
        steps: usize,
    ) -> Result<Self, PocketingError> {
        let (space, tooth, u_per_phi) = match kind {
            PocketFamilyKind::SpaceOfGear2 => (mp.gear2, mp.gear1, mp.gear1.z / mp.gear2.z),
            PocketFamilyKind::SpaceOfGear1 => (mp.gear1, mp.gear2, 1.0),
        };
        let mut fam = Self {
            kind,
            space,
            tooth,
            a: mp.centre_distance,
            alpha_w: mp.alpha_w,
            k: space.z / tooth.z,
            u_per_phi,
            half_backlash: 0.5 * mp.backlash,
            face_width: mp.face_width,
            u_max: 0.0,
            switches: Vec::new(),
            entry_limited: false,
        };
        fam.find_range(steps)?;
        Ok(fam)
    }

    /// Half-range of the pocket phase in φ1: the pocket exists for |φ1| ≤ φ_max (rad).
    pub fn phase_limit(&self) -> f64 {
        self.u_max / self.u_per_phi
    }

    /// Whether φ_max is the tooth-entry angle (true) or the end of the gap definitions (false).
    pub fn phase_limited_by_entry(&self) -> bool {
        self.entry_limited
    }

    /// Face width b (m).
    pub fn face_width(&self) -> f64 {
        self.face_width
    }

    /// (centre distance a_w, k = z_S/z_T, du/dφ1) for independent re-computations in tests.
    pub fn frame(&self) -> (f64, f64, f64) {
        (self.a, self.k, self.u_per_phi)
    }

    /// Normal backlash j_bn (m).
    pub fn backlash(&self) -> f64 {
        2.0 * self.half_backlash
    }

    /// φ1-interval on which the leading pair (S_r2) meets on its line of action (contact when
    /// the backlash is zero): from involute ranges of both flanks. `None` if empty.
    pub fn contact_interval_leading(&self) -> Option<(f64, f64)> {
        let (s, t) = (&self.space, &self.tooth);
        // t_S = α_w − u − η_S ∈ [t_fS, t_aS];  t_T = k u + τ_T + α_w ∈ [t_fT, t_aT]
        let lo = (self.alpha_w - s.half_space_base - s.roll_tip)
            .max((t.roll_form - t.half_tooth_base - self.alpha_w) / self.k);
        let hi = (self.alpha_w - s.half_space_base - s.roll_form)
            .min((t.roll_tip - t.half_tooth_base - self.alpha_w) / self.k);
        (lo < hi).then(|| (lo / self.u_per_phi, hi / self.u_per_phi))
    }

    /// Same for the trailing pair (S_r1): mirror image of the leading one.
    pub fn contact_interval_trailing(&self) -> Option<(f64, f64)> {
        self.contact_interval_leading().map(|(a, b)| (-b, -a))
    }

    /// φ1 values in (0, φ_max) where the integrand's formula changes (a gap changes kind),
    /// sorted; used to split quadrature panels.
    pub fn breakpoints_positive(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self
            .switches
            .iter()
            .map(|u| u.abs() / self.u_per_phi)
            .filter(|&p| p > 0.0 && p < self.phase_limit())
            .collect();
        v.sort_by(|a, b| a.total_cmp(b));
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-13);
        v
    }

    /// S-frame point of the S right flank (space centred at u) at roll t.
    fn s_right_point(&self, u: f64, t: f64) -> [f64; 2] {
        let r = self.space.r_base * (1.0 + t * t).sqrt();
        let c = u + self.space.half_space_base + inv_roll(t);
        [r * c.sin(), r * c.cos()]
    }

    /// T right flank point relative to O_T (tooth centred at v) at roll t.
    fn t_right_rel(&self, v: f64, t: f64) -> [f64; 2] {
        let r = self.tooth.r_base * (1.0 + t * t).sqrt();
        let c = v + self.tooth.half_tooth_base - inv_roll(t);
        [r * c.sin(), -r * c.cos()]
    }

    /// Gap of the right (+x, leading) flank pair at space position u, or `None` when no
    /// candidate has its foot on an involute (outside the pocket phase).
    pub fn right_side(&self, u: f64) -> Option<SideGap> {
        let (s, t) = (&self.space, &self.tooth);
        let v = self.k * u;
        let theta_s = u + s.half_space_base;
        let theta_t = v + t.half_tooth_base;
        let mut best: Option<SideGap> = None;
        let mut consider = |g: SideGap| {
            if best.map_or(true, |b| g.gap < b.gap) {
                best = Some(g);
            }
        };
        // 1. both flanks on the line of action (touching the base circles at clock ±α_w)
        let ts = self.alpha_w - theta_s;
        let tt = theta_t + self.alpha_w;
        if within(ts, s.roll_form, s.roll_tip) && within(tt, t.roll_form, t.roll_tip) {
            // the common normal of both flanks: the minimum (ties with a corner candidate at
            // the ends of the interval are resolved in its favour)
            return Some(SideGap {
                gap: self.half_backlash,
                roll_s: ts.clamp(s.roll_form, s.roll_tip),
                roll_t: tt.clamp(t.roll_form, t.roll_tip),
                kind: GapKind::LineOfAction,
            });
        }
        // 2. tip corner of T to the S flank: tangent length minus arc length
        let q = self.t_right_rel(v, t.roll_tip);
        let p = [q[0], q[1] + self.a];
        let rho = p[0].hypot(p[1]);
        if rho > s.r_base {
            let c = p[0].atan2(p[1]);
            let al = (s.r_base / rho).acos();
            let tg = c + al - theta_s;
            if within(tg, s.roll_form, s.roll_tip) {
                consider(SideGap {
                    gap: s.r_base * (theta_s + inv(al) - c),
                    roll_s: tg.clamp(s.roll_form, s.roll_tip),
                    roll_t: t.roll_tip,
                    kind: GapKind::ToothTipToSpaceFlank,
                });
            }
        }
        // 3. tip corner of S to the T flank
        let ps = self.s_right_point(u, s.roll_tip);
        let q = [ps[0], ps[1] - self.a];
        let rho = q[0].hypot(q[1]);
        if rho > t.r_base {
            let c = q[0].atan2(-q[1]);
            let al = (t.r_base / rho).acos();
            let tg = theta_t - c + al;
            if within(tg, t.roll_form, t.roll_tip) {
                consider(SideGap {
                    gap: t.r_base * (c - theta_t + inv(al)),
                    roll_s: s.roll_tip,
                    roll_t: tg.clamp(t.roll_form, t.roll_tip),
                    kind: GapKind::SpaceTipToToothFlank,
                });
            }
        }
        best
    }

    /// `½∫ p × dp` of the right half of the pocket boundary: S right flank from its involute
    /// start to the gap foot, the gap segment, the T right flank from the gap foot to the tip
    /// corner (closed form, module doc).
    fn right_half_integral(&self, u: f64, g: &SideGap) -> f64 {
        let (s, t) = (&self.space, &self.tooth);
        let v = self.k * u;
        let gs = self.s_right_point(u, g.roll_s);
        let q_gt = self.t_right_rel(v, g.roll_t);
        let q_tip = self.t_right_rel(v, t.roll_tip);
        let gt = [q_gt[0], q_gt[1] + self.a];
        let ot = [0.0, self.a];
        let rbs2 = s.r_base * s.r_base;
        let rbt2 = t.r_base * t.r_base;
        -rbs2 * (g.roll_s.powi(3) - s.roll_form.powi(3)) / 6.0
            + 0.5 * cross(gs, gt)
            + 0.5 * cross(ot, [q_tip[0] - q_gt[0], q_tip[1] - q_gt[1]])
            - rbt2 * (t.roll_tip.powi(3) - g.roll_t.powi(3)) / 6.0
    }

    /// `½∫ p × dp` of the T tip arc from the right to the left corner.
    fn tip_integral(&self, u: f64) -> f64 {
        let t = &self.tooth;
        let v = self.k * u;
        let half_tip = t.half_tooth_base - inv_roll(t.roll_tip);
        let cr = v + half_tip;
        let cl = v - half_tip;
        -t.r_tip * t.r_tip * half_tip - 0.5 * self.a * t.r_tip * (cl.sin() - cr.sin())
    }

    /// Pocket area and both side gaps at space position u (in rad of S), `None` outside.
    pub(crate) fn area_at_u(&self, u: f64) -> Option<(f64, SideGap, SideGap)> {
        let right = self.right_side(u)?;
        let left = self.right_side(-u)?;
        let area = self.space.bottom_integral
            + self.right_half_integral(u, &right)
            + self.right_half_integral(-u, &left)
            + self.tip_integral(u);
        Some((area, left, right))
    }

    /// Pocket state at driver angle φ1 (rad, 0 = symmetric position); `None` outside the pocket
    /// phase |φ1| ≤ φ_max.
    pub fn state(&self, phi1: f64) -> Option<PocketState> {
        let mut u = phi1 * self.u_per_phi;
        if u.abs() > self.u_max * (1.0 + 1e-12) {
            return None;
        }
        u = u.clamp(-self.u_max, self.u_max);
        let (area, left, right) = self.area_at_u(u)?;
        let b = self.face_width;
        Some(PocketState {
            area,
            volume: area * b,
            gap1: left.gap,
            gap2: right.gap,
            s_r1: left.gap * b,
            s_r2: right.gap * b,
            a_out: 2.0 * area + (left.gap + right.gap) * b,
            kinds: [left.kind, right.kind],
        })
    }

    /// Exact `dA/dφ1` while both pairs are on their lines of action (double contact for zero
    /// backlash), from the flux of the rigidly rotating boundaries [derived: a boundary piece
    /// rotating at ω about C sweeps `−ω(|q_end|² − |q_start|²)/2`; the gap segments lie on the
    /// lines of action and sweep nothing]: `dA/du = (r_SR² − r_SL²)/2 − k(ρ_TL² − ρ_TR²)/2`.
    /// `None` if not in that regime. Used to check the numerical derivative.
    pub fn area_rate_double_loa(&self, phi1: f64) -> Option<f64> {
        let u = phi1 * self.u_per_phi;
        let (_, l, r) = self.area_at_u(u)?;
        if l.kind != GapKind::LineOfAction || r.kind != GapKind::LineOfAction {
            return None;
        }
        let rs = |t: f64| self.space.r_base.powi(2) * (1.0 + t * t);
        let rt = |t: f64| self.tooth.r_base.powi(2) * (1.0 + t * t);
        let da_du = 0.5 * (rs(r.roll_s) - rs(l.roll_s)) - 0.5 * self.k * (rt(l.roll_t) - rt(r.roll_t));
        Some(da_du * self.u_per_phi)
    }

    /// Find u_max (largest symmetric interval where both gaps exist) and the kind switches.
    fn find_range(&mut self, steps: usize) -> Result<(), PocketingError> {
        let step = (std::f64::consts::PI / self.space.z) / steps as f64;
        let u_cap = 1.2; // rad of S: far beyond any real pocket phase
        let tol = 1e-9 * self.space.r_base;
        let ok = |u: f64| -> Result<bool, PocketingError> {
            match (self.right_side(u), self.right_side(-u)) {
                (Some(a), Some(b)) => {
                    if a.gap < -tol || b.gap < -tol {
                        Err(PocketingError::Interference(format!(
                            "flanks overlap by {:.3e} m at u = {u:.4} rad",
                            -a.gap.min(b.gap)
                        )))
                    } else {
                        Ok(true)
                    }
                }
                _ => Ok(false),
            }
        };
        if !ok(0.0)? {
            return Err(PocketingError::Numerical(
                "no pocket at the symmetric position (tooth does not reach into the space)".into(),
            ));
        }
        let mut lo = 0.0;
        let mut hi = f64::NAN;
        let mut u = step;
        while u <= u_cap {
            if ok(u)? {
                lo = u;
                u += step;
            } else {
                hi = u;
                break;
            }
        }
        if hi.is_nan() {
            return Err(PocketingError::Numerical(
                "pocket phase does not end within 1.2 rad".into(),
            ));
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if ok(mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        // keep clear of the round-off level end point (two candidates may expire together)
        let lo = lo * (1.0 - 1e-9);
        // entry of the tooth: its tip-land midpoint O_T + r_aT(sin v, −cos v) on the tip circle
        // of S: cos v = (a² + r_aT² − r_aS²)/(2 a r_aT) [derived, cosine rule]
        let (ra_t, ra_s) = (self.tooth.r_tip, self.space.r_tip);
        let cos_v = (self.a * self.a + ra_t * ra_t - ra_s * ra_s) / (2.0 * self.a * ra_t);
        let u_entry = cos_v.clamp(-1.0, 1.0).acos() / self.k;
        let entry_limited = u_entry < lo;
        let lo = lo.min(u_entry);
        if !ok(lo)? {
            return Err(PocketingError::Numerical(
                "pocket phase end is not a clean boundary".into(),
            ));
        }
        self.entry_limited = entry_limited;
        self.u_max = lo;
        // kind switches of the right gap on [−u_max, u_max] (left = mirror)
        let n = (2.0 * lo / step).ceil() as usize + 1;
        let kind_at = |u: f64| self.right_side(u.clamp(-lo, lo)).map(|g| g.kind);
        let mut switches = Vec::new();
        let mut prev_u = -lo;
        let mut prev = kind_at(prev_u);
        for i in 1..=n {
            let u = -lo + 2.0 * lo * i as f64 / n as f64;
            let k = kind_at(u);
            if k != prev {
                let (mut a, mut b) = (prev_u, u);
                for _ in 0..200 {
                    let m = 0.5 * (a + b);
                    if m <= a || m >= b {
                        break;
                    }
                    if kind_at(m) == prev {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                switches.push(0.5 * (a + b));
            }
            prev = k;
            prev_u = u;
        }
        if switches.iter().any(|&u| kind_at(u).is_none()) {
            return Err(PocketingError::Numerical(
                "a radial gap is undefined inside the pocket phase".into(),
            ));
        }
        self.switches = switches;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::cases;
    use super::*;

    #[test]
    fn coarse_scan_finds_the_same_phase_and_switches() {
        let mut inputs = vec![cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()];
        for beta in [10.0f64, 20.0, 33.5] {
            inputs.push(cases::helical(&cases::fzg_c(), beta.to_radians()));
            inputs.push(cases::helical(&cases::unequal_with_backlash(), beta.to_radians()));
        }
        for inp in inputs {
            let mp = MeshProfiles::new(&inp).unwrap();
            for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
                let fine = PocketFamily::from_profiles_scanned(&mp, kind, 512).unwrap();
                let coarse = PocketFamily::from_profiles(&mp, kind).unwrap();
                let (pf, pc) = (fine.phase_limit(), coarse.phase_limit());
                assert!(((pf - pc) / pf).abs() < 1e-12, "{kind:?}: {pf} vs {pc}");
                let (bf, bc) = (fine.breakpoints_positive(), coarse.breakpoints_positive());
                assert_eq!(bf.len(), bc.len(), "{kind:?}: {bf:?} vs {bc:?}");
                for (a, b) in bf.iter().zip(&bc) {
                    assert!((a - b).abs() < 1e-12 * pf, "{kind:?}: {bf:?} vs {bc:?}");
                }
            }
        }
    }

    fn families(inp: &PocketMeshInput) -> [PocketFamily; 2] {
        [
            PocketFamily::new(inp, PocketFamilyKind::SpaceOfGear2).unwrap(),
            PocketFamily::new(inp, PocketFamilyKind::SpaceOfGear1).unwrap(),
        ]
    }

    #[test]
    fn contact_interval_equals_path_of_contact_over_base_radius() {
        for inp in [cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()] {
            let mp = MeshProfiles::new(&inp).unwrap();
            // zero backlash: contact over g_α; with backlash the flanks face each other at the
            // constant distance δ = j_bn/2 along the line of action over g_α + δ
            let expect = (mp.path_of_contact() + 0.5 * mp.backlash) / mp.gear1.r_base;
            for f in families(&inp) {
                let (a, b) = f.contact_interval_leading().unwrap();
                assert!(
                    ((b - a) - expect).abs() < 1e-9,
                    "{:?}: {} vs {}",
                    f.kind,
                    b - a,
                    expect
                );
                let (c, d) = f.contact_interval_trailing().unwrap();
                assert!(((d - c) - expect).abs() < 1e-9);
                // gap = δ inside, > δ just outside; zero inside when backlash is zero
                let delta = 0.5 * f.backlash();
                for &(p, inside) in &[
                    (0.5 * (a + b), true),
                    (a + 1e-9, true),
                    (b - 1e-9, true),
                    (a - 1e-4, false),
                    (b + 1e-4, false),
                ] {
                    let st = f.state(p).unwrap();
                    if inside {
                        assert!((st.gap2 - delta).abs() < 1e-15, "{p}: {}", st.gap2);
                        assert_eq!(st.kinds[1], GapKind::LineOfAction);
                    } else {
                        assert!(st.gap2 > delta + 1e-13, "{p}: {}", st.gap2);
                    }
                }
            }
        }
    }

    #[test]
    fn fzg_contact_ratio_and_backlash() {
        let mp = MeshProfiles::new(&cases::fzg_c()).unwrap();
        let pbt = 2.0 * std::f64::consts::PI * mp.gear1.r_base / mp.gear1.z;
        let eps = mp.path_of_contact() / pbt;
        assert!((eps - 1.44).abs() < 0.01, "ε_α = {eps}");
        // the data are zero-backlash to rounding: thinned by < 0.1 µm
        assert_eq!(mp.backlash, 0.0);
        let inp = cases::fzg_c();
        let raw = PocketTeeth::new(
            16,
            4.5e-3,
            20f64.to_radians(),
            0.0,
            0.1817,
            inp.tip_radius1,
            inp.root_radius1,
            0.25,
            inp.face_width,
        )
        .unwrap();
        let thin = (raw.half_tooth_base - mp.gear1.half_tooth_base) * 2.0 * raw.r_base;
        assert!(thin > 0.0 && thin < 1e-7, "thinning {thin}");
    }

    #[test]
    fn area_even_gaps_mirrored_and_continuous() {
        for inp in [cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()] {
            for f in families(&inp) {
                let pm = f.phase_limit();
                let n = 2000;
                let scale = f.state(0.0).unwrap().area;
                let mut a = Vec::with_capacity(n + 1);
                for i in 0..=n {
                    let p = -pm + 2.0 * pm * i as f64 / n as f64;
                    let s = f.state(p).unwrap();
                    let m = f.state(-p).unwrap();
                    assert!((s.area - m.area).abs() < 1e-12 * s.area);
                    assert!((s.gap1 - m.gap2).abs() < 1e-15);
                    a.push(s.area);
                }
                // no jumps: second differences stay at the O(h²) level of a smooth curve
                let max_d2 = a
                    .windows(3)
                    .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
                    .fold(0.0, f64::max);
                assert!(max_d2 < 1e-3 * scale, "{:?}: second difference {max_d2}", f.kind);
                // continuity across every kind switch
                for &bp in &f.breakpoints_positive() {
                    let a = f.state(bp - 1e-10).unwrap();
                    let b = f.state(bp + 1e-10).unwrap();
                    assert!(
                        (a.area - b.area).abs() < 1e-7 * scale,
                        "{:?} jump at {bp}",
                        f.kind
                    );
                    assert!((a.gap1 - b.gap1).abs() < 1e-7 * inp.module);
                    assert!((a.gap2 - b.gap2).abs() < 1e-7 * inp.module);
                }
            }
        }
    }

    #[test]
    fn volume_minimal_at_symmetric_position_and_monotone() {
        for inp in [cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()] {
            for f in families(&inp) {
                let pm = f.phase_limit();
                let v0 = f.state(0.0).unwrap().volume;
                let mut prev = v0;
                for i in 1..=200 {
                    let v = f.state(pm * i as f64 / 200.0).unwrap().volume;
                    assert!(v > prev, "{:?}: not increasing at step {i}", f.kind);
                    prev = v;
                }
                assert!(v0 > 0.0);
            }
        }
    }

    #[test]
    fn exact_rate_in_double_contact_matches_difference_quotient() {
        let f = PocketFamily::new(&cases::seed004(), PocketFamilyKind::SpaceOfGear1).unwrap();
        let (a, b) = f.contact_interval_leading().unwrap();
        let (c, d) = f.contact_interval_trailing().unwrap();
        let (lo, hi) = (a.max(c), b.min(d));
        assert!(lo < 0.0 && hi > 0.0);
        let h = 1e-4;
        let a = |x: f64| f.state(x).unwrap().area;
        let scale = f.area_rate_double_loa(0.9 * lo).unwrap().abs();
        for i in 1..10 {
            let p = lo + (hi - lo) * i as f64 / 10.0;
            let exact = f.area_rate_double_loa(p).unwrap();
            let fd = (8.0 * (a(p + h) - a(p - h)) - (a(p + 2.0 * h) - a(p - 2.0 * h))) / (12.0 * h);
            assert!((exact - fd).abs() < 1e-7 * scale, "{p}: {exact} vs {fd}");
        }
        assert!(f.area_rate_double_loa(0.0).unwrap().abs() < 1e-12 * scale);
    }

    #[test]
    fn seed004_case_intervals_range_and_families() {
        let inp = cases::seed004();
        let [fa, fb] = families(&inp);
        let mp = MeshProfiles::new(&inp).unwrap();
        // half tooth angle β1 = s/(2r) = π/(2z) for x = 0
        let beta1 = std::f64::consts::PI / (2.0 * 76.0);
        let half = 0.5 * mp.path_of_contact() / mp.gear1.r_base;
        for f in [&fa, &fb] {
            // seed 004 eq. 20 (restored: symmetric ±(t_a − tan α) about the flank-at-pitch-point
            // origin), shifted by β1 to the symmetric-position origin
            let (a, b) = f.contact_interval_trailing().unwrap();
            assert!((a - (beta1 - half)).abs() < 1e-12 && (b - (beta1 + half)).abs() < 1e-12);
            let (c, d) = f.contact_interval_leading().unwrap();
            assert!((c + b).abs() < 1e-15 && (d + a).abs() < 1e-15);
            // pocket phase = tooth tip entering the mating tip circle: ±13.0°, the range of the
            // paper's figures 11–12
            let entry = (inp.centre_distance / (2.0 * inp.tip_radius1)).acos();
            assert!(f.phase_limited_by_entry());
            assert!((f.phase_limit() - entry).abs() < 1e-9);
            assert!((f.phase_limit().to_degrees() - 13.0).abs() < 0.01);
            // left of the origin S_r1 ≥ S_r2, right of it the opposite (seed 004 §IV.c)
            for i in 1..50 {
                let p = f.phase_limit() * i as f64 / 50.0;
                let (l, r) = (f.state(-p).unwrap(), f.state(p).unwrap());
                assert!(l.s_r1 >= l.s_r2 && r.s_r2 >= r.s_r1);
            }
        }
        // equal gears: both families are the same pocket
        for i in 0..20 {
            let p = fa.phase_limit() * (i as f64 / 10.0 - 1.0);
            let (x, y) = (fa.state(p).unwrap(), fb.state(p).unwrap());
            assert!((x.area - y.area).abs() < 1e-12 * x.area && (x.gap1 - y.gap1).abs() < 1e-15);
        }
        // unequal gears: the two families differ (each one is still even in φ1)
        let [ga, gb] = families(&cases::fzg_c());
        let (x, y) = (ga.state(0.0).unwrap(), gb.state(0.0).unwrap());
        assert!(
            (x.area - y.area).abs() > 0.01 * x.area,
            "{} vs {}",
            x.area,
            y.area
        );
    }

    /// Figures of docs/physics.md §3/6 (FZG C table, seed 004 K):
    /// `cargo test --release --lib pocket_figures -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn pocket_figures() {
        use super::super::integral::PocketTable;
        for (name, inp) in [("fzg_c", cases::fzg_c()), ("seed004", cases::seed004())] {
            let mp = MeshProfiles::new(&inp).unwrap();
            for (g, t) in [("gear 1", &mp.gear1), ("gear 2", &mp.gear2)] {
                eprintln!(
                    "{name} {g}: r_b {:.4} mm, r_form {:.4} mm, r_f {:.4} mm, roll_form {:.5}, \
                     fillet ρ {:.4} mm, undercut {}",
                    t.r_base * 1e3,
                    t.r_form() * 1e3,
                    t.r_root * 1e3,
                    t.roll_form,
                    t.profile.rho() * 1e3,
                    t.profile.undercut()
                );
            }
            for f in families(&inp) {
                let pm = f.phase_limit();
                let (a, b) = f.contact_interval_leading().unwrap();
                let (s0, se) = (f.state(0.0).unwrap(), f.state(pm).unwrap());
                let table = PocketTable::new(&f).unwrap();
                let k: Vec<String> = [0.6, 0.65, 0.7]
                    .iter()
                    .map(|cd| format!("{:.4e}", table.k_spur(*cd)))
                    .collect();
                eprintln!(
                    "{name} {:?}: φ_max {:.2}° (entry {}), S_r2 = 0 on [{:.2}°, {:.2}°], A(0) {:.3} mm², \
                     V(0) {:.2} mm³, A(φ_max) {:.2} mm², K(0.60/0.65/0.70) {k:?}",
                    f.kind,
                    pm.to_degrees(),
                    f.phase_limited_by_entry(),
                    a.to_degrees(),
                    b.to_degrees(),
                    s0.area * 1e6,
                    s0.volume * 1e9,
                    se.area * 1e6
                );
            }
        }
        // seed 004 table rows (family 2 = family 1 for equal gears)
        let f = PocketFamily::new(&cases::seed004(), PocketFamilyKind::SpaceOfGear2).unwrap();
        for d in [-13.0f64, -10.0, -8.0, -6.0, -5.0, -4.0, -3.0, -2.0, -1.0, 0.0] {
            let s = f.state(d.to_radians()).unwrap();
            eprintln!(
                "seed004 {d:>5}°: A {:.3} mm², V {:.1} mm³, S_r1 {:.2} mm², S_r2 {:.2} mm² {:?}",
                s.area * 1e6,
                s.volume * 1e9,
                s.s_r1 * 1e6,
                s.s_r2 * 1e6,
                s.kinds
            );
        }
        // FZG C power (both families, ρ 870) and the helical table (normal data kept)
        let fzg = cases::fzg_c();
        let pm = super::super::PocketingMesh::new(&fzg, 0.65).unwrap();
        for rpm in [1000.0, 3000.0, 6000.0] {
            let w = crate::physics::units::rpm_to_rad_s(rpm);
            let [a, b] = pm.family_power(w, 870.0);
            eprintln!("fzg_c {rpm} rpm: {:.2} W ({a:.2} + {b:.2})", a + b);
        }
        for beta in [0.0f64, 5.0, 10.0, 15.0, 20.0, 25.0] {
            let inp = cases::helical(&fzg, beta.to_radians());
            let mp = MeshProfiles::new(&inp).unwrap();
            let s = inp.helix_angle.tan() / mp.gear1.r_ref;
            let (mut kh, mut ks) = (0.0, 0.0);
            for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
                let t = PocketTable::new(&PocketFamily::from_profiles(&mp, kind).unwrap()).unwrap();
                ks += t.k_spur(0.65);
                kh += if beta == 0.0 {
                    t.k_spur(0.65)
                } else {
                    t.k_helical(0.65, s, 64)
                };
            }
            let w = crate::physics::units::rpm_to_rad_s(3000.0);
            let p = 16.0 * 870.0 * w.powi(3) * kh / (4.0 * std::f64::consts::PI);
            eprintln!(
                "fzg_c helical β {beta}°: K_hel/K_spur (n = 64) {:.3}, P 3000 rpm {p:.1} W",
                kh / ks
            );
        }
    }

    #[test]
    fn backlash_mesh_has_no_contact_but_constant_gap() {
        let f = PocketFamily::new(&cases::unequal_with_backlash(), PocketFamilyKind::SpaceOfGear2).unwrap();
        assert!(f.backlash() > 1e-5, "backlash {}", f.backlash());
        let st = f.state(0.0).unwrap();
        assert!(st.gap1 > 0.0 && (st.gap1 - st.gap2).abs() < 1e-15);
    }

    #[test]
    fn rejects_interfering_centre_distance() {
        let mut inp = cases::fzg_c();
        inp.centre_distance = 91.3e-3;
        assert!(matches!(
            MeshProfiles::new(&inp),
            Err(PocketingError::Interference(_))
        ));
    }
}
