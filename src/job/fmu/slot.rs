//! The model slot of the FMU runtime library: a fixed-size byte array in the library's data,
//! [`MAGIC`], then the payload's length (u64, little-endian; [`UNPATCHED`] until the exporter
//! writes one), then the payload (the [`super::Payload`] as JSON). The exporter finds the slot
//! in the library's bytes and writes the payload into a copy; the runtime reads it back
//! ([`decode`]).

use super::Payload;
use crate::job::JobError;

/// Marks the slot (32 bytes).
pub const MAGIC: [u8; 32] = *b"geartherm-fmu-model-slot-v1.....";

/// The length field of a slot no exporter has written.
pub const UNPATCHED: u64 = u64::MAX;

/// Bytes of the whole slot (header and payload).
pub const SLOT_LEN: usize = 1 << 20;

/// Bytes of the header (magic and length).
pub const HEADER_LEN: usize = MAGIC.len() + 8;

/// The slot as the runtime library is built with it: the magic, [`UNPATCHED`], and a non-zero
/// filler (so the array lives in the file, not in zero-initialised memory).
pub const fn unpatched() -> [u8; SLOT_LEN] {
    let mut s = [0xA5u8; SLOT_LEN];
    let mut i = 0;
    while i < MAGIC.len() {
        s[i] = MAGIC[i];
        i += 1;
    }
    let len = UNPATCHED.to_le_bytes();
    let mut k = 0;
    while k < 8 {
        s[MAGIC.len() + k] = len[k];
        k += 1;
    }
    s
}

/// A copy of the runtime library `lib` with `payload` in its slot. Exactly one unpatched slot
/// must be found (else the bytes are not a geartherm FMU runtime: an I/O error); a payload
/// larger than the slot is invalid input.
pub fn patch(lib: &[u8], payload: &[u8]) -> Result<Vec<u8>, JobError> {
    let mut head = MAGIC.to_vec();
    head.extend_from_slice(&UNPATCHED.to_le_bytes());
    let found: Vec<usize> = lib
        .windows(head.len())
        .enumerate()
        .filter(|(_, w)| *w == head.as_slice())
        .map(|(i, _)| i)
        .take(2)
        .collect();
    let at =
        match found.as_slice() {
            [one] => *one,
            [] => return Err(JobError::io(
                "the FMU runtime library has no model slot (not a geartherm-fmu library, or already patched)",
                std::io::ErrorKind::InvalidData,
            )),
            _ => {
                return Err(JobError::io(
                    "the FMU runtime library has more than one model slot",
                    std::io::ErrorKind::InvalidData,
                ))
            }
        };
    check_fits(payload)?;
    if at + SLOT_LEN > lib.len() {
        return Err(JobError::io(
            "the FMU runtime library ends inside its model slot",
            std::io::ErrorKind::InvalidData,
        ));
    }
    let mut out = lib.to_vec();
    let len_at = at + MAGIC.len();
    out[len_at..len_at + 8].copy_from_slice(&(payload.len() as u64).to_le_bytes());
    out[at + HEADER_LEN..at + HEADER_LEN + payload.len()].copy_from_slice(payload);
    Ok(out)
}

/// A payload larger than the slot is invalid input.
pub fn check_fits(payload: &[u8]) -> Result<(), JobError> {
    let room = SLOT_LEN - HEADER_LEN;
    if payload.len() > room {
        return Err(JobError::invalid(format!(
            "the model and its overrides take {} bytes; an FMU holds at most {room}",
            payload.len()
        )));
    }
    Ok(())
}

/// The payload in a slot's bytes (at least the header; the runtime copies the slot out of its
/// data with volatile reads first). None: the slot was never written.
pub fn decode(slot: &[u8]) -> Result<Option<Payload>, String> {
    if slot.len() < HEADER_LEN || slot[..MAGIC.len()] != MAGIC {
        return Err("the model slot is damaged (no magic)".into());
    }
    let mut len = [0u8; 8];
    len.copy_from_slice(&slot[MAGIC.len()..HEADER_LEN]);
    let len = u64::from_le_bytes(len);
    if len == UNPATCHED {
        return Ok(None);
    }
    let end = usize::try_from(len)
        .ok()
        .and_then(|l| l.checked_add(HEADER_LEN))
        .filter(|&e| e <= slot.len())
        .ok_or("the model slot is damaged (length)")?;
    serde_json::from_slice(&slot[HEADER_LEN..end])
        .map(Some)
        .map_err(|e| format!("the model slot is damaged: {e}"))
}

/// Length of a written slot's payload (None: unpatched or damaged), from its header.
pub fn payload_len(header: &[u8]) -> Option<usize> {
    if header.len() < HEADER_LEN || header[..MAGIC.len()] != MAGIC {
        return None;
    }
    let mut len = [0u8; 8];
    len.copy_from_slice(&header[MAGIC.len()..HEADER_LEN]);
    let len = u64::from_le_bytes(len);
    (len != UNPATCHED)
        .then_some(len)
        .and_then(|l| usize::try_from(l).ok())
        .filter(|&l| l <= SLOT_LEN - HEADER_LEN)
}

/// An FMI GUID from the payload: two FNV-1a hashes (64-bit, different offsets) as
/// `{8-4-4-4-12}` hex digits. The runtime compares it with the GUID an importer passes.
pub fn guid(payload: &[u8]) -> String {
    let fnv = |seed: u64| {
        payload.iter().fold(seed, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })
    };
    let (a, b) = (fnv(0xcbf2_9ce4_8422_2325), fnv(0x6c62_272e_07bb_0142));
    let hex = format!("{a:016x}{b:016x}");
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &hex[..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..]
    )
}
