//! Criterion bench of an exported FMU through its C API: the AT6 over the WLTC co-simulated at
//! communication steps of 1 s and 0.01 s by calling the runtime library's `fmi2…` functions, as
//! an importer does, against `geartherm run`'s integration of the same model
//! (`job::run::solve`: integration and outputs, after the model is read).
//!
//! The runtime library is the one `cargo build --release` builds (`target/release/
//! libgeartherm_fmu.so`, beside this bench's `deps/` directory; `$GEARTHERM_FMU_RUNTIME` names
//! another): build it first. The bench writes the AT6 into a copy's model slot, as `geartherm
//! fmu` does, and loads the copy with `dlopen`.
//!
//! The importer's side (the inputs, boundary values and derivatives at every communication
//! point, from the run's segments: inputs held over each 1 s sample, ambient and coolant as
//! lines) is computed before the clock starts. Each iteration instantiates, initialises,
//! steps through the cycle and frees an instance. Outputs (node temperatures and total loss) are
//! read once per 1 s sample (`fmu/cosim_*`), and at every communication point as well in the
//! `_read_` benches: the node temperatures and total loss (`read_every_step`), the temperatures
//! and loss energies, which need no loss evaluation (`read_temperatures_energies`), every output
//! variable (`read_all_outputs`, what FMPy's `simulate_fmu` records).
//!
//! `cargo build --release && cargo bench --bench fmu -- --warm-up-time 1 --measurement-time 4`

use std::ffi::{c_char, c_int, c_void, CString};
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};

use geartherm::job::fmu::{slot, Causality, FmuModel, Payload, Role};
use geartherm::job::{run, Model, RunOptions};
use geartherm::scene::Inputs;

#[path = "../examples/common/fmu_plan.rs"]
mod fmu_plan;
use fmu_plan::{plan, Point};

const AT6: &str = "models/at6_lepelletier.toml";

type Instantiate = unsafe extern "C" fn(
    *const c_char,
    c_int,
    *const c_char,
    *const c_char,
    *const [*mut c_void; 5],
    c_int,
    c_int,
) -> *mut c_void;
type Component = unsafe extern "C" fn(*mut c_void) -> c_int;
type SetupExperiment = unsafe extern "C" fn(*mut c_void, c_int, f64, f64, c_int, f64) -> c_int;
type SetReal = unsafe extern "C" fn(*mut c_void, *const u32, usize, *const f64) -> c_int;
type SetInteger = unsafe extern "C" fn(*mut c_void, *const u32, usize, *const c_int) -> c_int;
type SetDerivatives = unsafe extern "C" fn(*mut c_void, *const u32, usize, *const c_int, *const f64) -> c_int;
type GetReal = unsafe extern "C" fn(*mut c_void, *const u32, usize, *mut f64) -> c_int;
type DoStep = unsafe extern "C" fn(*mut c_void, f64, f64, c_int) -> c_int;
type Free = unsafe extern "C" fn(*mut c_void);

/// The FMI functions of a loaded runtime library.
struct Api {
    instantiate: Instantiate,
    setup: SetupExperiment,
    enter: Component,
    exit: Component,
    set_real: SetReal,
    set_integer: SetInteger,
    set_derivatives: SetDerivatives,
    get_real: GetReal,
    do_step: DoStep,
    free: Free,
    guid: CString,
}

/// `name` in the library `lib` (a `dlopen` handle).
fn symbol<T: Copy>(lib: *mut c_void, name: &str) -> T {
    let c = CString::new(name).unwrap();
    // SAFETY: a handle from dlopen and a NUL-terminated name.
    let p = unsafe { libc::dlsym(lib, c.as_ptr()) };
    assert!(!p.is_null(), "{name} not exported");
    assert_eq!(std::mem::size_of::<T>(), std::mem::size_of::<*mut c_void>());
    // SAFETY: the symbol is the FMI 2.0 function of that name, with the signature T.
    unsafe { std::mem::transmute_copy(&p) }
}

/// The runtime library built by cargo (or `$GEARTHERM_FMU_RUNTIME`).
fn runtime() -> PathBuf {
    if let Some(p) = std::env::var_os("GEARTHERM_FMU_RUNTIME") {
        return PathBuf::from(p);
    }
    let exe = std::env::current_exe().unwrap();
    let release = exe.parent().and_then(Path::parent).unwrap();
    release.join("libgeartherm_fmu.so")
}

/// The runtime with the AT6 in its slot, written to `dir` and loaded.
fn load(dir: &Path, payload: &Payload) -> Api {
    let rt = runtime();
    let lib = std::fs::read(&rt).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (build the FMU runtime first: cargo build --release)",
            rt.display()
        )
    });
    let bytes = serde_json::to_vec(payload).unwrap();
    let path = dir.join("at6.so");
    std::fs::write(&path, slot::patch(&lib, &bytes).unwrap()).unwrap();
    let c = CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: loading a library we just wrote.
    let h = unsafe { libc::dlopen(c.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    assert!(!h.is_null(), "dlopen {}", path.display());
    Api {
        instantiate: symbol(h, "fmi2Instantiate"),
        setup: symbol(h, "fmi2SetupExperiment"),
        enter: symbol(h, "fmi2EnterInitializationMode"),
        exit: symbol(h, "fmi2ExitInitializationMode"),
        set_real: symbol(h, "fmi2SetReal"),
        set_integer: symbol(h, "fmi2SetInteger"),
        set_derivatives: symbol(h, "fmi2SetRealInputDerivatives"),
        get_real: symbol(h, "fmi2GetReal"),
        do_step: symbol(h, "fmi2DoStep"),
        free: symbol(h, "fmi2FreeInstance"),
        guid: CString::new(slot::guid(&bytes)).unwrap(),
    }
}

/// Value references of the variables the importer uses.
struct Refs {
    held: [u32; 3],
    gear: u32,
    boundaries: Vec<u32>,
    /// The node temperatures and the total loss.
    outputs: Vec<u32>,
    /// The node temperatures and the loss energy per source and total (no loss power).
    state_outputs: Vec<u32>,
    /// Every output variable (what FMPy's `simulate_fmu` records).
    all_outputs: Vec<u32>,
}

fn refs(fm: &FmuModel) -> Refs {
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).unwrap().vr;
    Refs {
        held: [
            vr(Role::InputSpeed),
            vr(Role::InputTorque),
            vr(Role::VehicleSpeed),
        ],
        gear: vr(Role::Gear),
        boundaries: (0..fm.scene.thermal().boundary_names.len())
            .map(|b| vr(Role::Boundary(b)))
            .collect(),
        outputs: (0..fm.scene.nodes())
            .map(|n| vr(Role::NodeTemp(n)))
            .chain([vr(Role::TotalLoss)])
            .collect(),
        state_outputs: fm
            .vars
            .iter()
            .filter(|v| {
                matches!(
                    v.role,
                    Role::NodeTemp(_) | Role::SourceEnergy(_) | Role::TotalEnergy
                )
            })
            .map(|v| v.vr)
            .collect(),
        all_outputs: fm
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| v.vr)
            .collect(),
    }
}

/// One WLTC co-simulation through the C API; the outputs `every` read at every point, when
/// given, and `r.outputs` once per sample. Returns the sum of the last outputs (kept from the
/// optimiser).
fn cosim(api: &Api, r: &Refs, plan: &[(Inputs, Vec<Point>)], every: Option<&[u32]>) -> f64 {
    let name = c"bench";
    let callbacks = [std::ptr::null_mut::<c_void>(); 5];
    let mut out = vec![0.0; r.all_outputs.len()];
    let orders: Vec<c_int> = vec![1; r.boundaries.len()];
    // SAFETY: the FMI 2.0 calling sequence on an instance of this library, with arrays of the
    // lengths passed.
    unsafe {
        let c = (api.instantiate)(
            name.as_ptr(),
            1,
            api.guid.as_ptr(),
            std::ptr::null(),
            &callbacks,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!((api.setup)(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!((api.enter)(c), 0);
        assert_eq!((api.exit)(c), 0);
        for (i, points) in plan {
            let held = [i.input_speed, i.input_torque, i.vehicle_speed];
            assert_eq!((api.set_real)(c, r.held.as_ptr(), 3, held.as_ptr()), 0);
            let gear = i.state as c_int;
            assert_eq!((api.set_integer)(c, &r.gear, 1, &gear), 0);
            let nb = r.boundaries.len();
            for (a, b, x, d) in points {
                assert_eq!((api.set_real)(c, r.boundaries.as_ptr(), nb, x.as_ptr()), 0);
                let s = (api.set_derivatives)(c, r.boundaries.as_ptr(), nb, orders.as_ptr(), d.as_ptr());
                assert_eq!(s, 0);
                assert_eq!((api.do_step)(c, *a, b - a, 1), 0);
                if let Some(vrs) = every {
                    (api.get_real)(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr());
                }
            }
            (api.get_real)(c, r.outputs.as_ptr(), r.outputs.len(), out.as_mut_ptr());
        }
        (api.free)(c);
    }
    out.iter().sum()
}

fn benches(c: &mut Criterion) {
    let m = Model::load(Path::new(AT6), &[]).unwrap();
    let p = run::prepare(&m, &RunOptions::default()).unwrap();
    let payload = Payload {
        file: AT6.into(),
        text: std::fs::read_to_string(AT6).unwrap(),
        overrides: vec![],
        params: vec![],
    };
    let fm = FmuModel::build(payload.clone()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let api = load(dir.path(), &payload);
    let r = refs(&fm);
    let mut g = c.benchmark_group("fmu");
    g.sample_size(10);
    g.bench_function("run_wltc", |b| {
        b.iter(|| run::solve(&m, &p, &mut |_, _| {}).unwrap())
    });
    let coarse = plan(&p, 1.0);
    let fine = plan(&p, 0.01);
    g.bench_function("cosim_1s", |b| b.iter(|| cosim(&api, &r, &coarse, None)));
    g.bench_function("cosim_0.01s", |b| b.iter(|| cosim(&api, &r, &fine, None)));
    g.bench_function("cosim_0.01s_read_every_step", |b| {
        b.iter(|| cosim(&api, &r, &fine, Some(&r.outputs)))
    });
    g.bench_function("cosim_0.01s_read_temperatures_energies", |b| {
        b.iter(|| cosim(&api, &r, &fine, Some(&r.state_outputs)))
    });
    g.bench_function("cosim_0.01s_read_all_outputs", |b| {
        b.iter(|| cosim(&api, &r, &fine, Some(&r.all_outputs)))
    });
    g.finish();
    let steps = |pl: &[(Inputs, Vec<Point>)]| pl.iter().map(|(_, p)| p.len()).sum::<usize>();
    println!(
        "doSteps per WLTC: {} at 1 s, {} at 0.01 s (divide the medians by these for the time per doStep)",
        steps(&coarse),
        steps(&fine)
    );
}

criterion_group!(fmu, benches);
criterion_main!(fmu);
