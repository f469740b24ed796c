//! The `fmi2…` entry points (FMI 2.0, co-simulation). Model exchange, FMU states and
//! directional derivatives are not provided: those calls return `fmi2Error` with a message.

use std::ffi::{c_char, c_int, c_void, CString};

use geartherm::job::fmu::instance::Instance;

use crate::ffi::{c_str, guarded, log_to, refs, with, Callbacks, Component, Fmi2Status, DISCARD, ERROR, OK};

const FMI2_COSIMULATION: c_int = 1;

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    name: *const c_char,
    kind: c_int,
    guid: *const c_char,
    _resources: *const c_char,
    functions: *const Callbacks,
    _visible: c_int,
    _logging_on: c_int,
) -> *mut c_void {
    guarded(std::ptr::null_mut(), || {
        // SAFETY: the importer's callback structure (or null).
        let (logger, env) = unsafe { functions.as_ref() }.map_or((None, std::ptr::null_mut()), |f| {
            (f.logger, f.component_environment)
        });
        let name = CString::new(c_str(name)).unwrap_or_default();
        let fail = |m: &str| {
            log_to(logger, env, &name, ERROR, m);
            std::ptr::null_mut()
        };
        if kind != FMI2_COSIMULATION {
            return fail("this FMU is co-simulation only (no model exchange)");
        }
        let (fm, own_guid) = match crate::model() {
            Ok(m) => m,
            Err(e) => return fail(&e),
        };
        let given = c_str(guid);
        if given != own_guid {
            return fail(&format!("GUID {given} does not match this FMU's {own_guid}"));
        }
        let comp = Component {
            inst: Instance::new(fm),
            name,
            logger,
            env,
        };
        Box::into_raw(Box::new(comp)) as *mut c_void
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if c.is_null() {
        return;
    }
    guarded((), || {
        // SAFETY: `c` came from fmi2Instantiate and is freed once (FMI's contract).
        drop(unsafe { Box::from_raw(c as *mut Component) });
    });
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    _on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> Fmi2Status {
    with(c, |_| Ok(()))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    tolerance_defined: c_int,
    tolerance: f64,
    start: f64,
    _stop_defined: c_int,
    _stop: f64,
) -> Fmi2Status {
    with(c, |comp| {
        comp.inst
            .setup_experiment((tolerance_defined != 0).then_some(tolerance), start)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| comp.inst.enter_initialization())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| comp.inst.exit_initialization())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        comp.inst.terminate();
        Ok(())
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Fmi2Status {
    with(c, |comp| {
        comp.inst.reset();
        Ok(())
    })
}

/// Get `n` values through `get` into `out`.
fn get_values<T>(c: *mut c_void, vr: *const u32, n: usize, out: *mut T, conv: fn(f64) -> T) -> Fmi2Status {
    with(c, |comp| {
        let refs = refs(vr, n);
        if n > 0 && out.is_null() {
            return Err("null value array".into());
        }
        for (i, &r) in refs.iter().enumerate() {
            let v = comp.inst.get(r)?;
            // SAFETY: the importer passes room for n values.
            unsafe { *out.add(i) = conv(v) };
        }
        Ok(())
    })
}

/// Set `n` values from `vals` (converted to f64).
fn set_values<T: Copy>(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    vals: *const T,
    conv: fn(T) -> f64,
) -> Fmi2Status {
    with(c, |comp| {
        let refs = refs(vr, n);
        if n > 0 && vals.is_null() {
            return Err("null value array".into());
        }
        for (i, &r) in refs.iter().enumerate() {
            // SAFETY: the importer passes n values.
            let v = conv(unsafe { *vals.add(i) });
            comp.inst.set(r, v)?;
        }
        Ok(())
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(c: *mut c_void, vr: *const u32, n: usize, out: *mut f64) -> Fmi2Status {
    with(c, |comp| {
        let refs = refs(vr, n);
        if refs.is_empty() {
            return Ok(());
        }
        if out.is_null() {
            return Err("null value array".into());
        }
        // SAFETY: the importer passes room for n values.
        let out = unsafe { std::slice::from_raw_parts_mut(out, refs.len()) };
        comp.inst.get_many(refs, out)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    out: *mut c_int,
) -> Fmi2Status {
    get_values(c, vr, n, out, |v| v as c_int)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    vals: *const f64,
) -> Fmi2Status {
    set_values(c, vr, n, vals, |v| v)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    vals: *const c_int,
) -> Fmi2Status {
    set_values(c, vr, n, vals, f64::from)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: *mut c_void,
    _vr: *const u32,
    n: usize,
    _out: *mut c_int,
) -> Fmi2Status {
    no_variables(c, n, "Boolean")
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    _vr: *const u32,
    n: usize,
    _v: *const c_int,
) -> Fmi2Status {
    no_variables(c, n, "Boolean")
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    _vr: *const u32,
    n: usize,
    _out: *mut *const c_char,
) -> Fmi2Status {
    no_variables(c, n, "String")
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    _vr: *const u32,
    n: usize,
    _v: *const *const c_char,
) -> Fmi2Status {
    no_variables(c, n, "String")
}

/// The FMU has no variables of this type: n = 0 is fine, anything else an error.
fn no_variables(c: *mut c_void, n: usize, ty: &str) -> Fmi2Status {
    with(c, |_| {
        if n == 0 {
            Ok(())
        } else {
            Err(format!("this FMU has no {ty} variables"))
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    order: *const c_int,
    vals: *const f64,
) -> Fmi2Status {
    with(c, |comp| {
        let refs = refs(vr, n);
        if n > 0 && (vals.is_null() || order.is_null()) {
            return Err("null array".into());
        }
        for (i, &r) in refs.iter().enumerate() {
            // SAFETY: the importer passes n orders and values.
            let (o, v) = unsafe { (*order.add(i), *vals.add(i)) };
            comp.inst.set_derivative(r, o, v)?;
        }
        Ok(())
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _out: *mut f64,
) -> Fmi2Status {
    with(c, |_| {
        Err("output derivatives are not provided (maxOutputDerivativeOrder = 0)".into())
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    t: f64,
    h: f64,
    _no_set_state_prior: c_int,
) -> Fmi2Status {
    with(c, |comp| comp.inst.do_step(t, h))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Fmi2Status {
    with(c, |_| {
        Err("doStep always completes: there is nothing to cancel".into())
    })
}

/// `fmi2StatusKind`: fmi2LastSuccessfulTime = 2, fmi2Terminated = 3.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(c: *mut c_void, _kind: c_int, _out: *mut Fmi2Status) -> Fmi2Status {
    with(c, |_| Err("getStatus: doStep never runs asynchronously".into()))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, out: *mut f64) -> Fmi2Status {
    with(c, |comp| {
        if kind != 2 || out.is_null() {
            return Err("getRealStatus: only fmi2LastSuccessfulTime".into());
        }
        // SAFETY: the importer passes room for one value.
        unsafe { *out = comp.inst.time() };
        Ok(())
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(c: *mut c_void, _kind: c_int, _out: *mut c_int) -> Fmi2Status {
    with(c, |_| Err("getIntegerStatus: no integer status".into()))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: *mut c_void, kind: c_int, out: *mut c_int) -> Fmi2Status {
    let r = with(c, |_| {
        if kind != 3 || out.is_null() {
            return Err("getBooleanStatus: only fmi2Terminated".into());
        }
        // SAFETY: the importer passes room for one value.
        unsafe { *out = 0 };
        Ok(())
    });
    if r == OK {
        OK
    } else {
        DISCARD.max(r)
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    _kind: c_int,
    _out: *mut *const c_char,
) -> Fmi2Status {
    with(c, |_| Err("getStringStatus: no string status".into()))
}

macro_rules! not_provided {
    ($name:ident, $what:literal, ($($arg:ident : $ty:ty),*)) => {
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: *mut c_void, $($arg: $ty),*) -> Fmi2Status {
            $(let _ = $arg;)*
            with(c, |_| Err(concat!($what, " is not provided by this FMU").into()))
        }
    };
}

not_provided!(fmi2GetFMUstate, "getFMUstate", (s: *mut *mut c_void));
not_provided!(fmi2SetFMUstate, "setFMUstate", (s: *mut c_void));
not_provided!(fmi2FreeFMUstate, "freeFMUstate", (s: *mut *mut c_void));
not_provided!(fmi2SerializedFMUstateSize, "serializedFMUstateSize", (s: *mut c_void, size: *mut usize));
not_provided!(fmi2SerializeFMUstate, "serializeFMUstate", (s: *mut c_void, b: *mut u8, size: usize));
not_provided!(fmi2DeSerializeFMUstate, "deSerializeFMUstate", (b: *const u8, size: usize, s: *mut *mut c_void));
not_provided!(
    fmi2GetDirectionalDerivative,
    "getDirectionalDerivative",
    (u: *const u32, nu: usize, z: *const u32, nz: usize, dv: *const f64, df: *mut f64)
);
