//! Bearing models against peers (reference figures from running the peers outside the
//! repository, docs/validation.md §Bearings) and their units and scaling.

use super::skf::{Lubrication, SkfInput};
use super::*;

const RPM: f64 = std::f64::consts::PI / 30.0;

fn input(kind: SkfKind, c: SkfConstants, d: f64, big_d: f64, c0: f64, mu: (f64, f64)) -> SkfInput {
    SkfInput {
        kind,
        constants: c,
        size: BearingSize {
            bore: d * 1e-3,
            outside: big_d * 1e-3,
        },
        c0,
        lubrication: Lubrication::Grease,
        mu_bl: mu.0,
        mu_ehl: mu.1,
        seal: None,
        oil_level: 0.0,
        drag_vm: 0.0012,
        rows: 1.0,
    }
}

fn dgbb(r1: f64, s1: f64, s2: f64) -> SkfConstants {
    SkfConstants {
        r1,
        r2: 1.7,
        r3: 0.0,
        s1,
        s2,
        k_z: 3.1,
    }
}

fn moment(i: &SkfInput, n: f64, fr: f64, fa: f64, nu_cst: f64) -> BearingMoment {
    let m = BearingFriction::Skf(Skf::new(i).unwrap());
    let t = m.load_terms(
        n * RPM,
        BearingLoad {
            radial: fr,
            axial: fa,
        },
    );
    m.moment(&t, BearingOil::new(nu_cst * 1e-6))
}

fn close(got: f64, want: f64, tol: f64) {
    assert!((got / want - 1.0).abs() < tol, "got {got}, want {want}");
}

/// Peer P1 (Python deep-groove model, docs/validation.md): μ_bl 0.12, μ_EHL 0.1, grease.
#[test]
fn deep_groove_matches_the_python_peer() {
    let mu = (0.12, 0.1);
    // 6208 (series 62), ν 20 mm²/s, 3000 r/min: radial form, then the axial (α_F) form.
    let i = input(
        SkfKind::DeepGrooveBall,
        dgbb(3.9e-7, 3.23e-3, 36.5),
        40.0,
        80.0,
        19000.0,
        mu,
    );
    close(moment(&i, 3000.0, 1500.0, 0.0, 20.0).total(), 0.061094203, 1e-6);
    close(
        moment(&i, 3000.0, 1500.0, 1200.0, 20.0).total(),
        0.212206324,
        1e-6,
    );
    // 61811 (series 618), ν 30 mm²/s, 2000 r/min, F_r 300 N, F_a 200 N.
    let i = input(
        SkfKind::DeepGrooveBall,
        dgbb(4.7e-7, 6.5e-3, 0.78),
        55.0,
        72.0,
        8800.0,
        mu,
    );
    close(moment(&i, 2000.0, 300.0, 200.0, 30.0).total(), 0.069848548, 1e-6);
    // 6010 fully immersed: the drag term alone (the peer sets φ_rs = 1 when submerged, the
    // SKF model with K_rs = 3e-8 does not; docs/validation.md).
    let mut i = input(
        SkfKind::DeepGrooveBall,
        dgbb(4.1e-7, 3.73e-3, 14.6),
        50.0,
        80.0,
        16000.0,
        mu,
    );
    i.oil_level = 1.0;
    close(moment(&i, 2000.0, 800.0, 0.0, 12.0).drag, 0.036578007, 1e-6);
}

/// Peer P2 (eMotres bearings module): constant μ_sl 0.05, grease (K_rs 6e-8).
#[test]
fn angular_contact_and_sealed_deep_groove_match_the_emotres_peer() {
    let mu = (0.05, 0.05);
    let c = SkfConstants {
        r1: 4.33e-7,
        r2: 2.02,
        r3: 2.44e-12,
        s1: 1.0e-2,
        s2: 0.8,
        k_z: 4.4,
    };
    let i = input(SkfKind::AngularContactBall, c, 20.0, 47.0, 0.0, mu);
    close(moment(&i, 3000.0, 800.0, 600.0, 20.0).total(), 0.032567802, 1e-6);
    close(moment(&i, 12000.0, 300.0, 1000.0, 8.0).total(), 0.043333887, 1e-6);
    // 61811-2RS1 with contact seals (K_S1 0.018, K_S2 20, β 2.25, d_s 59.5 mm).
    let mut i = input(
        SkfKind::DeepGrooveBall,
        dgbb(4.7e-7, 6.5e-3, 0.78),
        55.0,
        72.0,
        8800.0,
        mu,
    );
    i.seal = Some((0.018, 20.0, 2.25, 59.5e-3));
    close(moment(&i, 2000.0, 150.0, 0.0, 30.0).total(), 0.212046110, 1e-6);
}

#[test]
fn skf_units_and_scaling() {
    let i = input(
        SkfKind::DeepGrooveBall,
        dgbb(3.9e-7, 3.23e-3, 36.5),
        40.0,
        80.0,
        19000.0,
        (0.12, 0.05),
    );
    // Rolling ∝ F_r^0.54, sliding ∝ F_r^(5/3) at fixed speed and viscosity.
    let (a, b) = (
        moment(&i, 1500.0, 1000.0, 0.0, 30.0),
        moment(&i, 1500.0, 2000.0, 0.0, 30.0),
    );
    close(b.rolling / a.rolling, 2f64.powf(0.54), 1e-12);
    close(b.sliding / a.sliding, 2f64.powf(5.0 / 3.0), 1e-12);
    // At vanishing speed φ_ish, φ_rs → 1: M_rr → G_rr (ν n)^0.6 (N·mm → N·m).
    let n = 1e-3;
    let g_rr = 3.9e-7 * 60f64.powf(1.96) * 1000f64.powf(0.54);
    close(
        moment(&i, n, 1000.0, 0.0, 30.0).rolling,
        1e-3 * g_rr * (30.0 * n).powf(0.6),
        1e-6,
    );
    // Power = M·ω and zero at standstill.
    let m = BearingFriction::Skf(Skf::new(&i).unwrap());
    let load = BearingLoad {
        radial: 1000.0,
        axial: 0.0,
    };
    let oil = BearingOil::new(30e-6);
    let w = 1500.0 * RPM;
    close(
        m.power(w, load, oil),
        m.moment(&m.load_terms(w, load), oil).total() * w,
        1e-12,
    );
    assert_eq!(m.power(0.0, load, oil), 0.0);
    // Reversing the rotation changes nothing.
    close(m.power(-w, load, oil), m.power(w, load, oil), 1e-15);
}

/// Palmgren in catalogue units against thermca's SI form of the same law
/// (M0 = 36008·f0·r_m³·(ν ω)^0.666 N·m), to 1 %.
#[test]
fn palmgren_units_match_thermca_si_form() {
    let size = BearingSize {
        bore: 0.030,
        outside: 0.090,
    };
    let m = Palmgren::new(size, 3.0, 0.0, 0.0, 1.0).unwrap();
    let (nu, rpm) = (13.5e-6, 2175.0);
    let w = rpm * RPM;
    let t = m.load_terms(rpm, BearingLoad::default());
    let got = m.moment(&t, BearingOil::new(nu)).rolling;
    let r = size.mean() / 2.0;
    close(got, 36008.0 * 3.0 * r.powi(3) * (nu * w).powf(0.666), 0.01);
    // Below ν n = 2000 the load-independent term is constant: 160e-7·f0·d_m³ N·mm.
    let slow = m.moment(
        &m.load_terms(10.0, BearingLoad::default()),
        BearingOil::new(10e-6),
    );
    close(slow.rolling, 1e-3 * 160e-7 * 3.0 * 60f64.powi(3), 1e-12);
    // M1 = f1·P1·d_m with P1 = max(F_r, k_a F_a + k_r F_r).
    let m = Palmgren::new(size, 0.0, 3e-4, 1.0, -0.1).unwrap();
    let t = m.load_terms(
        rpm,
        BearingLoad {
            radial: 1000.0,
            axial: 2000.0,
        },
    );
    close(
        m.moment(&t, BearingOil::new(nu)).sliding,
        1e-3 * 3e-4 * 1900.0 * 60.0,
        1e-12,
    );
}

/// Vanishing speeds (a cycle row of 1e-300 rpm) give finite, non-negative power: the drag term's
/// n²·(n f_t dm²)^-1.379 once gave 0·∞ = NaN there (issue 16 campaign, case 79658).
#[test]
fn vanishing_speeds_give_finite_power() {
    let mut i = input(
        SkfKind::DeepGrooveBall,
        dgbb(4.1e-7, 3.73e-3, 14.6),
        50.0,
        80.0,
        16000.0,
        (0.12, 0.1),
    );
    i.oil_level = 1.0;
    let m = BearingFriction::Skf(Skf::new(&i).unwrap());
    let load = BearingLoad {
        radial: 800.0,
        axial: 0.0,
    };
    for w in [1e-300, 1e-200, 1e-100, 1e-20, 1e-9] {
        let t = m.load_terms(w, load);
        let mo = m.moment(&t, BearingOil::new(12e-6));
        let p = m.power(w, load, BearingOil::new(12e-6));
        assert!(mo.total().is_finite() && mo.drag >= 0.0, "{w}: {mo:?}");
        assert!(p.is_finite() && (0.0..1e-6).contains(&p), "{w}: {p} W");
    }
}
