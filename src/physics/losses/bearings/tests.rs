//! Bearing models against peers (reference figures from running the peers outside the
//! repository, docs/validation.md §Bearings) and their units and scaling.

use super::skf::{Lubrication, SkfInput};
use super::*;

use crate::physics::units::RAD_S_PER_RPM;

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
        drag_form: DragForm::Current,
        rows: 1.0,
        width: 0.0,
        axial_factor_y: 0.0,
    }
}

fn dgbb(r1: f64, s1: f64, s2: f64) -> SkfConstants {
    SkfConstants {
        r1,
        r2: 1.7,
        r3: 0.0,
        s1,
        s2,
        s3: 0.0,
        k_z: 3.1,
        k_l: 0.0,
    }
}

fn moment(i: &SkfInput, n: f64, fr: f64, fa: f64, nu_cst: f64) -> BearingMoment {
    let m = BearingFriction::Skf(Skf::new(i).unwrap());
    let t = m.load_terms(
        n * RAD_S_PER_RPM,
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
        s3: 2.44e-12,
        k_z: 4.4,
        k_l: 0.0,
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
    let w = 1500.0 * RAD_S_PER_RPM;
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
    let w = rpm * RAD_S_PER_RPM;
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

fn roller(r1: f64, r2: f64, s1: f64, s2: f64, k_z: f64, k_l: f64) -> SkfConstants {
    SkfConstants {
        r1,
        r2,
        r3: 0.0,
        s1,
        s2,
        s3: 0.0,
        k_z,
        k_l,
    }
}

/// Peer P4 (cfernandesFEUP/Gear-Calculation `GearC/bearings.py` @345f3128, the FZG-rig code):
/// M_rr + M_sl of NJ 406 and QJ 308 N2MA with its own constants, oil bath (K_rs 3e-8), μ_bl 0.12,
/// μ_EHL 0.02 (roller) / 0.05 (ball). Its drag term is an older SKF form (10·V_M·K_roll·B·d_m^4·n²,
/// doubled) and is not compared (docs/validation.md).
#[test]
fn cylindrical_and_four_point_match_the_fernandes_peer() {
    let mut i = input(
        SkfKind::CylindricalRoller,
        roller(1.0e-6, 0.0, 0.16, 0.0015, 5.1, 0.65),
        30.0,
        90.0,
        53000.0,
        (0.12, 0.02),
    );
    i.lubrication = Lubrication::OilBath;
    let rr_sl = |i: &SkfInput, n, fr, fa, nu| {
        let m = moment(i, n, fr, fa, nu);
        assert_eq!(m.drag, 0.0);
        m.rolling + m.sliding
    };
    close(rr_sl(&i, 2175.0, 2000.0, 0.0, 13.5), 9.698774876e-02, 1e-6);
    close(rr_sl(&i, 2175.0, 2000.0, 500.0, 13.5), 1.800069787e-01, 1e-6);
    close(rr_sl(&i, 1450.0, 6000.0, 0.0, 40.0), 2.007201539e-01, 1e-6);
    let mut i = input(
        SkfKind::FourPointContactBall,
        SkfConstants {
            r1: 4.78e-7,
            r2: 2.42,
            r3: 1.40e-12,
            s1: 1.20e-2,
            s2: 0.9,
            s3: 1.40e-12,
            k_z: 3.1,
            k_l: 0.0,
        },
        40.0,
        90.0,
        1.0,
        (0.12, 0.05),
    );
    i.lubrication = Lubrication::OilBath;
    close(rr_sl(&i, 3000.0, 1000.0, 1500.0, 20.0), 1.654140363e-01, 1e-6);
    close(rr_sl(&i, 6000.0, 300.0, 2500.0, 8.0), 1.997516925e-01, 1e-6);
}

/// Peer P6 (`geometry_variables.py`, SKF Table 1a, search-index file 52327465425): G_rr and
/// G_sl of tapered (R2·Y, S2·Y given to the peer, which omits Y) and cylindrical roller bearings.
#[test]
fn tapered_and_cylindrical_forms_match_the_table_peer() {
    let g = |i: &SkfInput, fr: f64, fa: f64| {
        let t = Skf::new(i).unwrap().load_terms(
            1500.0,
            BearingLoad {
                radial: fr,
                axial: fa,
            },
        );
        (t.g_rr, t.g_sl)
    };
    let mut i = input(
        SkfKind::TaperedRoller,
        roller(1.76e-6, 10.9, 0.017, 2.0, 6.0, 0.7),
        30.0,
        62.0,
        44000.0,
        (0.12, 0.002),
    );
    i.axial_factor_y = 1.6;
    let (rr, sl) = g(&i, 3000.0, 0.0);
    close(rr, 1.908903157e-01, 1e-6);
    close(sl, 1.177691656e+03, 1e-6);
    let (rr, sl) = g(&i, 3000.0, 1200.0);
    close(rr, 3.633601459e-01, 1e-6);
    close(sl, 2.685136976e+03, 1e-6);
    i.size = BearingSize {
        bore: 0.040,
        outside: 0.080,
    };
    let (rr, sl) = g(&i, 5000.0, 2500.0);
    close(rr, 8.518632585e-01, 1e-6);
    close(sl, 6.345652695e+03, 1e-6);
    let i = input(
        SkfKind::CylindricalRoller,
        roller(1.09e-6, 0.0, 0.16, 0.0015, 5.1, 0.65),
        50.0,
        90.0,
        69500.0,
        (0.12, 0.02),
    );
    let (rr, sl) = g(&i, 4000.0, 300.0);
    close(rr, 3.987965308e-01, 1e-6);
    close(sl, 2.616997048e+03, 1e-6);
    // A tapered bearing without Y is refused.
    let mut bad = i;
    bad.kind = SkfKind::TaperedRoller;
    assert!(Skf::new(&bad).is_err());
}

/// Peer P5 (`drag.py`, roller branch, search-index file 67381577723): oil-bath drag of NJ 406
/// (H 45 and 72 mm) and of a 30206 (H 10 mm), with the V_M the peer interpolates.
#[test]
fn roller_drag_matches_the_p5_peer() {
    let vm = |x: f64, (x0, v0): (f64, f64), (x1, v1): (f64, f64)| v0 + (v1 - v0) * (x - x0) / (x1 - x0);
    let mut i = input(
        SkfKind::CylindricalRoller,
        roller(1.0e-6, 0.0, 0.16, 0.0015, 5.1, 0.65),
        30.0,
        90.0,
        53000.0,
        (0.12, 0.02),
    );
    i.lubrication = Lubrication::OilBath;
    i.width = 0.023;
    i.oil_level = 0.045;
    i.drag_vm = vm(0.75, (0.5, 6.8e-4), (0.8, 1.0e-3));
    close(moment(&i, 2175.0, 2000.0, 0.0, 13.5).drag, 2.707901818e-02, 1e-6);
    i.oil_level = 0.072;
    i.drag_vm = 1.5e-3;
    close(moment(&i, 3000.0, 2000.0, 0.0, 30.0).drag, 9.047268662e-02, 1e-6);
    let mut i = input(
        SkfKind::TaperedRoller,
        roller(1.76e-6, 10.9, 0.017, 2.0, 6.0, 0.7),
        30.0,
        62.0,
        44000.0,
        (0.12, 0.002),
    );
    i.axial_factor_y = 1.6;
    i.width = 0.01725;
    i.oil_level = 0.010;
    i.drag_vm = vm(10.0 / 46.0, (0.2, 3.0e-4), (0.3, 4.8e-4));
    close(moment(&i, 1500.0, 2000.0, 0.0, 20.0).drag, 3.038937437e-03, 1e-6);
    // Drag without width or K_L is refused.
    i.width = 0.0;
    assert!(Skf::new(&i).is_err());
}

/// Roller forms: rolling ∝ F_r^0.31, sliding linear in the loads; tapered axial load enters
/// through Y.
#[test]
fn roller_units_and_scaling() {
    let i = input(
        SkfKind::CylindricalRoller,
        roller(1.0e-6, 0.0, 0.16, 0.0015, 5.1, 0.65),
        30.0,
        90.0,
        53000.0,
        (0.12, 0.02),
    );
    let (a, b) = (
        moment(&i, 1500.0, 1000.0, 0.0, 30.0),
        moment(&i, 1500.0, 3000.0, 0.0, 30.0),
    );
    close(b.rolling / a.rolling, 3f64.powf(0.31), 1e-12);
    close(b.sliding / a.sliding, 3.0, 1e-12);
    let mut t = input(
        SkfKind::TaperedRoller,
        roller(1.76e-6, 10.9, 0.017, 2.0, 6.0, 0.7),
        30.0,
        62.0,
        44000.0,
        (0.12, 0.002),
    );
    t.axial_factor_y = 2.0;
    let (m1, m2) = (
        moment(&t, 1500.0, 1000.0, 100.0, 30.0),
        moment(&t, 1500.0, 1000.0 + 10.9 * 2.0 * 100.0, 0.0, 30.0),
    );
    // F_r + R2·Y·F_a in G_rr: the same rolling moment as a purely radial load of that size.
    close(m1.rolling, m2.rolling, 1e-12);
    assert_eq!(moment(&t, 0.0, 1000.0, 100.0, 30.0).total(), 0.0);
}

/// Vanishing speeds (a cycle row of 1e-300 rpm) give finite, non-negative power: the drag term
/// written as n²·(n f_t dm²)^-1.379 would give 0·∞ = NaN there (hostile-input campaign, seed 23, case 79658).
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
        assert!((0.0..1e-6).contains(&p), "{w}: {p} W");
    }
}

/// Speed powers per unit speed times the powers of the speed give the terms computed at that
/// speed, to rounding (the speed powers do not depend on the SKF form: a deep-groove ball bearing
/// under radial and combined load, with and without oil-bath drag, turning and at standstill);
/// Palmgren has none.
#[test]
fn speed_powers_per_unit_times_powers_of_the_speed() {
    let c = dgbb(3.3e-7, 3.3e-3, 0.0);
    let dry = input(SkfKind::DeepGrooveBall, c, 40.0, 80.0, 19000.0, (0.12, 0.1));
    let bath = SkfInput {
        oil_level: 0.03,
        lubrication: Lubrication::OilBath,
        ..dry
    };
    let load = |fr, fa| BearingLoad {
        radial: fr,
        axial: fa,
    };
    let size = BearingSize {
        bore: 0.04,
        outside: 0.08,
    };
    let palmgren = BearingFriction::Palmgren(Palmgren::new(size, 3.0, 0.0, 0.0, 1.0).unwrap());
    assert_eq!(palmgren.speed_powers_per_unit(1.0), None);
    let bearings = [dry, bath].map(|i| BearingFriction::Skf(Skf::new(&i).unwrap()));
    // The dry one has no oil-bath drag term, the other has.
    let drag = |b: &BearingFriction| b.speed_powers_per_unit(1.0).unwrap()[3];
    assert!(drag(&bearings[0]) == 0.0 && drag(&bearings[1]) > 0.0);
    for (deep_groove, ratio) in bearings
        .iter()
        .flat_map(|b| [1.0, -0.37, 2.9, 0.0].map(|r| (b, r)))
    {
        let unit = deep_groove.speed_powers_per_unit(ratio).unwrap();
        for w in [0.0, 3.0, 150.0, 600.0] {
            let p = skf::speed_exponent_powers(w);
            let speed = [0, 1, 2, 3].map(|i| unit[i] * p[i]);
            for l in [load(2000.0, 0.0), load(1200.0, 400.0)] {
                let direct = deep_groove.load_terms(ratio * w, l);
                let scaled = deep_groove.load_terms_with_speed(ratio * w, l, Some(speed));
                assert_eq!(
                    (scaled.g_rr, scaled.g_sl, scaled.n_rpm),
                    (direct.g_rr, direct.g_sl, direct.n_rpm)
                );
                for (a, b) in scaled.speed.iter().zip(&direct.speed) {
                    assert!(
                        (a - b).abs() <= 1e-13 * b.abs(),
                        "ratio {ratio} w {w}: {a} vs {b}"
                    );
                }
            }
        }
    }
}

/// The FZG group's bearing code (Gear-Calculation `GearC/bearings.pl` @0e4a135, run outside the
/// repository; `validation/peer_data/gear_calculation_bearings.csv`) over its NJ 406 and
/// QJ 308 N2MA grid (5 oils × 3 temperatures, 1–6 kN radial, 0 / 1.5 kN axial on the QJ,
/// 500–3000 r/min): at its fitted μ_bl, μ_EHL and its drag form (the older SKF term with its
/// V_M 1.49e-4, which it doubles) every term within 1e-6.
#[test]
fn nj406_and_qj308_match_the_fzg_group_code_over_its_grid() {
    let text = include_str!("../../../../validation/peer_data/gear_calculation_bearings.csv");
    let mut n_rows = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        let (nu, mu_bl, mu_ehl, fr, fa, n) = (num(3), num(4), num(5), num(6), num(7), num(8));
        let (want_rr, want_sl, want_drag) = (num(9), num(10), num(11));
        let mut i = if f[0] == "NJ 406" {
            let mut i = input(
                SkfKind::CylindricalRoller,
                roller(1.0e-6, 0.0, 0.16, 0.0015, 5.1, 0.65),
                30.0,
                90.0,
                53000.0,
                (mu_bl, mu_ehl),
            );
            i.width = 23e-3;
            i
        } else {
            input(
                SkfKind::FourPointContactBall,
                SkfConstants {
                    r1: 4.78e-7,
                    r2: 2.42,
                    r3: 1.40e-12,
                    s1: 1.20e-2,
                    s2: 0.9,
                    s3: 1.40e-12,
                    k_z: 3.1,
                    k_l: 0.0,
                },
                40.0,
                90.0,
                1.0,
                (mu_bl, mu_ehl),
            )
        };
        i.lubrication = Lubrication::OilBath;
        i.oil_level = 0.06; // any level: the older term does not depend on it
        i.drag_vm = 1.49e-4;
        i.drag_form = DragForm::Older;
        let m = moment(&i, n, fr, fa, nu);
        // N·m here, N·mm in the peer
        close(m.rolling * 1e3, want_rr, 1e-6);
        close(m.sliding * 1e3, want_sl, 1e-6);
        close(2.0 * m.drag * 1e3, want_drag, 1e-6);
        n_rows += 1;
    }
    assert_eq!(n_rows, 600);
}
