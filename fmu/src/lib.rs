//! The FMI 2.0 co-simulation C API over [`geartherm::job::fmu::instance::Instance`]: the runtime
//! library of an FMU that `geartherm fmu` exports. The model lives in [`MODEL_SLOT`], written by
//! the exporter into a copy of this library (`geartherm::job::fmu::slot`); nothing is read from
//! a file at run time.
//!
//! Every entry point runs inside `catch_unwind`: a panic becomes `fmi2Fatal` and a logged
//! message, never an unwind into the importer. Function signatures: FMI 2.0 standard,
//! `fmi2Functions.h` / `fmi2FunctionTypes.h`.

#![allow(clippy::missing_safety_doc)]

mod api;
mod ffi;

use std::sync::{Arc, OnceLock};

use geartherm::job::fmu::{slot, FmuModel};

/// The model slot (see `geartherm::job::fmu::slot`): patched in the FMU's copy of this library.
#[used]
#[no_mangle]
pub static MODEL_SLOT: [u8; slot::SLOT_LEN] = slot::unpatched();

/// The slot's bytes, read with volatile reads (the compiler must not fold the constant it was
/// built with: the exporter changes them in the file).
fn slot_bytes() -> Vec<u8> {
    let base = MODEL_SLOT.as_ptr();
    // SAFETY: every index is within the static array.
    let read = |i: usize| unsafe { std::ptr::read_volatile(base.add(i)) };
    let header: Vec<u8> = (0..slot::HEADER_LEN).map(read).collect();
    let len = slot::payload_len(&header).unwrap_or(0);
    (0..slot::HEADER_LEN + len).map(read).collect()
}

/// The model (built once per process from the slot) and the GUID of its payload.
fn model() -> Result<(Arc<FmuModel>, String), String> {
    static MODEL: OnceLock<Result<(Arc<FmuModel>, String), String>> = OnceLock::new();
    MODEL
        .get_or_init(|| {
            let bytes = slot_bytes();
            let payload = slot::decode(&bytes)?
                .ok_or("this library holds no model: export one with `geartherm fmu`")?;
            let guid = slot::guid(&bytes[slot::HEADER_LEN..]);
            let fm = FmuModel::build(payload).map_err(|e| e.to_string())?;
            Ok((Arc::new(fm), guid))
        })
        .clone()
}
