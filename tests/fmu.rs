//! FMU export and co-simulation: the stepper and an FMU instance reproduce `geartherm run`'s
//! states at the communication points, bad values set through FMI are errors the instance
//! recovers from by a reset, and bad exports exit 1 or 3 writing nothing.

use std::path::Path;
use std::process::Command;
use std::sync::Arc;

use geartherm::job::fmu::instance::{Instance, Phase};
use geartherm::job::fmu::{self as job_fmu, slot, FmuModel, FmuOptions, Payload, Role};
use geartherm::job::{run, Model, RunOptions};
use geartherm::solve::cosim::Stepper;
use geartherm::solve::transient::integrate;

#[path = "common/wall.rs"]
mod wall;

const AT6: &str = "models/at6_lepelletier.toml";

fn at6() -> (Model, run::Prepared) {
    let m = Model::load(Path::new(AT6), &[]).unwrap();
    let p = run::prepare(&m, &RunOptions::default()).unwrap();
    (m, p)
}

fn fmu_model(params: &[&str]) -> Arc<FmuModel> {
    Arc::new(
        FmuModel::build(Payload {
            file: AT6.into(),
            text: std::fs::read_to_string(AT6).unwrap(),
            overrides: vec![],
            params: params.iter().map(|s| s.to_string()).collect(),
        })
        .unwrap(),
    )
}

#[test]
fn stepper_fed_a_runs_segments_reproduces_its_states() {
    let (_, p) = at6();
    let traj = integrate(&p.scene, &p.segs, &p.opts, &mut |_, _| {}).unwrap();
    let y0 = p.scene.initial_state(p.opts.initial_temp);
    let mut s = Stepper::new(&p.scene, y0, p.segs[0].inputs, p.opts.clone(), p.segs[0].t0).unwrap();
    let mut worst = 0.0f64;
    for (k, seg) in p.segs.iter().enumerate() {
        s.set_inputs(&p.scene, seg.inputs);
        // Outputs read between steps must not change the integration.
        let _ = s.losses(&p.scene);
        s.step(&p.scene, seg.t1).unwrap();
        let row = traj.states.get(k + 1).unwrap();
        for (a, b) in s.state().iter().zip(row) {
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
    }
    println!("stepper vs run, AT6 WLTC: largest difference {worst:.3e} (relative, states)");
    assert!(worst <= 1e-12, "{worst:e}");
}

/// Drive an instance through the run's segments (inputs held, boundaries as lines), return the
/// largest temperature difference (K) and energy-per-source difference (relative).
fn drive_instance(step: f64) -> (f64, f64) {
    let (_, p) = at6();
    drive_model(fmu_model(&[]), &p, step)
}

/// Drive an instance of `fm` through the segments of the run `p` as [`drive_instance`].
fn drive_model(fm: Arc<FmuModel>, p: &run::Prepared, step: f64) -> (f64, f64) {
    let traj = integrate(&p.scene, &p.segs, &p.opts, &mut |_, _| {}).unwrap();
    let mut inst = Instance::new(fm.clone());
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    inst.enter_initialization().unwrap();
    inst.exit_initialization().unwrap();
    let nodes = p.scene.nodes();
    let (mut dt_max, mut de_max) = (0.0f64, 0.0f64);
    for (k, seg) in p.segs.iter().enumerate() {
        let i = seg.inputs;
        inst.set(vr(Role::InputSpeed), i.input_speed).unwrap();
        inst.set(vr(Role::InputTorque), i.input_torque).unwrap();
        inst.set(vr(Role::VehicleSpeed), i.vehicle_speed).unwrap();
        inst.set(vr(Role::Gear), i.state as f64).unwrap();
        let n_sub = ((seg.t1 - seg.t0) / step).round().max(1.0) as usize;
        for j in 0..n_sub {
            let t0 = seg.t0 + (seg.t1 - seg.t0) * j as f64 / n_sub as f64;
            let t1 = seg.t0 + (seg.t1 - seg.t0) * (j + 1) as f64 / n_sub as f64;
            for b in 0..p.scene.thermal().boundary_names.len() {
                let at = |t| p.scene.thermal().boundary_temperature_at(b, t).unwrap();
                inst.set(vr(Role::Boundary(b)), at(t0)).unwrap();
                inst.set_derivative(vr(Role::Boundary(b)), 1, (at(t1) - at(t0)) / (t1 - t0))
                    .unwrap();
            }
            inst.do_step(t0, t1 - t0).unwrap();
        }
        let row = traj.states.get(k + 1).unwrap();
        for (n, t_run) in row.iter().enumerate().take(nodes) {
            dt_max = dt_max.max((inst.get(vr(Role::NodeTemp(n))).unwrap() - t_run).abs());
        }
        let e_run = p.scene.loss_energy_by_source(row);
        for s in geartherm::job::fmu::variables::sources(&fm.scene) {
            let e = inst.get(vr(Role::SourceEnergy(s))).unwrap();
            let r = e_run[s.index()];
            de_max = de_max.max((e - r).abs() / r.abs().max(1e-300));
        }
    }
    (dt_max, de_max)
}

#[test]
fn instance_at_one_second_steps_reproduces_the_run() {
    let (dt, de) = drive_instance(1.0);
    println!(
        "FMU instance vs run, AT6 WLTC, 1 s steps: |dT| ≤ {dt:.3e} K, energy per source ≤ {de:.3e} relative"
    );
    assert!(dt <= 1e-6, "{dt:e} K");
    assert!(de <= 1e-9, "{de:e}");
}

/// Reading the outputs changes nothing: two instances at 0.01 s steps (interpolated inside
/// ROS3's own steps), one read every output after setting each new input torque and before the
/// doStep, the other never; afterwards every output of both is the same to the bit. Also the
/// outputs read at a point are those of a fresh evaluation (the cached parts are refreshed by a
/// doStep and by a set input).
#[test]
fn reading_outputs_between_setting_inputs_and_stepping_changes_nothing() {
    let fm = fmu_model(&[]);
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let outputs: Vec<u32> = (fm.vars.iter())
        .filter(|v| v.causality == job_fmu::Causality::Output)
        .map(|v| v.vr)
        .collect();
    let start = || {
        let mut i = Instance::new(fm.clone());
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.set(vr(Role::InputSpeed), 200.0).unwrap();
        i
    };
    let (mut read, mut quiet) = (start(), start());
    let mut t = 0.0;
    let mut read_losses = Vec::new();
    for k in 0..40 {
        let torque = 50.0 + 10.0 * (k % 4) as f64;
        for i in [&mut read, &mut quiet] {
            i.set(vr(Role::InputTorque), torque).unwrap();
        }
        let all: Vec<f64> = outputs.iter().map(|&v| read.get(v).unwrap()).collect();
        read_losses.push(all[outputs.iter().position(|&v| v == vr(Role::TotalLoss)).unwrap()]);
        for _ in 0..25 {
            read.do_step(t, 0.01).unwrap();
            quiet.do_step(t, 0.01).unwrap();
            t += 0.01;
            read.get(vr(Role::TotalLoss)).unwrap();
        }
    }
    for &v in &outputs {
        let (a, b) = (read.get(v).unwrap(), quiet.get(v).unwrap());
        assert_eq!(a.to_bits(), b.to_bits(), "output {v}: {a} against {b}");
    }
    // The loss read after a new torque is the new torque's: the four torques give four losses.
    assert!(read_losses[1] > read_losses[0] && read_losses[2] > read_losses[1]);
}

#[test]
fn instance_bad_values_are_errors_and_reset_recovers() {
    let fm = fmu_model(&[]);
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let mut inst = Instance::new(fm.clone());
    inst.enter_initialization().unwrap();
    inst.exit_initialization().unwrap();
    let bad: [(Role, f64, &str); 5] = [
        (Role::InputSpeed, f64::NAN, "input_speed = NaN"),
        (Role::InputSpeed, -1.0, "input_speed = -1"),
        (Role::Gear, 7.0, "gear = 7: outside [0, 6]"),
        (Role::Gear, -1.0, "gear = -1"),
        (Role::Boundary(1), f64::INFINITY, "T_boundary.coolant = inf"),
    ];
    for (role, v, msg) in bad {
        let e = inst.set(vr(role), v).unwrap_err();
        assert!(e.contains(msg) && e.contains("t = 0 s"), "{e}");
        assert_eq!(inst.phase(), Phase::Error);
        assert!(inst.do_step(0.0, 1.0).is_err());
        inst.reset();
        inst.enter_initialization().unwrap();
        inst.exit_initialization().unwrap();
        inst.set(vr(Role::InputSpeed), 200.0).unwrap();
        inst.set(vr(Role::InputTorque), 100.0).unwrap();
        inst.do_step(0.0, 1.0).unwrap();
        assert!(inst.get(vr(Role::NodeTemp(0))).unwrap() > 296.15);
        inst.reset();
        inst.enter_initialization().unwrap();
        inst.exit_initialization().unwrap();
    }
    // A communication point that is not the instance's time.
    assert!(inst.do_step(5.0, 1.0).unwrap_err().contains("at t = 0 s"));
}

#[test]
fn parameter_changes_the_model_and_is_checked() {
    let fm = fmu_model(&["lubrication.oil_level_mm"]);
    let p = fm.vars.iter().find(|v| v.role == Role::Param(0)).unwrap();
    assert_eq!(p.name, "param.lubrication.oil_level_mm");
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let churn = |level: f64| {
        let mut i = Instance::new(fm.clone());
        i.set(p.vr, level).unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization()?;
        i.set(vr(Role::InputSpeed), 300.0).unwrap();
        i.set(vr(Role::InputTorque), 100.0).unwrap();
        i.get(vr(Role::TotalLoss))
    };
    let start = p.start.unwrap();
    let (a, b) = (churn(start).unwrap(), churn(start + 20.0).unwrap());
    assert!(b > a, "a higher oil level churns more: {a} W, {b} W");
    let e = churn(1e6).unwrap_err();
    assert!(e.contains("oil_level_mm"), "{e}");
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
}

/// A stand-in runtime library: a file holding an unpatched model slot (the export patches and
/// packages it; it is not loaded here).
fn fake_runtime(dir: &Path) -> std::path::PathBuf {
    let p = dir.join("libfake.so");
    let mut bytes = b"\x7fELF not really".to_vec();
    bytes.extend_from_slice(&slot::unpatched());
    std::fs::write(&p, bytes).unwrap();
    p
}

fn export(dir: &Path, args: &[&str]) -> std::process::Output {
    bin()
        .arg("fmu")
        .args(args)
        .env("GEARTHERM_FMU_RUNTIME", fake_runtime(dir))
        .output()
        .unwrap()
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn cli_export_writes_an_fmu_with_the_model_in_its_slot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("at6.fmu");
    let o = export(
        dir.path(),
        &[
            AT6,
            "--out",
            out.to_str().unwrap(),
            "--param",
            "lubrication.oil_level_mm",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[..4], b"PK\x03\x04");
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("modelDescription.xml") && text.contains("binaries/linux64/at6.so"));
    assert!(text.contains("name=\"param.lubrication.oil_level_mm\""));
    assert_eq!(listing(dir.path()), ["at6.fmu", "libfake.so"]);
}

#[test]
fn cli_bad_exports_exit_1_or_3_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.fmu");
    let out_s = out.to_str().unwrap();
    let cases: [(Vec<&str>, i32, &str); 5] = [
        (
            vec!["tests/invalid/bad_loss_model.toml", "--out", out_s],
            1,
            "bad_loss_model.toml",
        ),
        (
            vec![AT6, "--out", out_s, "--param", "lubrication.no_such_key"],
            1,
            "lubrication.no_such_key",
        ),
        (
            vec![AT6, "--out", out_s, "--param", "oil.catalogue"],
            1,
            "not a number",
        ),
        (
            vec![AT6, "--out", "/nonexistent_dir_38/x.fmu"],
            3,
            "/nonexistent_dir_38",
        ),
        (vec![AT6, "--out", "/proc/x.fmu"], 3, "x.fmu"),
    ];
    for (args, code, named) in cases {
        let o = export(dir.path(), &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(named), "{args:?}: {err}");
        assert_eq!(listing(dir.path()), ["libfake.so"], "{args:?}");
    }
    assert!(!Path::new("/nonexistent_dir_38").exists());
}

#[test]
fn cli_export_without_a_runtime_library_is_an_io_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.fmu");
    let o = bin()
        .args(["fmu", AT6, "--out", out.to_str().unwrap()])
        .env("GEARTHERM_FMU_RUNTIME", dir.path().join("missing.so"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing.so"));
    assert!(listing(dir.path()).is_empty());
}

/// A network larger than the 24 nodes up to which `Method::Auto` picks ROS3 for a run: the AT6
/// with its housing meshed into 30 patches exports, and its instance at 1 s steps reproduces a
/// `geartherm run --solver ros3` of the same model over the WLTC.
#[test]
fn a_thirty_patch_housing_mesh_exports_and_reproduces_a_ros3_run() {
    let text = std::fs::read_to_string(AT6).unwrap() + &wall::mesh_toml(10, 3, Some(0.3), 100.0);
    let o = FmuOptions {
        params: vec![],
        model_identifier: "at6_mesh".into(),
    };
    let export = job_fmu::prepare(&text, AT6, &[], &o).unwrap();
    assert!(export.variables() > 0);
    let fm = Arc::new(
        FmuModel::build(Payload {
            file: AT6.into(),
            text: text.clone(),
            overrides: vec![],
            params: vec![],
        })
        .unwrap(),
    );
    let nodes = fm.scene.nodes();
    assert!(nodes > 30, "{nodes} nodes");
    let m = Model::from_text(&text, Path::new(AT6), &[]).unwrap();
    let ros3 = RunOptions {
        solver: "ros3".into(),
        ..RunOptions::default()
    };
    let p = run::prepare(&m, &ros3).unwrap();
    let (dt, de) = drive_model(fm, &p, 1.0);
    println!(
        "FMU instance vs run --solver ros3, AT6 with a 30-patch housing ({nodes} nodes), WLTC, 1 s steps: |dT| ≤ {dt:.3e} K, energy per source ≤ {de:.3e} relative"
    );
    assert!(dt <= 1e-6, "{dt:e} K");
    assert!(de <= 1e-9, "{de:e}");
}

/// An instance of the AT6 FMU with `param.lubrication.oil_level_mm`, at rtol 1e-8, started at
/// `t0` with `initial` temperatures (None: the model's) and the oil level `level`, at 300 rad/s,
/// 100 N·m, gear index 2.
fn tuned(fm: &Arc<FmuModel>, t0: f64, initial: Option<&[f64]>, level: f64) -> Instance {
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let mut i = Instance::new(fm.clone());
    i.setup_experiment(None, t0).unwrap();
    i.set(vr(Role::Rtol), 1e-8).unwrap();
    i.set(vr(Role::Param(0)), level).unwrap();
    for (n, t) in initial.unwrap_or(&[]).iter().enumerate() {
        i.set(vr(Role::InitialTemp(n)), *t).unwrap();
    }
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.set(vr(Role::InputSpeed), 300.0).unwrap();
    i.set(vr(Role::InputTorque), 100.0).unwrap();
    i.set(vr(Role::Gear), 2.0).unwrap();
    i
}

/// A tunable parameter changed between two steps: the run continues from the state at that
/// point with the new value, as a second instance started there from that state with the new
/// value does (within the integration's tolerance: the two integrators take their own steps);
/// a value the model refuses is an FMI error naming the key path and the time.
#[test]
fn a_tunable_parameter_changed_between_steps_equals_two_segments() {
    let fm = fmu_model(&["lubrication.oil_level_mm"]);
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let nodes = fm.scene.nodes();
    let temps = |i: &mut Instance| -> Vec<f64> {
        (0..nodes)
            .map(|n| i.get(vr(Role::NodeTemp(n))).unwrap())
            .collect()
    };
    let level = fm.params[0].value;
    let (mut a, mut same) = (tuned(&fm, 0.0, None, level), tuned(&fm, 0.0, None, level));
    for k in 0..300 {
        a.do_step(k as f64, 1.0).unwrap();
        same.do_step(k as f64, 1.0).unwrap();
    }
    let at_300 = temps(&mut a);
    let e_300 = a.get(vr(Role::TotalEnergy)).unwrap();
    a.set(vr(Role::Param(0)), level + 20.0).unwrap();
    let mut b = tuned(&fm, 300.0, Some(&at_300), level + 20.0);
    let (mut d_ab, mut d_same) = (0.0f64, 0.0f64);
    for k in 300..900 {
        for i in [&mut a, &mut b, &mut same] {
            i.do_step(k as f64, 1.0).unwrap();
        }
        let (ta, tb, ts) = (temps(&mut a), temps(&mut b), temps(&mut same));
        for n in 0..nodes {
            d_ab = d_ab.max((ta[n] - tb[n]).abs());
            d_same = d_same.max((ta[n] - ts[n]).abs());
        }
    }
    let e_a = a.get(vr(Role::TotalEnergy)).unwrap() - e_300;
    let e_b = b.get(vr(Role::TotalEnergy)).unwrap();
    let de = (e_a - e_b).abs() / e_b;
    println!(
        "oil level {level} -> {} mm at 300 s, 300-900 s: |T(one instance) - T(two segments)| <= {d_ab:.3e} K, \
         loss energy {de:.3e} relative; the change itself moves T by up to {d_same:.3e} K",
        level + 20.0
    );
    assert!(d_same > 1e-2, "the change has no effect: {d_same:e} K");
    assert!(d_ab <= 1e-6, "{d_ab:e} K");
    assert!(de <= 1e-8, "{de:e}");
    let e = a.set(vr(Role::Param(0)), 1e6).unwrap_err();
    assert!(e.contains("oil_level_mm") && e.contains("t = 900 s"), "{e}");
    assert_eq!(a.phase(), Phase::Error);
    a.reset();
    a.enter_initialization().unwrap();
    a.exit_initialization().unwrap();
    a.do_step(0.0, 1.0).unwrap();
}

/// The loss outputs of an instance (evaluated lazily, at most once per communication point,
/// through the stepper's per-sample loss terms, and reused while the inputs and the oil
/// temperature are unchanged) equal a fresh evaluation at the state of the point: to the bit
/// against a new work area's evaluation (per-sample terms prepared anew), within 1e-12 relative
/// against the full evaluation without per-sample terms. Checked at points inside ROS3's steps
/// (interpolated states), right after a gear change (before and after its first doStep), after
/// an input set to another value and back, and after a reset.
#[test]
fn loss_outputs_equal_a_fresh_evaluation_at_the_state_of_the_point() {
    use geartherm::physics::efficiency::efficiency;
    use geartherm::scene::{sum_by_source, Inputs, OperatingPoint};
    let (_, p) = at6();
    let fm = fmu_model(&[]);
    let scene = &fm.scene;
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    let sources = job_fmu::variables::sources(scene);
    let losses: Vec<u32> = (sources.iter().map(|&s| vr(Role::SourceLoss(s))))
        .chain([vr(Role::TotalLoss), vr(Role::Efficiency)])
        .collect();
    let mut checked = 0;
    let mut check = |inst: &mut Instance, i: Inputs| {
        let mut got = vec![0.0; losses.len()];
        let before = inst.loss_evaluations();
        inst.get_many(&losses, &mut got).unwrap();
        inst.get_many(&losses, &mut got).unwrap();
        assert!(inst.loss_evaluations() <= before + 1, "one evaluation per point");
        let mut y = vec![0.0; scene.n_states()];
        for (n, x) in y.iter_mut().enumerate().take(scene.nodes()) {
            *x = inst.get(vr(Role::NodeTemp(n))).unwrap();
        }
        let mut w = scene.work(i);
        scene.evaluate_losses(&y, &mut w);
        let op = OperatingPoint {
            state: i.state,
            input_speed: i.input_speed,
            input_torque: i.input_torque,
            oil: scene.thermal().oil_properties(scene.oil_temp(&y)),
        };
        let mut full = vec![0.0; scene.items()];
        scene.losses().evaluate(&op, &mut full);
        let items = &scene.losses().items;
        let (by, by_full) = (sum_by_source(items, &w.q), sum_by_source(items, &full));
        let total: f64 = w.q.iter().sum();
        let mut want: Vec<(f64, f64)> = (sources.iter())
            .map(|s| (by[s.index()], by_full[s.index()]))
            .collect();
        want.push((total, full.iter().sum()));
        let eta = |p: f64| efficiency(i.input_torque * i.input_speed, p).unwrap_or(0.0);
        want.push((eta(total), eta(full.iter().sum())));
        for ((&g, &(fresh, full)), &v) in got.iter().zip(&want).zip(&losses) {
            assert_eq!(
                g.to_bits(),
                fresh.to_bits(),
                "t = {}: output {v}: {g} against {fresh}",
                inst.time()
            );
            assert!(
                (g - full).abs() <= 1e-12 * full.abs(),
                "output {v}: {g} against {full}"
            );
        }
        assert!(total > 0.0);
        checked += 1;
    };
    let set_inputs = |inst: &mut Instance, i: &Inputs| {
        inst.set(vr(Role::InputSpeed), i.input_speed).unwrap();
        inst.set(vr(Role::InputTorque), i.input_torque).unwrap();
        inst.set(vr(Role::VehicleSpeed), i.vehicle_speed).unwrap();
        inst.set(vr(Role::Gear), i.state as f64).unwrap();
    };
    let bounds = p.scene.thermal().boundary_names.len();
    let mut inst = Instance::new(fm.clone());
    let mut gear_changes = 0;
    for round in 0..2 {
        inst.enter_initialization().unwrap();
        inst.exit_initialization().unwrap();
        // The first segments of the WLTC with running gears, through a gear change.
        for (k, seg) in p.segs.iter().enumerate().take(30) {
            let i = seg.inputs;
            set_inputs(&mut inst, &i);
            let new_gear = k > 0 && p.segs[k - 1].inputs.state != i.state;
            if new_gear && i.input_speed > 0.0 {
                check(&mut inst, i);
                gear_changes += 1;
            }
            for j in 0..100 {
                let t0 = seg.t0 + (seg.t1 - seg.t0) * j as f64 / 100.0;
                let t1 = seg.t0 + (seg.t1 - seg.t0) * (j + 1) as f64 / 100.0;
                for b in 0..bounds {
                    let at = |t| p.scene.thermal().boundary_temperature_at(b, t).unwrap();
                    inst.set(vr(Role::Boundary(b)), at(t0)).unwrap();
                }
                inst.do_step(t0, t1 - t0).unwrap();
                if i.input_speed > 0.0 && (new_gear && j == 0 || j % 37 == 5) {
                    check(&mut inst, i);
                }
            }
            if i.input_speed > 0.0 && i.input_torque != 0.0 {
                // Another torque read and back: evaluated anew at the torque in force.
                inst.set(vr(Role::InputTorque), 2.0 * i.input_torque).unwrap();
                inst.get(vr(Role::TotalLoss)).unwrap();
                inst.set(vr(Role::InputTorque), i.input_torque).unwrap();
                check(&mut inst, i);
                // Another torque not read and back: the evaluation at these inputs and state
                // is reused.
                let evaluations = inst.loss_evaluations();
                inst.set(vr(Role::InputTorque), 2.0 * i.input_torque).unwrap();
                inst.set(vr(Role::InputTorque), i.input_torque).unwrap();
                check(&mut inst, i);
                assert_eq!(inst.loss_evaluations(), evaluations);
            }
        }
        if round == 0 {
            inst.reset();
            assert_eq!(inst.loss_evaluations(), 0);
        }
    }
    println!("loss outputs checked against fresh evaluations at {checked} points, {gear_changes} after gear changes");
    assert!(
        gear_changes >= 2 && checked > 100,
        "{gear_changes} gear changes, {checked} points"
    );
}
