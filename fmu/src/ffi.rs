//! FMI 2.0 types, the component behind an `fmi2Component` and the guard around every call.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use geartherm::job::fmu::instance::{Instance, Message};

pub type Fmi2Status = c_int;
pub const OK: Fmi2Status = 0;
pub const WARNING: Fmi2Status = 1;
pub const DISCARD: Fmi2Status = 2;
pub const ERROR: Fmi2Status = 3;
pub const FATAL: Fmi2Status = 4;

/// `fmi2CallbackLogger` (C-variadic: the message is a printf format; ours has no `%`).
pub type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Fmi2Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct Callbacks {
    pub logger: Option<Logger>,
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, Fmi2Status)>,
    pub component_environment: *mut c_void,
}

/// What an `fmi2Component` points to.
pub struct Component {
    pub inst: Instance,
    pub name: CString,
    pub logger: Option<Logger>,
    pub env: *mut c_void,
}

impl Component {
    /// Send `msg` to the importer's logger with `status`.
    pub fn log(&self, status: Fmi2Status, msg: &str) {
        log_to(self.logger, self.env, &self.name, status, msg);
    }
}

/// Send `msg` to `logger` (nothing without one).
pub fn log_to(logger: Option<Logger>, env: *mut c_void, name: &CStr, status: Fmi2Status, msg: &str) {
    let Some(logger) = logger else { return };
    // No printf directive may reach the logger: '%' is written as "pct".
    let clean: String = msg.replace('%', " pct").replace('\0', " ");
    let (Ok(text), Ok(cat)) = (CString::new(clean), CString::new(category(status))) else {
        return;
    };
    // SAFETY: the importer's logger with valid C strings.
    unsafe { logger(env, name.as_ptr(), status, cat.as_ptr(), text.as_ptr()) };
}

fn category(status: Fmi2Status) -> &'static str {
    match status {
        OK => "logAll",
        WARNING => "logStatusWarning",
        DISCARD => "logStatusDiscard",
        ERROR => "logStatusError",
        _ => "logStatusFatal",
    }
}

/// Run `f` on the component `c` (null: error), its `Err` logged as an error, a panic as fatal.
pub fn with(c: *mut c_void, f: impl FnOnce(&mut Component) -> Result<(), Message>) -> Fmi2Status {
    if c.is_null() {
        return ERROR;
    }
    // SAFETY: `c` came from fmi2Instantiate (Box<Component>) and was not freed (FMI's contract).
    let comp = unsafe { &mut *(c as *mut Component) };
    match catch_unwind(AssertUnwindSafe(|| f(comp))) {
        Ok(Ok(())) => OK,
        Ok(Err(m)) => {
            comp.log(ERROR, &m);
            ERROR
        }
        Err(p) => {
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            comp.log(FATAL, &format!("internal error (a bug): {what}"));
            FATAL
        }
    }
}

/// Catch a panic of an entry point without a component.
pub fn guarded<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// A C string argument (null: empty).
pub fn c_str(p: *const c_char) -> String {
    if p.is_null() {
        return String::new();
    }
    // SAFETY: a NUL-terminated string from the importer.
    unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
}

/// The `n` value references at `vr` (empty when n = 0 or null).
pub fn refs<'a>(vr: *const u32, n: usize) -> &'a [u32] {
    if vr.is_null() || n == 0 {
        return &[];
    }
    // SAFETY: the importer passes n value references.
    unsafe { std::slice::from_raw_parts(vr, n) }
}
