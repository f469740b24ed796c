//! `air_density_reference_c` of `[[thermal.coolers]]`: a fixed-speed fan's air stream whose
//! capacity rate scales as T_ref/T_air (K). The FZG C's losses with the oil properties frozen
//! (a constant source) drive small networks: the cooler's heat flow against the hand-computed
//! factor, the analytic time derivative against a central difference of the right-hand side when
//! the air is a boundary following a ramp, and the assembled Jacobian against central
//! differences and products when the air is a node with capacity (a thermostat cooler and a
//! PI-valve cooler on it).

use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::Scene;

mod common;
use common::{fzg_frozen, steady_inputs};

/// Oil node capacity, J/K, and the cooler's ε·C_min at the reference, W/K.
const C_OIL: f64 = 4000.0;
const EPS_C: f64 = 0.5 * 100.0;
/// Reference air temperature of the capacity rate, °C.
const T_REF_C: f64 = 15.0;

/// Oil cooled by a fan cooler into an air boundary ramping from 10 °C (t = 0) to 40 °C
/// (t = 1000 s); with `reference` the cooler's capacity rate follows the air's density.
fn boundary_air(reference: Option<f64>) -> Scene {
    let key = reference.map_or(String::new(), |r| format!("air_density_reference_c = {r:e}\n"));
    let text = format!(
        r#"
[thermal]
oil_node = "oil"
initial_temp_c = 80.0
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = {C_OIL:e}
[[thermal.boundaries]]
name = "air"
series = [[0.0, 10.0], [1000.0, 40.0]]
[[thermal.coolers]]
name = "fan_cooler"
hot = "oil"
cold = "air"
effectiveness = 0.5
capacity_rate_w_per_k = 100.0
{key}"#
    );
    fzg_frozen(&text, 80.0)
}

#[test]
fn the_heat_flow_scales_as_the_reference_over_the_air_temperature() {
    let (with, without) = (boundary_air(Some(T_REF_C)), boundary_air(None));
    let inputs = steady_inputs(3000.0, 150.0);
    let (mut w1, mut w0) = (with.work(inputs), without.work(inputs));
    let y = vec![80.0 + KELVIN_OFFSET];
    let (mut f1, mut f0) = (vec![0.0; with.n_states()], vec![0.0; without.n_states()]);
    // t = 500 s: air 25 °C. Hand: the factor 288.15/298.15 = 0.96646; the cooler without it
    // carries 50 W/K × 55 K = 2750 W, with it 2657.8 W: the oil cools 92.2 W / 4000 J/K slower.
    with.rhs(500.0, &y, &mut w1, &mut f1);
    without.rhs(500.0, &y, &mut w0, &mut f0);
    let factor = (T_REF_C + KELVIN_OFFSET) / (25.0 + KELVIN_OFFSET);
    assert!((factor - 0.96646).abs() < 1e-5, "{factor}");
    let q0 = EPS_C * 55.0;
    let expect = (1.0 - factor) * q0 / C_OIL;
    assert!((expect - 92.2 / 4000.0).abs() < 1e-4, "{expect}");
    let got = f1[0] - f0[0];
    assert!((got - expect).abs() < 1e-12, "{got} vs {expect}");
    // At the reference air temperature (t = 1000/6 s: 15 °C) the two agree.
    let t = 1000.0 / 6.0;
    with.rhs(t, &y, &mut w1, &mut f1);
    without.rhs(t, &y, &mut w0, &mut f0);
    assert!((f1[0] - f0[0]).abs() < 1e-12, "{} vs {}", f1[0], f0[0]);
}

#[test]
fn the_time_derivative_follows_the_air_density_of_a_boundary_ramp() {
    let scene = boundary_air(Some(T_REF_C));
    let mut work = scene.work(steady_inputs(3000.0, 150.0));
    let y = vec![80.0 + KELVIN_OFFSET];
    let n = scene.n_states();
    let (mut ft, mut fp, mut fm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let d = 1e-3;
    for t in [100.0, 500.0, 900.0] {
        scene.time_derivative(t, &y, &mut work, &mut ft);
        scene.rhs(t + d, &y, &mut work, &mut fp);
        scene.rhs(t - d, &y, &mut work, &mut fm);
        let fd = (fp[0] - fm[0]) / (2.0 * d);
        // Hand: ∂q/∂T_air = −g·T_oil/T_air (g = ε·C·T_ref/T_air), the air warming 0.03 K/s.
        let ta = 10.0 + 0.03 * t + KELVIN_OFFSET;
        let g = EPS_C * (T_REF_C + KELVIN_OFFSET) / ta;
        let hand = g * y[0] / ta * 0.03 / C_OIL;
        assert!((ft[0] - fd).abs() <= 1e-7 * fd.abs(), "t {t}: {} vs {fd}", ft[0]);
        assert!(
            (ft[0] - hand).abs() <= 1e-12 * hand.abs(),
            "t {t}: {} vs {hand}",
            ft[0]
        );
    }
}

/// Oil and a capacity node of cooler air (air heated by the coolers, cooled by a 30 W/K link to a
/// 20 °C ambient); a thermostat cooler (open 70 °C, full 90 °C) and a PI-valve cooler, both
/// onto the air node and following its density.
fn node_air() -> Scene {
    let text = format!(
        r#"
[thermal]
oil_node = "oil"
initial_temp_c = 80.0
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = {C_OIL:e}
[[thermal.nodes]]
name = "air"
capacity_j_per_k = 500.0
[[thermal.boundaries]]
name = "ambient"
temp_c = 20.0
[[thermal.links]]
between = ["air", "ambient"]
conductance_w_per_k = 30.0
[[thermal.coolers]]
name = "thermostat_cooler"
hot = "oil"
cold = "air"
effectiveness = 0.5
capacity_rate_w_per_k = 100.0
thermostat = {{ open_c = 70.0, full_c = 90.0 }}
air_density_reference_c = {T_REF_C:e}
[[thermal.coolers]]
name = "valve_cooler"
hot = "oil"
cold = "air"
effectiveness = 1.0
capacity_rate_w_per_k = 20.0
air_density_reference_c = 0.0
[[thermal.controls]]
name = "bypass"
kind = "pi_valve"
sensor = "oil"
cooler = "valve_cooler"
set_c = 75.0
gain_per_k = 0.05
integral_time_s = 200.0
min_share = 0.0
max_share = 1.0
"#
    );
    fzg_frozen(&text, 80.0)
}

#[test]
fn the_jacobian_holds_the_air_nodes_density_column() {
    let scene = node_air();
    let mut work = scene.work(steady_inputs(3000.0, 150.0));
    let mut y = scene.initial_state(None);
    let (th, ta) = (80.0 + KELVIN_OFFSET, 45.0 + KELVIN_OFFSET);
    y[0] = th;
    y[1] = ta;
    let row = scene.thermal().integral_row(0).unwrap();
    y[row] = 0.3;
    scene.initial_control_modes(&y, &mut work);
    assert_eq!(work.net.mode[0], 1, "the valve between its limits");
    let n = scene.n_states();
    let dense = common::jacobian::checked_dense_jacobian(&scene, &y, &mut work);
    // The oil's row, the air's column, by hand: each cooler's q = g·T_ref/T_air·x·(T_oil − T_air)
    // has ∂q/∂T_air = −g·x·T_ref·T_oil/T_air² (the thermostat half open at 80 °C: x = 0.5; the
    // valve's share gain·(T_oil − set) + I = 0.05·5 + 0.3 = 0.55, its reference 0 °C).
    let x_valve = 0.05 * 5.0 + 0.3;
    // The oil loses q: its rate rises by ∂q/∂T_air's magnitude over its capacity.
    let by_hand =
        (EPS_C * 0.5 * (T_REF_C + KELVIN_OFFSET) + 20.0 * x_valve * KELVIN_OFFSET) * th / (ta * ta) / C_OIL;
    assert!(
        (dense[n] - by_hand).abs() <= 1e-9 * by_hand.abs(),
        "∂(dT_oil/dt)/∂T_air = {} vs {by_hand}",
        dense[n]
    );
}
