//! Run-time pocketing power of one mesh (physics.md §6).
//!
//! Per pocket passage the squeezed oil leaves with `v = Q/(C_d A_out)`, `Q = −ω1 dV/dφ1`, at the
//! Bernoulli pressure `Δp = ½ρv²`; the power `Δp·Q` integrated over the closing phase
//! (dt = dφ1/ω1) gives the energy `E = ½ρω1²·K` with the geometric `K` of `integral.rs`.
//! z1 pockets of each family pass per revolution of gear 1, i.e. `z1·ω1/(2π)` per second:
//! `P = z1·ω1/(2π)·½ρω1²K = z1·ρ·ω1³·K/(4π)` per family [derived from seeds 000 and 004].
//! Dimensions: K ~ L⁵ (V ~ L³, A ~ L²), so P ~ ρ ω³ L⁵.

use super::areas::{MeshProfiles, PocketFamily, PocketFamilyKind};
use super::integral::PocketTable;
use super::{PocketMeshInput, PocketingError};

/// Options of the pocketing model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketingOptions {
    /// Discharge coefficient C_d of the leakage openings (default 0.65; physics.md §6 0.6–0.7).
    pub discharge_coefficient: f64,
    /// Helical gears: `None` (default) evaluates the connected-slice model in its exact
    /// infinitely-many-slices limit (`PocketTable::k_helical_continuum`); `Some(n)` uses n
    /// discrete transverse slices (kept for convergence studies). Ignored for spur gears.
    pub helix_slices: Option<usize>,
}

impl Default for PocketingOptions {
    fn default() -> Self {
        Self {
            discharge_coefficient: 0.65,
            helix_slices: None,
        }
    }
}

/// Precomputed pocketing model of one mesh: K of both families, evaluation is one multiply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketingMesh {
    /// K of [space of gear 2 entered by gear 1, space of gear 1 entered by gear 2] (m⁵).
    k: [f64; 2],
    /// z1/(4π).
    z1_over_4pi: f64,
    /// Volume the closing pockets of both families expel per radian of gear 1, m³/rad:
    /// z1 (ΔV_1 + ΔV_2)/(2π).
    swept_per_rad: f64,
    /// Discharge coefficient used.
    cd: f64,
}

impl PocketingMesh {
    /// Build with discharge coefficient `cd` and default options.
    pub fn new(input: &PocketMeshInput, cd: f64) -> Result<Self, PocketingError> {
        Self::with_options(
            input,
            &PocketingOptions {
                discharge_coefficient: cd,
                ..PocketingOptions::default()
            },
        )
    }

    /// Build with explicit options.
    pub fn with_options(input: &PocketMeshInput, opts: &PocketingOptions) -> Result<Self, PocketingError> {
        let cd = opts.discharge_coefficient;
        if !(cd.is_finite() && cd > 0.0 && cd <= 1.0) {
            return Err(PocketingError::InvalidInput(
                "discharge_coefficient",
                format!("must be in (0, 1], got {cd}"),
            ));
        }
        if let Some(n) = opts.helix_slices.filter(|n| *n == 0 || *n > 4096) {
            return Err(PocketingError::InvalidInput(
                "helix_slices",
                format!("must be in 1..=4096, got {n}"),
            ));
        }
        let mp = MeshProfiles::new(input)?;
        let dphi_dy = input.helix_angle.tan() / mp.gear1.r_ref;
        let mut k = [0.0; 2];
        let mut displaced = 0.0;
        for (i, kind) in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1]
            .into_iter()
            .enumerate()
        {
            let fam = PocketFamily::from_profiles(&mp, kind)?;
            let table = PocketTable::new(&fam)?;
            displaced += table.displaced_volume();
            k[i] = match opts.helix_slices {
                _ if input.helix_angle == 0.0 => table.k_spur(cd),
                None => table.k_helical_continuum(cd, dphi_dy),
                Some(n) => table.k_helical(cd, dphi_dy, n),
            };
            if !(k[i].is_finite() && k[i] >= 0.0) {
                return Err(PocketingError::Numerical(format!("K = {} for {kind:?}", k[i])));
            }
        }
        Ok(Self {
            k,
            z1_over_4pi: input.z1 as f64 / (4.0 * std::f64::consts::PI),
            swept_per_rad: input.z1 as f64 * displaced / (2.0 * std::f64::consts::PI),
            cd,
        })
    }

    /// Volume flow the closing pockets of both families expel at gear-1 speed `omega1` (rad/s,
    /// magnitude used), m³/s: `z1 |ω1| (ΔV_1 + ΔV_2)/(2π)` (the swept flow of
    /// [`crate::physics::lubrication`]).
    pub fn swept_flow(&self, omega1: f64) -> f64 {
        self.swept_per_rad * omega1.abs()
    }

    /// K of the two families (m⁵): [space of gear 2, space of gear 1].
    pub fn k(&self) -> [f64; 2] {
        self.k
    }

    /// Discharge coefficient used to build K.
    pub fn discharge_coefficient(&self) -> f64 {
        self.cd
    }

    /// Pocketing power of each family (W) at driver speed `omega1` (rad/s, sign ignored) and
    /// oil (or oil–air mixture) density `density` (kg/m³): `z1 ρ |ω1|³ K / (4π)`.
    pub fn family_power(&self, omega1: f64, density: f64) -> [f64; 2] {
        let c = self.z1_over_4pi * density * omega1.abs().powi(3);
        [c * self.k[0], c * self.k[1]]
    }

    /// Total pocketing power of the mesh (W), both families. Allocation-free.
    pub fn power(&self, omega1: f64, density: f64) -> f64 {
        self.z1_over_4pi * density * omega1.abs().powi(3) * (self.k[0] + self.k[1])
    }
}

#[cfg(test)]
mod tests {
    use super::super::cases;
    use super::*;
    use crate::physics::units::rpm_to_rad_s;
    use std::f64::consts::PI;

    #[test]
    fn power_formula_equals_passage_frequency_times_energy() {
        let inp = cases::fzg_c();
        let m = PocketingMesh::new(&inp, 0.65).unwrap();
        let (w, rho) = (rpm_to_rad_s(3000.0), 870.0);
        let e = 0.5 * rho * w * w * (m.k()[0] + m.k()[1]);
        let p = inp.z1 as f64 * w / (2.0 * PI) * e;
        assert!((m.power(w, rho) - p).abs() < 1e-12 * p);
        assert_eq!(m.power(-w, rho), m.power(w, rho));
        let fp = m.family_power(w, rho);
        assert!((fp[0] + fp[1] - m.power(w, rho)).abs() < 1e-12 * p);
        // cubic in speed, linear in density
        assert!((m.power(2.0 * w, rho) - 8.0 * m.power(w, rho)).abs() < 1e-12 * p * 8.0);
        assert!((m.power(w, 2.0 * rho) - 2.0 * m.power(w, rho)).abs() < 1e-12 * p * 2.0);
    }

    #[test]
    fn swept_flow_is_the_volume_the_closing_pockets_lose() {
        // FZG C (docs/physics.md §6 table): A(φ_max) 68.30 / 68.33 mm², A(0) 5.723 / 5.635 mm²,
        // b 14 mm, z1 16: ΔV = 14 × (A(φ_max) − A(0)) per family.
        let m = PocketingMesh::new(&cases::fzg_c(), 0.65).unwrap();
        let dv = 14.0 * ((68.30 - 5.723) + (68.33 - 5.635)) * 1e-9;
        let expect = 16.0 * dv / (2.0 * PI);
        assert!(
            (m.swept_flow(-1.0) / expect - 1.0).abs() < 2e-4,
            "{}",
            m.swept_flow(1.0) / expect
        );
    }

    #[test]
    fn units_mm_converted_and_length_scaling() {
        // the same FZG mesh typed in millimetres and converted, vs typed in metres
        let m_si = cases::fzg_c();
        let mm = PocketMeshInput {
            module: 4.5 / 1000.0,
            tip_radius1: 82.46 / 2.0 / 1000.0,
            tip_radius2: 118.36 / 2.0 / 1000.0,
            root_radius1: (4.5 * 16.0 - 2.0 * 4.5 * (1.25 - 0.1817)) / 2.0 / 1000.0,
            root_radius2: (4.5 * 24.0 - 2.0 * 4.5 * (1.25 - 0.1715)) / 2.0 / 1000.0,
            centre_distance: 91.5 / 1000.0,
            face_width: 14.0 / 1000.0,
            ..m_si
        };
        let w = rpm_to_rad_s(6000.0);
        let p_si = PocketingMesh::new(&m_si, 0.65).unwrap().power(w, 870.0);
        let p_mm = PocketingMesh::new(&mm, 0.65).unwrap().power(w, 870.0);
        assert!(((p_si - p_mm) / p_si).abs() < 1e-9, "{p_si} vs {p_mm}");
        // K ~ L⁵: all lengths × k
        let base = PocketingMesh::new(&m_si, 0.65).unwrap().k();
        for k in [0.1, 3.0, 1000.0] {
            let s = PocketingMesh::new(&m_si.scaled(k), 0.65).unwrap().k();
            for i in 0..2 {
                let r = s[i] / (base[i] * k.powi(5));
                assert!((r - 1.0).abs() < 1e-8, "scale {k}: ratio {r}");
            }
            // lengths × k and time × k (ω/k): P scales as k⁵/k³ = k²
            let p = PocketingMesh::new(&m_si.scaled(k), 0.65)
                .unwrap()
                .power(w / k, 870.0);
            assert!((p / (p_si * k * k) - 1.0).abs() < 1e-8);
        }
    }

    #[test]
    fn helical_mesh_builds_and_spur_limit() {
        let mut inp = cases::fzg_c();
        let spur = PocketingMesh::new(&inp, 0.65).unwrap();
        inp.helix_angle = 1e-9;
        let nearly = PocketingMesh::new(&inp, 0.65).unwrap();
        for i in 0..2 {
            assert!(((nearly.k()[i] - spur.k()[i]) / spur.k()[i]).abs() < 1e-6);
        }
        for deg in [5.0, 15.0, 25.0] {
            let inp = cases::helical(&cases::fzg_c(), f64::to_radians(deg));
            let hel = PocketingMesh::new(&inp, 0.65).unwrap();
            // the helix spreads the squeeze over a longer angle: less than the spur pocket of
            // the same transverse section
            let fam = PocketFamily::new(&inp, PocketFamilyKind::SpaceOfGear2).unwrap();
            let ks = PocketTable::new(&fam).unwrap().k_spur(0.65);
            assert!(
                hel.k()[0] > 0.0 && hel.k()[0] < ks,
                "β {deg}°: {:?} vs {ks}",
                hel.k()
            );
        }
    }

    #[test]
    fn rejects_bad_options() {
        let inp = cases::fzg_c();
        assert!(PocketingMesh::new(&inp, 0.0).is_err());
        assert!(PocketingMesh::new(&inp, 1.5).is_err());
        let o = PocketingOptions {
            helix_slices: Some(0),
            ..PocketingOptions::default()
        };
        assert!(PocketingMesh::with_options(&inp, &o).is_err());
    }
}
