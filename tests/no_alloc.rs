//! Evaluating all losses of a gearbox at an operating point allocates nothing (counting allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use geartherm::model;
use geartherm::scene::{LossScene, OperatingPoint};

struct Counting;
// Counted per thread: the tests run in parallel and must not see each other's allocations.
thread_local! {
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

fn allocs() -> usize {
    COUNT.with(Cell::get)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn loss_evaluation_allocates_nothing() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for m in ["at6_lepelletier", "fzg_c", "helical_stage", "pt6_spur_pair"] {
        let gb = model::load(&root.join(format!("models/{m}.toml"))).unwrap();
        let scene = LossScene::compile(&gb).unwrap();
        let mut out = vec![0.0; scene.len()];
        let ops: Vec<OperatingPoint> = (0..gb.gear_states.len())
            .map(|state| OperatingPoint {
                state,
                input_speed: 250.0,
                input_torque: 150.0,
                oil: gb.oil.properties(350.0),
            })
            .collect();
        let before = allocs();
        for op in &ops {
            scene.evaluate(op, &mut out);
        }
        let after = allocs();
        assert_eq!(after - before, 0, "{m}: evaluation allocated");
        assert!(out.iter().all(|w| w.is_finite() && *w >= 0.0), "{m}: {out:?}");
    }
}

#[test]
fn sample_switch_right_hand_side_and_jacobian_product_allocate_nothing() {
    use geartherm::scene::{Inputs, Scene};
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for m in ["at6_lepelletier", "fzg_c", "helical_stage", "pt6_spur_pair"] {
        let gb = model::load(&root.join(format!("models/{m}.toml"))).unwrap();
        let scene = Scene::compile(&gb).unwrap();
        let inputs = Inputs {
            state: 0,
            input_speed: 250.0,
            input_torque: 150.0,
            vehicle_speed: 20.0,
        };
        let mut work = scene.work(inputs);
        let mut y = scene.initial_state(None);
        let mut dy = vec![0.0; y.len()];
        let mut v = vec![0.0; y.len()];
        let mut jv = vec![0.0; y.len()];
        let mut jac = vec![0.0; scene.jacobian_pattern().len()];
        let mut slopes = vec![0.0; scene.items()];
        let mut ft = vec![0.0; y.len()];
        let before = allocs();
        for k in 0..20 {
            y[scene.thermal().oil] += 0.5 * k as f64; // new T_oil: the Jacobian column is recomputed
                                                      // a new sample: per-sample conductances and loss terms are recomputed
            let sample = Inputs {
                input_speed: 250.0 + k as f64,
                input_torque: if k % 2 == 0 { 150.0 } else { -40.0 },
                ..inputs
            };
            scene.set_inputs(sample, &mut work);
            scene.rhs(k as f64, &y, &mut work, &mut dy);
            for j in 0..scene.nodes() {
                v.iter_mut().for_each(|x| *x = 0.0);
                v[j] = 1.0;
                scene.jvp(k as f64, &y, &v, &mut work, &mut jv);
            }
            // The assembled Jacobian too.
            scene.jacobian_values(k as f64, &y, &mut work, &mut jac);
            // And what ROS3 evaluates per step: loss slopes, the Jacobian from them, ∂f/∂t.
            scene.loss_slopes(k as f64, &y, &mut work, &mut slopes);
            scene.jacobian_values_with_slopes(k as f64, &y, &mut work, &slopes, &mut jac);
            scene.time_derivative(k as f64, &y, &mut work, &mut ft);
        }
        let after = allocs();
        assert_eq!(after - before, 0, "{m}: rhs/jvp allocated");
        assert!(
            dy.iter()
                .chain(&jv)
                .chain(&slopes)
                .chain(&ft)
                .all(|x| x.is_finite()),
            "{m}"
        );
        assert!(work.jac_evals >= 20, "{m}: Jacobian column recomputed per T_oil");
        assert!(work.terms.prepared >= 20, "{m}: loss terms prepared per sample");
    }
}

#[test]
fn ros3_allocates_nothing_per_step_or_row() {
    // Two cycles of different lengths: the trajectory reserves its rows (states and losses in one
    // buffer each) before integrating, so the count does not grow with the rows or the steps.
    use geartherm::cycle::DriveCycle;
    use geartherm::scene::Scene;
    use geartherm::solve::drive::segments;
    use geartherm::solve::transient::{integrate, Method, TransientOptions};
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let gb = model::load(&root.join("models/fzg_c.toml")).unwrap();
    let scene = Scene::compile(&gb).unwrap();
    let (_, segs) = segments(&gb, &DriveCycle::resolve("wltc").unwrap()).unwrap();
    let o = TransientOptions {
        method: Method::Ros3,
        ..TransientOptions::default()
    };
    let count = |segs: &[geartherm::solve::transient::Segment]| {
        let before = allocs();
        let t = integrate(&scene, segs, &o, &mut |_, _| {}).unwrap();
        (allocs() - before, t.stats.steps, t.times.len())
    };
    let (short, short_steps, short_rows) = count(&segs[..300]);
    let (long, long_steps, long_rows) = count(&segs);
    let per_row = (long - short) as f64 / (long_rows - short_rows) as f64;
    println!(
        "{short} allocations for {short_steps} steps / {short_rows} rows, {long} for {long_steps} / {long_rows}: {per_row:.2} per extra row"
    );
    assert!(long_steps > 5 * short_steps);
    assert_eq!(long, short, "{per_row} allocations per row");
}

/// With controllers of every kind: the right-hand side, the Jacobian, the switching functions and
/// a switch allocate nothing.
#[test]
fn controllers_and_their_switches_allocate_nothing() {
    use geartherm::scene::{Inputs, Scene};
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("models/fzg_c.toml")).unwrap();
    let extra = r#"
[[thermal.coolers]]
name = "fan_cooler"
hot = "oil"
cold = "ambient"
effectiveness = 0.5
capacity_rate_w_per_k = 40.0
[[thermal.controls]]
name = "bypass"
kind = "valve"
sensor = "oil"
closed_c = 20.0
open_c = 60.0
min_share = 0.1
cooler = "fan_cooler"
[[thermal.controls]]
name = "fan"
kind = "two_point"
sensor = "oil"
on_c = 60.0
off_c = 55.0
link = "housing-air"
off_fraction = 0.3
[[thermal.controls]]
name = "heater"
kind = "two_point"
sensor = "oil"
on_c = 20.0
off_c = 30.0
heater_w = 300.0
[[thermal.coolers]]
name = "pi_cooler"
hot = "oil"
cold = "ambient"
effectiveness = 0.5
capacity_rate_w_per_k = 40.0
[[thermal.controls]]
name = "pi"
kind = "pi_valve"
sensor = "oil"
set_c = 60.0
gain_per_k = 0.05
integral_time_s = 100.0
cooler = "pi_cooler"
"#;
    let gb = model::from_str(&format!("{text}\n{extra}"), std::path::Path::new("m.toml")).unwrap();
    let scene = Scene::compile(&gb).unwrap();
    assert_eq!(scene.thermal().controls.len(), 4);
    assert!(scene.thermal().integral_row(3).is_some());
    let inputs = Inputs {
        state: 0,
        input_speed: 250.0,
        input_torque: 150.0,
        vehicle_speed: 0.0,
    };
    let mut work = scene.work(inputs);
    let mut y = scene.initial_state(None);
    let mut dy = vec![0.0; y.len()];
    let mut jac = vec![0.0; scene.jacobian_pattern().len()];
    let mut g = vec![0.0; scene.switching_count()];
    let (mut v, mut jv) = (vec![0.0; y.len()], vec![0.0; y.len()]);
    let before = allocs();
    for k in 0..20 {
        y[scene.thermal().oil] += 3.0; // through the valve's band and the set points
        v[k % y.len()] = 1.0;
        scene.jvp(k as f64, &y, &v, &mut work, &mut jv);
        scene.rhs(k as f64, &y, &mut work, &mut dy);
        scene.jacobian_values(k as f64, &y, &mut work, &mut jac);
        scene.switching_functions(&y, &work, &mut g);
        scene.settle_controls(&y, &mut work);
    }
    let after = allocs();
    assert_eq!(after - before, 0, "rhs/Jacobian/switches allocated");
    assert!(
        work.net.switches.iter().sum::<usize>() >= 3,
        "{:?}",
        work.net.switches
    );
    assert!(dy.iter().chain(&jac).all(|x| x.is_finite()));
}

/// An FMU instance at 0.01 s communication steps: reading every output (one `fmi2GetReal` of
/// all, the loss model evaluated at the point) allocates nothing, and neither does a doStep
/// that stays inside a ROS3 step already taken (the state interpolated there).
#[test]
fn fmu_output_reads_and_interpolating_do_steps_allocate_nothing() {
    use geartherm::job::fmu::instance::Instance;
    use geartherm::job::fmu::{Causality, FmuModel, Payload, Role};
    use std::sync::Arc;
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("models/at6_lepelletier.toml");
    let fm = Arc::new(
        FmuModel::build(Payload {
            file: file.display().to_string(),
            text: std::fs::read_to_string(&file).unwrap(),
            overrides: vec![],
            params: vec![],
        })
        .unwrap(),
    );
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let outputs: Vec<u32> = (fm.vars.iter())
        .filter(|v| v.causality == Causality::Output)
        .map(|v| v.vr)
        .collect();
    let mut out = vec![0.0; outputs.len()];
    let mut i = Instance::new(fm.clone());
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    let (mut reads, mut quiet_steps, mut interpolated, mut t) = (0, 0, 0, 0.0);
    for k in 0..6 {
        i.set(vr(Role::Gear), (1 + k % 2) as f64).unwrap();
        i.set(vr(Role::InputSpeed), 150.0 + 20.0 * k as f64).unwrap();
        i.set(vr(Role::InputTorque), 60.0 + 15.0 * k as f64).unwrap();
        for _ in 0..100 {
            let steps = i.stepper_stats().unwrap().steps;
            let before = allocs();
            i.do_step(t, 0.01).unwrap();
            let step_allocs = allocs() - before;
            t += 0.01;
            if i.stepper_stats().unwrap().steps == steps {
                interpolated += 1;
                quiet_steps += usize::from(step_allocs == 0);
            }
            let before = allocs();
            i.get_many(&outputs, &mut out).unwrap();
            reads += allocs() - before;
        }
    }
    println!("{interpolated} of 600 doSteps inside a step taken, {quiet_steps} of them without allocation");
    assert!(out.iter().all(|x| x.is_finite()));
    assert_eq!(reads, 0, "reading the outputs allocated");
    assert!(interpolated > 400, "{interpolated} doSteps inside a step taken");
    assert_eq!(quiet_steps, interpolated, "an interpolating doStep allocated");
}
