//! The geometric pocketing integral K (physics.md §6) and its helical extension.
//!
//! `K = ∫ (−dV/dφ1)³ / (C_d A_out)² dφ1` over the closing phase φ1 ∈ [−φ_max, 0] (m⁵).
//! Expansion (dV/dφ1 > 0) contributes nothing: while the pocket grows it fills from the
//! surroundings (or cavitates) and the model assigns it no loss [documented choice,
//! physics.md §6].
//!
//! Numerics. `A_axial(φ1)` and the gap sum `g1 + g2` are even in φ1 and analytic between the
//! points where a gap changes kind (`PocketFamily::breakpoints_positive`). On each such panel of
//! [0, φ_max] they are represented by Chebyshev series fitted at Chebyshev points of the
//! closed-form geometry (degree doubled until the tail is at round-off level, panels split if
//! needed); `dA/dφ1` is the exact derivative of that series (spectral differentiation of the
//! analytic V; checked against the exact line-of-action flux formula and finite differences in
//! the tests). K is then integrated by adaptive Gauss–Legendre quadrature on each panel. Near
//! the minimum of V, `dV/dφ1 → 0` linearly while `A_out ≥ 2 A_min > 0`: the integrand vanishes
//! like |φ1|³, so K is finite; convergence is shown in the tests.
//!
//! Helical gears [derived, physics.md §6 "transverse slices shifted in phase"]: the face is cut
//! into n slices of width w = b/n at axial positions y_j; slice j is the spur pocket at
//! φ1 + Δ_j, `Δ_j = y_j tan β / r_1` (transverse section phase of gear 1). The slices of one
//! helical pocket are treated as ONE connected control volume with a common pressure:
//! `V = w Σ A(φ1 + Δ_j)`, exits = the two end-face cross sections `A(φ1 + Δ_0) + A(φ1 + Δ_{n−1})`
//! plus all radial gaps `w Σ (g1 + g2)(φ1 + Δ_j)`; a slice outside its pocket phase keeps the
//! area and gaps of the phase end (the space is open there). Reduces exactly to spur for β = 0
//! and converges with n. Caveat: the axial flow between slices is not modelled (it is assumed
//! free: no axial pressure gradient inside the pocket); summing independent spur pockets of
//! width b/n instead would either give K_helical = K_spur exactly (if each slice gets the share
//! w/b of the face exits — the phase shift drops out of a full-passage integral) or a loss
//! falling like 1/n² (if every slice had two full face exits), so that reading was rejected.
//! The scene uses the model's exact n → ∞ limit (`k_helical_continuum`): one spur pocket history
//! shifted in phase, integrated over the face width in closed form from the Chebyshev tables.

use super::areas::PocketFamily;
use super::PocketingError;

/// Chebyshev series on one panel [lo, hi] of φ1 ≥ 0.
#[derive(Debug, Clone, PartialEq)]
struct Panel {
    lo: f64,
    hi: f64,
    /// A_axial (m²)
    area: Vec<f64>,
    /// dA_axial/dφ1 (m²/rad)
    darea: Vec<f64>,
    /// g1 + g2 (m)
    gaps: Vec<f64>,
    /// Antiderivative of g1 + g2 in φ1 on this panel, zero at `lo` (m·rad)
    gaps_int: Vec<f64>,
    /// ∫_0^lo (g1 + g2) dφ1 (m·rad)
    gaps_int_lo: f64,
}

/// Evaluate Σ c_k T_k(x) by Clenshaw's recurrence [std].
fn clenshaw(c: &[f64], x: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c.iter().skip(1).rev() {
        let b0 = 2.0 * x * b1 - b2 + ck;
        b2 = b1;
        b1 = b0;
    }
    x * b1 - b2 + c.first().copied().unwrap_or(0.0)
}

/// Chebyshev coefficients of values at the n first-kind points `x_j = cos(π(j + ½)/n)` [std].
/// `T_k(x_j) = cos(kθ_j)` by the three-term recurrence (no trigonometric call per term).
fn cheb_coeffs(vals: &[f64]) -> Vec<f64> {
    let n = vals.len();
    let nf = n as f64;
    let mut c = vec![0.0; n];
    for (j, v) in vals.iter().enumerate() {
        let x = (std::f64::consts::PI * (j as f64 + 0.5) / nf).cos();
        let (mut t0, mut t1) = (1.0, x);
        c[0] += v;
        for ck in c.iter_mut().skip(1) {
            *ck += v * t1;
            let t2 = 2.0 * x * t1 - t0;
            t0 = t1;
            t1 = t2;
        }
    }
    c[0] /= nf;
    for ck in c.iter_mut().skip(1) {
        *ck *= 2.0 / nf;
    }
    c
}

/// Coefficients of the antiderivative (w.r.t. x ∈ [−1, 1]) of a Chebyshev series, zero at
/// x = −1 [std: `C_1 = c_0 − c_2/2`, `C_k = (c_{k−1} − c_{k+1})/(2k)` for k ≥ 2].
fn cheb_integral(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    let at = |k: usize| c.get(k).copied().unwrap_or(0.0);
    let mut out = vec![0.0; n + 1];
    out[1] = at(0) - 0.5 * at(2);
    for (k, ok) in out.iter_mut().enumerate().skip(2) {
        *ok = (at(k - 1) - at(k + 1)) / (2.0 * k as f64);
    }
    // value at x = −1: Σ C_k (−1)^k
    let at_minus_one: f64 = out
        .iter()
        .enumerate()
        .map(|(k, v)| if k % 2 == 0 { *v } else { -*v })
        .sum();
    out[0] = -at_minus_one;
    out
}

/// Coefficients of the derivative (w.r.t. x ∈ [−1, 1]) of a Chebyshev series [std recurrence
/// `c'_{k−1} = c'_{k+1} + 2k c_k`].
fn cheb_derivative(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    if n < 2 {
        return vec![0.0];
    }
    let mut d = vec![0.0; n];
    for k in (1..n).rev() {
        let next = if k + 1 < n { d[k + 1] } else { 0.0 };
        d[k - 1] = next + 2.0 * k as f64 * c[k];
    }
    d[0] *= 0.5;
    d.truncate(n - 1);
    d
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n) [std].
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 1 { 1.0 } else { p0 };
            dp = nf * (z * pn - pn1) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
        w[n - 1 - i] = w[i];
    }
    (x, w)
}

/// Closed-form geometry of one family tabulated as Chebyshev series on [0, φ_max].
#[derive(Debug, Clone, PartialEq)]
pub struct PocketTable {
    panels: Vec<Panel>,
    phi_max: f64,
    face_width: f64,
    gl_x: Vec<f64>,
    gl_w: Vec<f64>,
}

const GL_N: usize = 24;
/// Gauss–Legendre nodes per smooth sub-interval of the helical K, from the convergence study in
/// docs/performance.md (`k_helical_continuum_with`).
const HELIX_GL_NODES: usize = 8;
const MAX_DEG: usize = 256;

impl PocketTable {
    /// Tabulate a family (fits the closed-form area and gaps; errors if a fit cannot reach
    /// round-off level, which would indicate a geometry discontinuity).
    pub fn new(fam: &PocketFamily) -> Result<Self, PocketingError> {
        let phi_max = fam.phase_limit();
        let mut edges = vec![0.0];
        edges.extend(fam.breakpoints_positive());
        edges.push(phi_max);
        let eval = |p: f64| -> Result<(f64, f64), PocketingError> {
            fam.state(p)
                .map(|s| (s.area, s.gap1 + s.gap2))
                .ok_or_else(|| PocketingError::Numerical(format!("no pocket at φ1 = {p}")))
        };
        // scale for the tail test: the area at the end of the phase, the module-size gap
        let a_scale = eval(phi_max)?.0;
        let g_scale = fam.space.r_base / fam.space.z;
        let mut panels = Vec::new();
        let mut stack: Vec<(f64, f64, u32)> = edges
            .windows(2)
            .filter(|w| w[1] > w[0])
            .map(|w| (w[0], w[1], 0))
            .rev()
            .collect();
        while let Some((lo, hi, depth)) = stack.pop() {
            match Self::fit(&eval, lo, hi, a_scale, g_scale)? {
                Some(p) => panels.push(p),
                None if depth < 10 => {
                    let mid = 0.5 * (lo + hi);
                    stack.push((mid, hi, depth + 1));
                    stack.push((lo, mid, depth + 1));
                }
                None => {
                    return Err(PocketingError::Numerical(format!(
                        "pocket area not smooth on [{lo}, {hi}] rad"
                    )))
                }
            }
        }
        if panels.is_empty() {
            return Err(PocketingError::Numerical("empty pocket phase".into()));
        }
        panels.sort_by(|a, b| a.lo.total_cmp(&b.lo));
        let mut acc = 0.0;
        for p in &mut panels {
            p.gaps_int_lo = acc;
            acc += clenshaw(&p.gaps_int, 1.0);
        }
        let (gl_x, gl_w) = gauss_legendre(GL_N);
        Ok(Self {
            panels,
            phi_max,
            face_width: fam.face_width(),
            gl_x,
            gl_w,
        })
    }

    /// Table of one family built with an 8× finer scan for the phase end and the gap-kind
    /// switches than the default (high-resolution references in tests and studies).
    pub fn reference(
        inp: &super::PocketMeshInput,
        kind: super::PocketFamilyKind,
    ) -> Result<Self, PocketingError> {
        let mp = super::areas::MeshProfiles::new(inp)?;
        Self::new(&PocketFamily::from_profiles_scanned(&mp, kind, 512)?)
    }

    fn fit(
        eval: &dyn Fn(f64) -> Result<(f64, f64), PocketingError>,
        lo: f64,
        hi: f64,
        a_scale: f64,
        g_scale: f64,
    ) -> Result<Option<Panel>, PocketingError> {
        let mut n = 16;
        while n <= MAX_DEG {
            let mut va = Vec::with_capacity(n);
            let mut vg = Vec::with_capacity(n);
            for j in 0..n {
                let x = (std::f64::consts::PI * (j as f64 + 0.5) / n as f64).cos();
                let (a, g) = eval(0.5 * (lo + hi) + 0.5 * (hi - lo) * x)?;
                va.push(a);
                vg.push(g);
            }
            let ca = cheb_coeffs(&va);
            let cg = cheb_coeffs(&vg);
            let tail = |c: &[f64], scale: f64| c[c.len() - 4..].iter().all(|v| v.abs() < 1e-12 * scale);
            if tail(&ca, a_scale) && tail(&cg, g_scale) {
                let s = 2.0 / (hi - lo);
                let darea = cheb_derivative(&ca).into_iter().map(|d| d * s).collect();
                let gaps_int = cheb_integral(&cg).into_iter().map(|v| v / s).collect();
                return Ok(Some(Panel {
                    lo,
                    hi,
                    area: ca,
                    darea,
                    gaps: cg,
                    gaps_int,
                    gaps_int_lo: 0.0,
                }));
            }
            n *= 2;
        }
        Ok(None)
    }

    /// Half-range φ_max of the pocket phase (rad).
    pub fn phase_limit(&self) -> f64 {
        self.phi_max
    }

    /// Volume one pocket of this family expels while it closes (m³): face width × (A(φ_max) − A(0)).
    /// A helical pocket expels the same volume (its slices pass the same areas, shifted in phase).
    pub fn displaced_volume(&self) -> f64 {
        self.face_width * (self.eval(self.phi_max).0 - self.eval(0.0).0).max(0.0)
    }

    /// Number of Chebyshev panels (diagnostics).
    pub fn panel_count(&self) -> usize {
        self.panels.len()
    }

    /// Series lengths of the area fits, per panel (diagnostics).
    pub fn panel_degrees(&self) -> Vec<usize> {
        self.panels.iter().map(|p| p.area.len()).collect()
    }

    /// `(A_axial, dA_axial/dφ1, g1 + g2)` at φ1 (even extension; clamped to the phase end
    /// outside |φ1| ≤ φ_max, where the derivative is 0).
    pub fn eval(&self, phi1: f64) -> (f64, f64, f64) {
        let x = phi1.abs();
        let sgn = if phi1 < 0.0 { -1.0 } else { 1.0 };
        let (x, outside) = if x >= self.phi_max {
            (self.phi_max, true)
        } else {
            (x, false)
        };
        let i = self
            .panels
            .partition_point(|p| p.hi < x)
            .min(self.panels.len() - 1);
        let p = &self.panels[i];
        let t = ((2.0 * x - p.lo - p.hi) / (p.hi - p.lo)).clamp(-1.0, 1.0);
        let a = clenshaw(&p.area, t);
        let g = clenshaw(&p.gaps, t);
        let da = if outside { 0.0 } else { sgn * clenshaw(&p.darea, t) };
        (a, da, g)
    }

    /// `(dA_axial/dφ1, g1 + g2)` at φ1 (as [`Self::eval`] without the area).
    fn eval_rate_gaps(&self, phi1: f64) -> (f64, f64) {
        let x = phi1.abs();
        if x >= self.phi_max {
            return (0.0, self.eval(phi1).2);
        }
        let i = self
            .panels
            .partition_point(|p| p.hi < x)
            .min(self.panels.len() - 1);
        let p = &self.panels[i];
        let t = ((2.0 * x - p.lo - p.hi) / (p.hi - p.lo)).clamp(-1.0, 1.0);
        let sgn = if phi1 < 0.0 { -1.0 } else { 1.0 };
        (sgn * clenshaw(&p.darea, t), clenshaw(&p.gaps, t))
    }

    /// `(A_axial, G)` at φ1, with `G(φ1) = ∫_0^φ1 (g1 + g2) dφ` (odd in φ1; beyond the phase
    /// end the gaps keep their end value, so G grows linearly there).
    fn eval_area_gap_integral(&self, phi1: f64) -> (f64, f64) {
        let x = phi1.abs();
        let sgn = if phi1 < 0.0 { -1.0 } else { 1.0 };
        let xc = x.min(self.phi_max);
        let i = self
            .panels
            .partition_point(|p| p.hi < xc)
            .min(self.panels.len() - 1);
        let p = &self.panels[i];
        let t = ((2.0 * xc - p.lo - p.hi) / (p.hi - p.lo)).clamp(-1.0, 1.0);
        let a = clenshaw(&p.area, t);
        let mut gi = p.gaps_int_lo + clenshaw(&p.gaps_int, t);
        if x > self.phi_max {
            gi += (x - self.phi_max) * clenshaw(&p.gaps, t);
        }
        (a, sgn * gi)
    }

    /// Adaptive Gauss–Legendre integral of `f` on [lo, hi] to relative tolerance `rtol`
    /// (absolute floor `atol`).
    fn integrate(&self, f: &dyn Fn(f64) -> f64, lo: f64, hi: f64, rtol: f64, atol: f64) -> f64 {
        let gl = |a: f64, b: f64| -> f64 {
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            h * self
                .gl_x
                .iter()
                .zip(&self.gl_w)
                .map(|(x, w)| w * f(m + h * x))
                .sum::<f64>()
        };
        let mut total = 0.0;
        let mut stack = vec![(lo, hi, gl(lo, hi), 0u32)];
        while let Some((a, b, whole, depth)) = stack.pop() {
            let m = 0.5 * (a + b);
            let (l, r) = (gl(a, m), gl(m, b));
            if (l + r - whole).abs() <= rtol * (l + r).abs() + atol || depth >= 40 {
                total += l + r;
            } else {
                stack.push((a, m, l, depth + 1));
                stack.push((m, b, r, depth + 1));
            }
        }
        total
    }

    /// Spur K (m⁵) for discharge coefficient `cd`: closing phase φ1 ∈ [−φ_max, 0], written as
    /// ∫_0^{φ_max} using evenness (−V'(−ψ) = b A'(ψ)).
    pub fn k_spur(&self, cd: f64) -> f64 {
        self.k_spur_partial(cd, self.phi_max)
    }

    /// Spur K restricted to the last part φ1 ∈ [−ψ_start, 0] of the closing phase (m⁵); shows
    /// how little the (somewhat arbitrary) start of the pocket phase matters.
    pub fn k_spur_partial(&self, cd: f64, psi_start: f64) -> f64 {
        let b = self.face_width;
        let f = |psi: f64| {
            let (a, da, g) = self.eval(psi);
            let q = (b * da).max(0.0);
            let aout = cd * (2.0 * a + b * g);
            q * q * q / (aout * aout)
        };
        let mut k = 0.0;
        for p in &self.panels {
            let hi = p.hi.min(psi_start);
            if hi > p.lo {
                k += self.integrate(&f, p.lo, hi, 1e-12, 0.0);
            }
        }
        k
    }

    /// Helical K (m⁵): connected-slice model (module doc) with `n` slices and a phase shift
    /// `dphi_dy = tan β / r_1` (rad of φ1 per m of face width). Equals `k_spur` for
    /// `dphi_dy = 0`.
    pub fn k_helical(&self, cd: f64, dphi_dy: f64, n: usize) -> f64 {
        let n = n.max(1);
        let b = self.face_width;
        let w = b / n as f64;
        let shifts: Vec<f64> = (0..n)
            .map(|j| (-0.5 * b + (j as f64 + 0.5) * w) * dphi_dy)
            .collect();
        let f = |psi: f64| {
            let mut dv = 0.0;
            let mut gsum = 0.0;
            for &d in &shifts {
                let (da, g) = self.eval_rate_gaps(psi + d);
                dv += da;
                gsum += g;
            }
            let a0 = self.eval(psi + shifts[0]).0;
            let a1 = self.eval(psi + shifts[n - 1]).0;
            let q = (w * dv).max(0.0);
            let aout = cd * (a0 + a1 + w * gsum);
            q * q * q / (aout * aout)
        };
        // breakpoints of every shifted slice
        let dmax = shifts.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let top = self.phi_max + dmax;
        let mut pts = vec![0.0, top];
        for p in &self.panels {
            for e in [p.lo, p.hi] {
                for &d in &shifts {
                    for c in [e - d, -e - d] {
                        if c > 0.0 && c < top {
                            pts.push(c);
                        }
                    }
                }
            }
        }
        pts.sort_by(|a, b| a.total_cmp(b));
        pts.dedup_by(|a, b| (*a - *b).abs() < 1e-14);
        // absolute floor: far below the spur value
        let atol = 1e-14 * self.k_spur(cd) / pts.len() as f64;
        pts.windows(2)
            .map(|s| self.integrate(&f, s[0], s[1], 1e-10, atol))
            .sum()
    }

    /// Helical K (m⁵) of the connected-slice model (module doc) in its limit of infinitely many
    /// slices, evaluated exactly: with `h = b·|dφ/dy|/2` the slice sums become integrals over
    /// the face width of ONE spur pocket history shifted in phase,
    /// `Σ w A'(ψ + Δ_j) → (A(ψ + h) − A(ψ − h))/|dφ/dy|` and
    /// `Σ w g(ψ + Δ_j) → (G(ψ + h) − G(ψ − h))/|dφ/dy|` (G the antiderivative of the gap sum,
    /// exact from its Chebyshev series), and the end faces are at ψ ± h. So the integrand costs
    /// two table look-ups whatever the helix, and there is no slice count to choose:
    /// `k_helical(cd, s, n)` converges to it like 1/n (the end faces sit w/2 inside the face;
    /// measured in the tests and docs/performance.md). Equals `k_spur` for `dphi_dy = 0`.
    pub fn k_helical_continuum(&self, cd: f64, dphi_dy: f64) -> f64 {
        self.k_helical_continuum_with(cd, dphi_dy, Some(HELIX_GL_NODES)).0
    }

    /// [`Self::k_helical_continuum`] with `nodes` Gauss–Legendre nodes on each smooth
    /// sub-interval (between the shifted panel edges), or `None` for the adaptive reference
    /// (24-node rule, relative tolerance 1e-13); returns K and the number of integrand
    /// evaluations (convergence study, docs/performance.md).
    pub fn k_helical_continuum_with(&self, cd: f64, dphi_dy: f64, nodes: Option<usize>) -> (f64, usize) {
        let b = self.face_width;
        let s = dphi_dy.abs();
        let h = 0.5 * b * s;
        // below this shift the helical and spur values agree to round-off (K − K_spur ~ h²)
        if h.is_nan() || h <= 1e-7 * self.phi_max {
            return (self.k_spur(cd), 0);
        }
        let evals = std::cell::Cell::new(0usize);
        let f = |psi: f64| {
            evals.set(evals.get() + 1);
            let (ap, gp) = self.eval_area_gap_integral(psi + h);
            let (am, gm) = self.eval_area_gap_integral(psi - h);
            let q = ((ap - am) / s).max(0.0);
            let aout = cd * (ap + am + (gp - gm) / s);
            q * q * q / (aout * aout)
        };
        let top = self.phi_max + h;
        let mut pts = vec![0.0, top];
        for p in &self.panels {
            for e in [p.lo, p.hi] {
                for c in [e - h, e + h, -e + h] {
                    if c > 0.0 && c < top {
                        pts.push(c);
                    }
                }
            }
        }
        pts.sort_by(|a, b| a.total_cmp(b));
        pts.dedup_by(|a, b| (*a - *b).abs() < 1e-14);
        let k = match nodes {
            Some(n) => {
                let (x, w) = gauss_legendre(n.max(1));
                pts.windows(2)
                    .map(|iv| {
                        let (m, hw) = (0.5 * (iv[0] + iv[1]), 0.5 * (iv[1] - iv[0]));
                        hw * x.iter().zip(&w).map(|(x, w)| w * f(m + hw * x)).sum::<f64>()
                    })
                    .sum()
            }
            None => pts
                .windows(2)
                .map(|iv| self.integrate(&f, iv[0], iv[1], 1e-13, 0.0))
                .sum(),
        };
        (k, evals.get())
    }

    /// K by the discrete rotational-increment form of seed 000 (§3.4, Seetharaman–Kahraman):
    /// the closing phase is cut into `m` increments; in each the outflow is the volume change
    /// over the increment and the leakage area is taken at its start. Converges to `k_spur` as
    /// m → ∞ (first order); used for comparison only.
    pub fn k_increments(&self, cd: f64, m: usize) -> f64 {
        let m = m.max(1);
        let b = self.face_width;
        let h = self.phi_max / m as f64;
        (0..m)
            .map(|i| {
                // closing: from ψ = φ_max − i h down to φ_max − (i+1) h
                let (p0, p1) = (self.phi_max - i as f64 * h, self.phi_max - (i + 1) as f64 * h);
                let (a0, _, g0) = self.eval(p0);
                let (a1, _, _) = self.eval(p1);
                let q = (b * (a0 - a1) / h).max(0.0);
                let aout = cd * (2.0 * a0 + b * g0);
                q * q * q / (aout * aout) * h
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::super::areas::{PocketFamily, PocketFamilyKind};
    use super::super::cases;
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_for_polynomials() {
        let (x, w) = gauss_legendre(GL_N);
        for p in 0..(2 * GL_N) {
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
            let exact = if p % 2 == 1 { 0.0 } else { 2.0 / (p as f64 + 1.0) };
            assert!((q - exact).abs() < 1e-14, "degree {p}");
        }
    }

    #[test]
    fn table_reproduces_closed_form_and_its_derivative() {
        for inp in [cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()] {
            for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
                let f = PocketFamily::new(&inp, kind).unwrap();
                let t = PocketTable::new(&f).unwrap();
                let pm = f.phase_limit();
                let amax = f.state(pm).unwrap().area;
                let mut dscale: f64 = 0.0;
                for i in 0..=100 {
                    dscale = dscale.max(t.eval(pm * i as f64 / 100.0).1.abs());
                }
                for i in 0..97 {
                    let p = -pm + 2.0 * pm * (i as f64 + 0.31) / 97.0;
                    let s = f.state(p).unwrap();
                    let (a, da, g) = t.eval(p);
                    assert!((a - s.area).abs() < 1e-11 * amax);
                    assert!((g - s.gap1 - s.gap2).abs() < 1e-11 * inp.module);
                    // derivative vs 4th-order central difference of the closed form
                    let h = 1e-4 * pm;
                    let av = |x: f64| f.state(x).map(|s| s.area);
                    if let (Some(a1), Some(a2), Some(a3), Some(a4)) =
                        (av(p + h), av(p - h), av(p + 2.0 * h), av(p - 2.0 * h))
                    {
                        let near_bp = f
                            .breakpoints_positive()
                            .iter()
                            .any(|b| (p.abs() - b).abs() < 3.0 * h);
                        if !near_bp {
                            let fd = (8.0 * (a1 - a2) - (a3 - a4)) / (12.0 * h);
                            assert!((fd - da).abs() < 1e-7 * dscale, "{kind:?} φ={p}: {da} vs {fd}");
                        }
                    }
                    if let Some(exact) = f.area_rate_double_loa(p) {
                        assert!((exact - da).abs() < 1e-9 * dscale, "{p}: {da} vs {exact}");
                    }
                }
            }
        }
    }

    #[test]
    fn k_is_finite_and_converged() {
        let cd = 0.65;
        for inp in [cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()] {
            for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
                let f = PocketFamily::new(&inp, kind).unwrap();
                let t = PocketTable::new(&f).unwrap();
                let k = t.k_spur(cd);
                assert!(k.is_finite() && k > 0.0);
                // fixed composite Gauss–Legendre with 2^j sub-panels per panel converges to k
                let b = inp.face_width;
                let integrand = |psi: f64| {
                    let (a, da, g) = t.eval(psi);
                    let q = (b * da).max(0.0);
                    q.powi(3) / (cd * (2.0 * a + b * g)).powi(2)
                };
                let mut errs = Vec::new();
                for j in 0..4 {
                    let mut s = 0.0;
                    for p in &t.panels {
                        let n = 1usize << j;
                        let hh = (p.hi - p.lo) / n as f64;
                        for q in 0..n {
                            let (a0, a1) = (p.lo + q as f64 * hh, p.lo + (q + 1) as f64 * hh);
                            let (m, h) = (0.5 * (a0 + a1), 0.5 * (a1 - a0));
                            s += h * t
                                .gl_x
                                .iter()
                                .zip(&t.gl_w)
                                .map(|(x, w)| w * integrand(m + h * x))
                                .sum::<f64>();
                        }
                    }
                    errs.push(((s - k) / k).abs());
                }
                assert!(errs[3] < 1e-10, "{kind:?}: {errs:?}");
                // the integrand vanishes at the volume minimum (no singularity)
                assert!(integrand(0.0) < 1e-20 * integrand(0.3 * t.phi_max));
                assert!(integrand(1e-3 * t.phi_max) < 1e-6 * integrand(0.3 * t.phi_max));
                // discharge coefficient enters as 1/C_d²
                assert!((t.k_spur(0.5) * 0.25 - t.k_spur(1.0)).abs() < 1e-10 * t.k_spur(1.0));
            }
        }
    }

    #[test]
    fn k_direct_from_closed_form_agrees_with_table() {
        // independent path: finite-difference derivative of the closed-form volume, plain
        // composite Simpson on a fine grid
        let inp = cases::fzg_c();
        let cd = 0.7;
        for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
            let f = PocketFamily::new(&inp, kind).unwrap();
            let t = PocketTable::new(&f).unwrap();
            let pm = f.phase_limit();
            let n = 4000;
            let h = pm / n as f64;
            let e = 1e-6 * pm;
            let g = |psi: f64| {
                let lo = (psi - e).max(0.0);
                let hi = (psi + e).min(pm);
                let (s0, s1) = (f.state(-hi).unwrap(), f.state(-lo).unwrap());
                let dv = (s1.volume - s0.volume) / (hi - lo); // dV/dφ at −ψ (negative)
                let s = f.state(-psi).unwrap();
                (-dv).max(0.0).powi(3) / (cd * s.a_out).powi(2)
            };
            let mut s = g(0.0) + g(pm);
            for i in 1..n {
                s += if i % 2 == 1 { 4.0 } else { 2.0 } * g(i as f64 * h);
            }
            let kd = s * h / 3.0;
            let kt = t.k_spur(cd);
            assert!(((kd - kt) / kt).abs() < 1e-5, "{kind:?}: direct {kd} table {kt}");
        }
    }

    #[test]
    fn helical_reduces_to_spur_and_converges_in_slices() {
        let inp = cases::fzg_c();
        let f = PocketFamily::new(&inp, PocketFamilyKind::SpaceOfGear2).unwrap();
        let t = PocketTable::new(&f).unwrap();
        let cd = 0.65;
        let ks = t.k_spur(cd);
        for n in [1, 3, 16] {
            assert!(((t.k_helical(cd, 0.0, n) - ks) / ks).abs() < 1e-9);
        }
        let r1 = f.tooth.r_ref;
        let dphi_dy = 15f64.to_radians().tan() / r1;
        let k8 = t.k_helical(cd, dphi_dy, 8);
        let k32 = t.k_helical(cd, dphi_dy, 32);
        let k128 = t.k_helical(cd, dphi_dy, 128);
        assert!(((k32 - k128) / k128).abs() < ((k8 - k128) / k128).abs());
        assert!(((k32 - k128) / k128).abs() < 0.02, "{k8} {k32} {k128}");
        // the helix spreads the squeeze: less loss than spur
        assert!(k128 < ks);
    }

    #[test]
    fn gap_antiderivative_matches_quadrature_of_the_gaps() {
        let f = PocketFamily::new(&cases::unequal_with_backlash(), PocketFamilyKind::SpaceOfGear1).unwrap();
        let t = PocketTable::new(&f).unwrap();
        let pm = t.phi_max;
        assert!(t.eval(0.5 * pm).2 > 1e-3 * cases::unequal_with_backlash().module);
        for x in [0.1 * pm, 0.5 * pm, 0.97 * pm, 1.3 * pm, -0.6 * pm] {
            let g = |p: f64| t.eval(p).2;
            let n = 20000;
            let h = x / n as f64;
            let mut s = g(0.0) + g(x);
            for i in 1..n {
                s += if i % 2 == 1 { 4.0 } else { 2.0 } * g(i as f64 * h);
            }
            let q = s * h / 3.0;
            let gi = t.eval_area_gap_integral(x).1;
            assert!((gi - q).abs() < 1e-9 * q.abs(), "x = {x}: {gi} vs {q}");
        }
    }

    #[test]
    fn helical_continuum_is_the_limit_of_the_slices() {
        let cd = 0.65;
        for beta in [15f64, 30.0] {
            let inp = cases::helical(&cases::fzg_c(), beta.to_radians());
            let f = PocketFamily::new(&inp, PocketFamilyKind::SpaceOfGear2).unwrap();
            let t = PocketTable::new(&f).unwrap();
            let s = beta.to_radians().tan() / f.tooth.r_ref;
            let kc = t.k_helical_continuum(cd, s);
            // the fixed rule agrees with the adaptive reference to far below 1e-6
            let (kr, _) = t.k_helical_continuum_with(cd, s, None);
            assert!(((kc - kr) / kr).abs() < 1e-10, "β {beta}: {kc} vs {kr}");
            // slices converge to it like 1/n; first-order Richardson closes most of the gap
            let e: Vec<f64> = [32, 64, 128]
                .iter()
                .map(|&n| (t.k_helical(cd, s, n) - kc) / kc)
                .collect();
            for w in e.windows(2) {
                let r = w[0] / w[1];
                assert!((1.8..2.2).contains(&r), "β {beta}: {e:?}");
            }
            let rich = 2.0 * e[2] - e[1];
            assert!(
                rich.abs() < 0.05 * e[2].abs(),
                "β {beta}: {e:?}, Richardson {rich}"
            );
            // spur limit
            assert!(((t.k_helical_continuum(cd, 1e-12) - t.k_spur(cd)) / t.k_spur(cd)).abs() < 1e-12);
        }
    }

    #[test]
    fn increment_form_converges_to_k() {
        let f = PocketFamily::new(&cases::seed004(), PocketFamilyKind::SpaceOfGear1).unwrap();
        let t = PocketTable::new(&f).unwrap();
        let k = t.k_spur(0.65);
        let e: Vec<f64> = [10, 40, 160, 640]
            .iter()
            .map(|&m| ((t.k_increments(0.65, m) - k) / k).abs())
            .collect();
        assert!(e[3] < e[2] && e[2] < e[1] && e[3] < 0.01, "{e:?}");
    }
}
