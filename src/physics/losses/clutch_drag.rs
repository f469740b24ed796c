//! Drag of an open (disengaged) wet multi-plate clutch or brake: viscous shear of the ATF film
//! in the clearance between the friction and steel plates, with the film broken up by the
//! centrifugal flow demand at higher slip speeds when the oil supply cannot fill the gap.
//!
//! Model (the flow-limited film of Yuan et al. 2007 and Iqbal et al. 2013; surveyed in
//! Pointner-Gabriel, Voelkel & Stahl 2025, "Drag losses of wet brakes and clutches — a scoping
//! review", Lubricants 13(1) 27), per friction interface of a pack with `z` interfaces:
//!
//! - Couette shear of a Newtonian film of clearance h between radii r_i and r_e with relative
//!   speed Δω \[std, Newton's law of viscosity integrated over an annulus\]:
//!   `T = φ·π·μ·Δω·(r_e⁴ − r_i⁴)/(2h)`, φ the land fraction of the grooved friction face
//!   (φ = 1 for a plain face: grooves carry oil but shear none);
//! - radial flow the film needs to stay complete out to radius r \[derived here: thin-film
//!   Navier–Stokes with the centrifugal term ρ·v_θ²/r, linear v_θ = Δω·r·z/h across the gap,
//!   ambient pressure at r_i and at the film edge; the flow-limited film idea is that of Yuan et
//!   al. 2007 and Iqbal et al. 2013, whose full texts were not available to check their exact
//!   coefficients — docs/physics.md]:
//!   `Q(r) = π·ρ·Δω²·h³·(r² − r_i²) / (40·μ·ln(r/r_i))`;
//! - the supplied flow per interface q = Q_pack/z fills the gap out to the radius r_e where
//!   Q(r_e) = q (Q increases with r); if q ≥ Q(r_o) the film is complete (r_e = r_o). Below the
//!   critical slip speed `Δω_c = √(40·μ·q·ln(r_o/r_i) / (π·ρ·h³·(r_o² − r_i²)))` the drag rises
//!   linearly with slip; above it the film shrinks and the drag falls — the rise, peak and decay
//!   of measured open-clutch drag curves the cited papers describe;
//! - beyond r_e Iqbal et al. shear an oil mist; here its viscosity is the fraction
//!   `mist_viscosity_ratio` of the oil's (0 unless the model file sets it).
//!
//! Both plates' absolute speeds are replaced by their difference (exact for a brake, whose steel
//! plates stand still; for a rotating clutch the centrifugal term of the common rotation is
//! neglected — documented in docs/physics.md). Strongly viscosity dependent: μ enters linearly
//! below Δω_c and through r_e above it, so cold starts show several times the warm drag.
//!
//! Units: SI throughout (m, rad/s, Pa·s, kg/m³, m³/s, N·m, W).

use std::f64::consts::PI;

/// One open clutch or brake pack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClutchPack {
    /// Number of friction interfaces (oil films), z ≥ 1 (a pack of n friction plates between
    /// steel plates has 2n).
    pub interfaces: f64,
    /// Inner radius of the friction face, m.
    pub inner_radius: f64,
    /// Outer radius of the friction face, m.
    pub outer_radius: f64,
    /// Clearance per interface (film thickness of the open pack), m.
    pub clearance: f64,
    /// Lubrication oil flow through the whole pack, m³/s (0: film limited to r_i, mist only).
    pub oil_flow: f64,
    /// Land fraction φ of the friction face (1 plain face; 0 < φ ≤ 1).
    pub groove_factor: f64,
    /// Viscosity of the mist beyond the film edge as a fraction of the oil's (0..1).
    pub mist_viscosity_ratio: f64,
}

/// Why a pack is not valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClutchPackError {
    /// A parameter is out of its range.
    #[error("{name} = {value}: {allowed}")]
    Range {
        /// Parameter.
        name: &'static str,
        /// Value.
        value: f64,
        /// Allowed.
        allowed: &'static str,
    },
}

/// Drag of one pack at one operating point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drag {
    /// Drag torque of the pack, N·m (≥ 0, opposing the slip).
    pub torque: f64,
    /// Drag power = torque × |slip|, W.
    pub power: f64,
    /// Radius where the full film ends, m (r_i ≤ r_e ≤ r_o).
    pub film_radius: f64,
}

/// Couette torque of one film of viscosity `mu` (Pa·s), relative speed `slip` (rad/s), clearance
/// `h` (m) on the annulus `r_in`..`r_out` (m): π·μ·Δω·(r_out⁴ − r_in⁴)/(2h). N·m.
pub fn couette_torque(mu: f64, slip: f64, h: f64, r_in: f64, r_out: f64) -> f64 {
    PI * mu * slip * (r_out.powi(4) - r_in.powi(4)) / (2.0 * h)
}

impl ClutchPack {
    /// Check the parameters.
    pub fn check(&self) -> Result<(), ClutchPackError> {
        let r = |name, value: f64, ok: bool, allowed| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(ClutchPackError::Range { name, value, allowed })
            }
        };
        r("interfaces", self.interfaces, self.interfaces >= 1.0, ">= 1")?;
        r("inner_radius", self.inner_radius, self.inner_radius > 0.0, "> 0")?;
        r(
            "outer_radius",
            self.outer_radius,
            self.outer_radius > self.inner_radius,
            "> inner radius",
        )?;
        r("clearance", self.clearance, self.clearance > 0.0, "> 0")?;
        r("oil_flow", self.oil_flow, self.oil_flow >= 0.0, ">= 0")?;
        r(
            "groove_factor",
            self.groove_factor,
            self.groove_factor > 0.0 && self.groove_factor <= 1.0,
            "in (0, 1]",
        )?;
        r(
            "mist_viscosity_ratio",
            self.mist_viscosity_ratio,
            (0.0..=1.0).contains(&self.mist_viscosity_ratio),
            "in [0, 1]",
        )
    }

    /// Flow one interface needs to keep its film complete out to radius `r` (m³/s) at slip
    /// `slip` (rad/s): π·ρ·Δω²·h³·(r² − r_i²)/(40·μ·ln(r/r_i)); its limit at r → r_i is
    /// π·ρ·Δω²·h³·2r_i²/(40·μ).
    pub fn film_flow(&self, r: f64, slip: f64, mu: f64, rho: f64) -> f64 {
        let h = self.clearance;
        PI * rho * slip * slip * h.powi(3) * g(r, self.inner_radius) / (40.0 * mu)
    }

    /// Critical slip speed (rad/s) up to which the film is complete: above it the supplied flow
    /// no longer fills the gap.
    pub fn critical_slip(&self, mu: f64, rho: f64) -> f64 {
        let q = self.oil_flow / self.interfaces;
        let h = self.clearance;
        (40.0 * mu * q / (PI * rho * h.powi(3) * g(self.outer_radius, self.inner_radius))).sqrt()
    }

    /// Radius where the film ends at slip `slip` (rad/s), viscosity `mu`, density `rho`.
    pub fn film_radius(&self, slip: f64, mu: f64, rho: f64) -> f64 {
        let (ri, ro) = (self.inner_radius, self.outer_radius);
        let slip = slip.abs();
        if slip == 0.0 {
            return ro;
        }
        let q = self.oil_flow / self.interfaces;
        // Target of g(r) = (r² − r_i²)/ln(r/r_i), increasing from 2r_i² at r_i.
        let target = 40.0 * mu * q / (PI * rho * slip * slip * self.clearance.powi(3));
        if target >= g(ro, ri) {
            return ro;
        }
        if target <= 2.0 * ri * ri {
            return ri;
        }
        // Safeguarded Newton on the monotone g (bisection step whenever Newton leaves the
        // bracket); a few iterations to 1e-12 of the outer radius.
        let (mut lo, mut hi) = (ri, ro);
        let (g_lo, g_hi) = (2.0 * ri * ri, g(ro, ri));
        let mut r = ri + (ro - ri) * (target - g_lo) / (g_hi - g_lo);
        for _ in 0..100 {
            let f = g(r, ri) - target;
            if f < 0.0 {
                lo = r;
            } else {
                hi = r;
            }
            let d = g_prime(r, ri);
            let mut next = r - f / d;
            if !(next > lo && next < hi) || !d.is_finite() || d <= 0.0 {
                next = 0.5 * (lo + hi);
            }
            if (next - r).abs() <= 1e-12 * ro || hi - lo <= 1e-12 * ro {
                return next;
            }
            r = next;
        }
        r
    }

    /// Drag of the pack at slip speed `slip` (rad/s, either sign), oil dynamic viscosity `mu`
    /// (Pa·s) and density `rho` (kg/m³). No allocation.
    pub fn drag(&self, slip: f64, mu: f64, rho: f64) -> Drag {
        let w = slip.abs();
        if w == 0.0 {
            return Drag {
                torque: 0.0,
                power: 0.0,
                film_radius: self.outer_radius,
            };
        }
        let re = self.film_radius(w, mu, rho);
        let h = self.clearance;
        let film = couette_torque(mu, w, h, self.inner_radius, re);
        let mist = couette_torque(self.mist_viscosity_ratio * mu, w, h, re, self.outer_radius);
        let torque = self.interfaces * self.groove_factor * (film + mist);
        Drag {
            torque,
            power: torque * w,
            film_radius: re,
        }
    }
}

/// dg/dr = (2r·ln x − (r² − r_i²)/r)/ln²x, x = r/r_i (limit 2r_i at r = r_i).
fn g_prime(r: f64, ri: f64) -> f64 {
    let d = r - ri;
    let e = d / ri;
    if e < 1e-6 {
        // series: r_i·(2 + 2e/3)
        return ri * (2.0 + 2.0 * e / 3.0);
    }
    let l = e.ln_1p();
    (2.0 * r * l - d * (r + ri) / r) / (l * l)
}

/// (r² − r_i²)/ln(r/r_i), with its limit 2r_i² at r = r_i (ln_1p and (r − r_i)(r + r_i) keep
/// it accurate near r_i).
fn g(r: f64, ri: f64) -> f64 {
    let d = r - ri;
    let e = d / ri;
    if e < 1e-6 {
        // series: r_i²·(2 + 2e + e²/3)
        return ri * ri * (2.0 + e * (2.0 + e / 3.0));
    }
    d * (r + ri) / e.ln_1p()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const RPM: f64 = PI / 30.0;

    /// A 6HP-size brake pack: 4 friction plates (8 interfaces), 75–90 mm, 0.15 mm clearance per
    /// interface, 1 L/min lubrication.
    fn pack() -> ClutchPack {
        ClutchPack {
            interfaces: 8.0,
            inner_radius: 0.075,
            outer_radius: 0.090,
            clearance: 0.15e-3,
            oil_flow: 1.0e-3 / 60.0,
            groove_factor: 1.0,
            mist_viscosity_ratio: 0.0,
        }
    }

    #[test]
    fn couette_reproduces_the_textbook_worked_example() {
        // Çengel & Cimbala, Fluid Mechanics, problem 2-79 (worked solution published with the
        // problem on homeworklib.com): two 30 cm discs, 2 mm SAE 30 film with μ = 0.38 Pa·s,
        // 1200 rpm against 1125 rpm (125.6 and 117.8 rad/s in the solution), torque
        // T = π·μ·Δω·D⁴/(32h). The posted number, 0.151 N·m, is an arithmetic slip of that
        // solution (π·0.38·7.8·0.3⁴ = 0.0754, not 0.00966); its own formula gives 1.18 N·m.
        let t = couette_torque(0.38, 125.6 - 117.8, 2e-3, 0.0, 0.15);
        assert!((t - 1.178).abs() < 0.001, "{t}");
        assert_relative_eq!(
            t,
            PI * 0.38 * 7.8 * 0.3f64.powi(4) / (32.0 * 2e-3),
            max_relative = 1e-12
        );
    }

    #[test]
    fn below_the_critical_slip_the_film_is_complete_and_drag_is_couette() {
        let p = pack();
        let (mu, rho) = (0.02, 850.0);
        let wc = p.critical_slip(mu, rho);
        let w = 0.5 * wc;
        let d = p.drag(w, mu, rho);
        assert_eq!(d.film_radius, p.outer_radius);
        let want = 8.0 * couette_torque(mu, w, 0.15e-3, 0.075, 0.090);
        assert_relative_eq!(d.torque, want, max_relative = 1e-12);
        // at Δω_c the needed flow equals the supply exactly
        assert_relative_eq!(
            p.film_flow(p.outer_radius, wc, mu, rho),
            p.oil_flow / 8.0,
            max_relative = 1e-12
        );
    }

    #[test]
    fn drag_rises_peaks_at_the_critical_slip_and_falls() {
        let p = pack();
        let (mu, rho) = (0.02, 850.0);
        let wc = p.critical_slip(mu, rho);
        let t = |w: f64| p.drag(w, mu, rho).torque;
        assert!(t(0.5 * wc) < t(0.99 * wc));
        assert!(t(1.05 * wc) < t(wc));
        // a narrow annulus (r_i/r_o = 0.83) loses its film within 10 % above Δω_c
        assert!(t(1.5 * wc) < 0.01 * t(wc));
        // with mist the residual drag is the mist's Couette shear over the whole face
        let mut m = p;
        m.mist_viscosity_ratio = 0.05;
        let res = m.drag(3.0 * wc, mu, rho).torque;
        assert_relative_eq!(
            res,
            8.0 * couette_torque(0.05 * mu, 3.0 * wc, 0.15e-3, 0.075, 0.09),
            max_relative = 1e-12
        );
        // film radius: Q(r_e) = q on the break-up branch
        let w = 1.04 * wc;
        let re = p.film_radius(w, mu, rho);
        assert!(re > p.inner_radius && re < p.outer_radius);
        assert_relative_eq!(p.film_flow(re, w, mu, rho), p.oil_flow / 8.0, max_relative = 1e-9);
        // the torque is continuous at Δω_c
        assert_relative_eq!(t(wc * (1.0 - 1e-9)), t(wc * (1.0 + 1e-9)), max_relative = 1e-6);
    }

    #[test]
    fn units_and_scaling() {
        let p = pack();
        let (mu, rho) = (0.02, 850.0);
        let w = 0.3 * p.critical_slip(mu, rho);
        let d = p.drag(w, mu, rho);
        assert_relative_eq!(d.power, d.torque * w, max_relative = 1e-15);
        // full film: T ∝ z·φ·μ·Δω/h
        let mut q = p;
        q.interfaces = 4.0;
        q.oil_flow = p.oil_flow / 2.0; // same flow per interface
        assert_relative_eq!(q.drag(w, mu, rho).torque, 0.5 * d.torque, max_relative = 1e-12);
        q = p;
        q.groove_factor = 0.6;
        assert_relative_eq!(q.drag(w, mu, rho).torque, 0.6 * d.torque, max_relative = 1e-12);
        assert_relative_eq!(
            p.drag(0.5 * w, mu, rho).torque,
            0.5 * d.torque,
            max_relative = 1e-12
        );
        // sign of the slip does not matter, zero slip no drag
        assert_eq!(p.drag(-w, mu, rho), d);
        assert_eq!(p.drag(0.0, mu, rho).torque, 0.0);
        // the critical slip scales with sqrt(μ·q/h³)
        let wc = p.critical_slip(mu, rho);
        assert_relative_eq!(p.critical_slip(4.0 * mu, rho), 2.0 * wc, max_relative = 1e-12);
        // cold oil (5× the viscosity) drags much more at a typical open-pack slip of 1500 rpm
        let hot = p.drag(1500.0 * RPM, 0.01, 840.0).power;
        let cold = p.drag(1500.0 * RPM, 0.05, 860.0).power;
        assert!(cold > 3.0 * hot, "{cold} vs {hot}");
        // no oil flow: no film beyond r_i, only the mist shears
        q = p;
        q.oil_flow = 0.0;
        assert_eq!(q.drag(100.0, mu, rho).torque, 0.0);
        q.mist_viscosity_ratio = 0.1;
        let m = q.drag(100.0, mu, rho).torque;
        assert_relative_eq!(
            m,
            8.0 * couette_torque(0.1 * mu, 100.0, 0.15e-3, 0.075, 0.09),
            max_relative = 1e-12
        );
    }

    #[test]
    fn film_function_and_its_derivative_are_consistent() {
        let ri = 0.075;
        for x in [1.0 + 1e-8, 1.0 + 5e-7, 1.0 + 2e-6, 1.01, 1.1, 1.2, 1.5] {
            let r = ri * x;
            let h = 1e-6 * r;
            let fd = (g(r + h, ri) - g(r - h, ri)) / (2.0 * h);
            assert_relative_eq!(g_prime(r, ri), fd, max_relative = 1e-5);
        }
        // continuity across the series switch
        assert_relative_eq!(
            g(ri * (1.0 + 0.999_999e-6), ri),
            g(ri * (1.0 + 1.000_001e-6), ri),
            max_relative = 1e-10
        );
    }

    #[test]
    fn invalid_packs_are_rejected() {
        let mut p = pack();
        assert!(p.check().is_ok());
        p.outer_radius = 0.07;
        assert!(p.check().is_err());
        p = pack();
        p.groove_factor = 0.0;
        assert!(p.check().is_err());
        p = pack();
        p.clearance = f64::NAN;
        assert!(p.check().is_err());
    }
}
