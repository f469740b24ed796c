//! The friction model of a catalogue bearing (SKF 2004 or Palmgren) with the constants the
//! catalogue does not carry: SKF's μ values, the drag-term V_M curves and the seal constants
//! (sources at each).

use super::common::{q, MM};
use crate::model::bearing_catalogue::{BearingType, CatalogueBearing, SeriesEntry};
use crate::model::problems::Problems;
use crate::physics::losses::bearings::skf::{DragForm, Lubrication, SkfInput};
use crate::physics::losses::bearings::{BearingFriction, BearingSize, Palmgren, Skf, SkfConstants, SkfKind};

/// μ_bl of the SKF sliding term (both peers of docs/physics.md §Bearings).
pub(crate) const MU_BL: f64 = 0.12;

/// μ_EHL for mineral oils (the SKF online calculator's value, as the MATLAB peer notes; the SKF
/// catalogue text gives 0.05 for mineral oils, "other bearings").
pub(crate) const MU_EHL: f64 = 0.05;

/// μ_EHL of cylindrical roller bearings (SKF catalogue friction chapter, as shown at
/// yumpu.com/en/document/view/55668573/skf-rolling-bearings/105; the same in peer [P5]).
pub(crate) const MU_EHL_CYLINDRICAL: f64 = 0.02;

/// μ_EHL of tapered roller bearings (same source).
pub(crate) const MU_EHL_TAPERED: f64 = 0.002;

/// V_M of the roller drag term against H/d_m: SKF's diagram as digitised by peer [P5]
/// (`drag.py`, "graph digitization" — numbers read from a figure), linear in between, constant
/// beyond 1.2.
pub(crate) const DRAG_VM_ROLLER: [(f64, f64); 14] = [
    (0.0, 0.0),
    (0.025, 5e-6),
    (0.05, 3.0e-5),
    (0.075, 6.0e-5),
    (0.10, 1.0e-4),
    (0.125, 1.5e-4),
    (0.15, 2.1e-4),
    (0.175, 2.6e-4),
    (0.20, 3.0e-4),
    (0.30, 4.8e-4),
    (0.50, 6.8e-4),
    (0.80, 1.0e-3),
    (1.00, 1.25e-3),
    (1.20, 1.5e-3),
];

/// V_M of the ball drag term against H/d_m: the same digitised diagram of peer [P5] (its ball
/// curve; numbers read from a figure), linear in between, constant beyond 1.2.
pub(crate) const DRAG_VM_BALL: [(f64, f64); 14] = [
    (0.0, 0.0),
    (0.025, 2e-6),
    (0.05, 1.2e-5),
    (0.075, 3.0e-5),
    (0.10, 6.5e-5),
    (0.125, 1.0e-4),
    (0.15, 1.45e-4),
    (0.175, 1.95e-4),
    (0.20, 2.45e-4),
    (0.30, 3.8e-4),
    (0.50, 5.5e-4),
    (0.80, 8.0e-4),
    (1.00, 1.0e-3),
    (1.20, 1.25e-3),
];

/// V_M of the curve `table` at oil height `h_over_dm` (H/d_m).
fn drag_vm_on(table: &[(f64, f64); 14], h_over_dm: f64) -> f64 {
    let x = h_over_dm.clamp(0.0, 1.2);
    table.windows(2).find(|w| x <= w[1].0).map_or(table[13].1, |w| {
        w[0].1 + (w[1].1 - w[0].1) * (x - w[0].0) / (w[1].0 - w[0].0)
    })
}

/// V_M of a roller bearing at oil height `h_over_dm` (H/d_m).
pub(crate) fn drag_vm_roller(h_over_dm: f64) -> f64 {
    drag_vm_on(&DRAG_VM_ROLLER, h_over_dm)
}

/// V_M of a ball bearing at oil height `h_over_dm` (H/d_m).
pub(crate) fn drag_vm_ball(h_over_dm: f64) -> f64 {
    drag_vm_on(&DRAG_VM_BALL, h_over_dm)
}

/// SKF seal constants (K_S1, K_S2, β) by type and outside diameter D (mm): SKF, as listed by
/// thermca `bearing.seal_heat_loss` [SKF06] (the 62 < D ≤ 80 mm row agrees with the
/// eMotres catalogue).
pub(crate) fn seal_constants(kind: BearingType, outside_mm: f64) -> Option<(f64, f64, f64)> {
    match kind {
        BearingType::DeepGrooveBall => Some(if outside_mm <= 62.0 {
            (0.023, 2.0, 2.25)
        } else if outside_mm <= 80.0 {
            (0.018, 20.0, 2.25)
        } else if outside_mm <= 100.0 {
            (0.018, 15.0, 2.25)
        } else {
            (0.018, 0.0, 2.25)
        }),
        BearingType::AngularContactBall => Some((0.014, 10.0, 2.0)),
        BearingType::CylindricalRoller => Some((0.032, 50.0, 2.0)),
        _ => None,
    }
}

/// The SKF form of a bearing type (None: needle roller bearings, which have no SKF row in any
/// source found).
pub(crate) fn skf_kind(kind: BearingType) -> Option<SkfKind> {
    match kind {
        BearingType::DeepGrooveBall => Some(SkfKind::DeepGrooveBall),
        BearingType::AngularContactBall => Some(SkfKind::AngularContactBall),
        BearingType::FourPointContactBall => Some(SkfKind::FourPointContactBall),
        BearingType::CylindricalRoller => Some(SkfKind::CylindricalRoller),
        BearingType::TaperedRoller => Some(SkfKind::TaperedRoller),
        BearingType::NeedleRoller => None,
    }
}

/// Bore and outside diameter of a catalogue bearing, m.
pub(crate) fn size_of(entry: &CatalogueBearing) -> BearingSize {
    BearingSize {
        bore: entry.d_mm * MM,
        outside: entry.outside_mm * MM,
    }
}

/// What a model file sets for the SKF model of one bearing (None: the default).
pub(crate) struct SkfChoices {
    /// Integral contact seals.
    pub sealed: bool,
    /// Oil bath or grease.
    pub lubrication: Lubrication,
    /// Height of the oil above the bearing's lowest point (SKF's H), m.
    pub oil_above: f64,
    /// μ_bl.
    pub mu_bl: Option<f64>,
    /// μ_EHL.
    pub mu_ehl: Option<f64>,
    /// Edition of the drag term.
    pub drag_form: DragForm,
    /// V_M of the drag term.
    pub drag_vm: Option<f64>,
    /// The catalogue oil's fitted (μ_bl, μ_EHL) for this kind of bearing, with the oil's key and
    /// the pair's source.
    pub oil_mu: Option<([f64; 2], String)>,
}

/// The SKF sliding friction coefficients of one bearing and where each comes from.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BearingMu {
    /// μ_bl.
    pub mu_bl: f64,
    /// μ_EHL.
    pub mu_ehl: f64,
    /// Where μ_bl comes from: the model file's key, the catalogue oil's fitted pair, or SKF's
    /// constant.
    pub mu_bl_origin: String,
    /// Where μ_EHL comes from (as `mu_bl_origin`).
    pub mu_ehl_origin: String,
}

/// μ_bl and μ_EHL of a bearing of SKF form `kind`: the model file's keys, else the catalogue
/// oil's fitted pair, else SKF's constants (μ_bl 0.12; μ_EHL by type), each with its origin.
pub(crate) fn mu_pair(kind: SkfKind, c: &SkfChoices) -> BearingMu {
    let skf_ehl = match kind {
        SkfKind::CylindricalRoller => MU_EHL_CYLINDRICAL,
        SkfKind::TaperedRoller => MU_EHL_TAPERED,
        SkfKind::DeepGrooveBall | SkfKind::AngularContactBall | SkfKind::FourPointContactBall => MU_EHL,
    };
    let pick = |key: Option<f64>, name: &str, k: usize, skf: f64| match (key, &c.oil_mu) {
        (Some(v), _) => (v, format!("model file key {name}")),
        (None, Some((m, src))) => (m[k], format!("catalogue oil {src}")),
        (None, None) => (skf, format!("SKF constant ({name} = {skf})")),
    };
    let (mu_bl, mu_bl_origin) = pick(c.mu_bl, "mu_bl", 0, MU_BL);
    let (mu_ehl, mu_ehl_origin) = pick(c.mu_ehl, "mu_ehl", 1, skf_ehl);
    BearingMu {
        mu_bl,
        mu_ehl,
        mu_bl_origin,
        mu_ehl_origin,
    }
}

/// The SKF (2004) model of catalogue bearing `entry` at key path `p`: its series row; μ_bl and
/// μ_EHL (the entry's, else the oil's fitted pair, else SKF's constants); the drag term at the
/// oil height; the seal term when sealed. None after a problem.
pub(crate) fn skf(
    entry: &CatalogueBearing,
    series: &[SeriesEntry],
    c: &SkfChoices,
    p: &str,
    problems: &mut Problems,
) -> Option<BearingFriction> {
    let row = entry
        .series
        .as_ref()
        .and_then(|s| series.iter().find(|r| &r.series == s && r.kind == entry.kind));
    let (Some(row), Some(kind)) = (row, skf_kind(entry.kind)) else {
        problems.push(
            format!("{p}.model"),
            "skf",
            format!(
                "{} ({:?}): no SKF geometry constants for this bearing in the catalogue (needle roller \
                 bearings have no SKF row in any source found; other types need a `series` row); use model = \"palmgren\"",
                entry.designation, entry.kind
            ),
        );
        return None;
    };
    let seal = if c.sealed {
        seal_constants(entry.kind, entry.outside_mm).map(|(k1, k2, beta)| {
            // Seal counterface d_s ≈ d + 0.25(D − d) (eMotres catalogue estimate).
            (
                k1,
                k2,
                beta,
                (entry.d_mm + 0.25 * (entry.outside_mm - entry.d_mm)) * MM,
            )
        })
    } else {
        None
    };
    let size = size_of(entry);
    let h = c.oil_above / size.mean();
    let drag_vm = match kind {
        SkfKind::CylindricalRoller | SkfKind::TaperedRoller => drag_vm_roller(h),
        SkfKind::DeepGrooveBall | SkfKind::AngularContactBall | SkfKind::FourPointContactBall => {
            drag_vm_ball(h)
        }
    };
    let BearingMu { mu_bl, mu_ehl, .. } = mu_pair(kind, c);
    for (k, v) in [("mu_bl", mu_bl), ("mu_ehl", mu_ehl)] {
        problems.in_range(&format!("{p}.{k}"), v, 0.0, 0.5, "");
    }
    let drag_vm = c.drag_vm.unwrap_or(drag_vm);
    problems.in_range(&format!("{p}.drag_vm"), drag_vm, 0.0, 0.01, "");
    let input = SkfInput {
        kind,
        constants: SkfConstants {
            r1: row.r1,
            r2: row.r2,
            r3: row.r3,
            s1: row.s1,
            s2: row.s2,
            s3: row.s3,
            k_z: row.k_z,
            k_l: row.k_l,
        },
        size,
        c0: entry.c0_kn * 1e3,
        lubrication: c.lubrication,
        mu_bl,
        mu_ehl,
        seal,
        oil_level: c.oil_above,
        drag_vm,
        drag_form: c.drag_form,
        rows: entry.rows.unwrap_or(1.0),
        width: entry.b_mm * MM,
        axial_factor_y: entry.y.unwrap_or(0.0),
    };
    match Skf::new(&input) {
        Ok(m) => Some(BearingFriction::Skf(m)),
        Err(e) => {
            problems.push(p, q(&entry.designation), e.to_string());
            None
        }
    }
}

/// The Palmgren model of catalogue bearing `entry` at key path `p` (its type's factors; no seal
/// term). None after a problem.
pub(crate) fn palmgren(
    entry: &CatalogueBearing,
    sealed: bool,
    p: &str,
    problems: &mut Problems,
) -> Option<BearingFriction> {
    if sealed {
        problems.push(
            format!("{p}.sealed"),
            "true",
            "integral seals are modelled by the SKF seal term only: use model = \"skf\" or a [[seals]] entry",
        );
    }
    let (f0_bath, f1, ka, kr) = entry.kind.palmgren_defaults();
    // Grease: f0 of thermca's grease column is not carried; oil bath is the gearbox case.
    let f0 = f0_bath;
    match Palmgren::new(size_of(entry), f0, f1, ka, kr) {
        Ok(m) => Some(BearingFriction::Palmgren(m)),
        Err(e) => {
            problems.push(p, q(&entry.designation), e.to_string());
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::drag_vm_roller;

    /// The roller V_M curve as the peer P5 interpolates it (its printed values,
    /// docs/validation.md §Bearings).
    #[test]
    fn roller_vm_interpolates_like_the_p5_peer() {
        for (x, want) in [(0.75, 9.466667e-4), (1.2, 1.5e-3), (10.0 / 46.0, 3.313043e-4)] {
            assert!((drag_vm_roller(x) / want - 1.0).abs() < 1e-6, "{x}");
        }
        assert_eq!(drag_vm_roller(-1.0), 0.0);
        assert_eq!(drag_vm_roller(5.0), 1.5e-3);
    }
}
