//! [`SlidingMesh::new`], remembered across compiles: the contact-path tables (most of a sliding
//! compile's time) depend on the mesh's geometry and the options but not on the friction law,
//! so a mesh compiled again with another law (the model-form spread's alternatives, a study
//! varying the law) reuses them ([`SlidingMesh::with_friction`]). A pure function's results: a
//! remembered mesh is the one the computation gives, bit for bit; the last [`SLIDING_MEMO`]
//! distinct inputs are kept.

use std::sync::Mutex;

use crate::physics::losses::sliding::friction::FrictionLaw;
use crate::physics::losses::sliding::{SlidingError, SlidingMesh, SlidingMeshInput, SlidingOptions};

/// Most sliding meshes kept.
const SLIDING_MEMO: usize = 32;

type Memo = Vec<(SlidingMeshInput, SlidingOptions, SlidingMesh)>;

/// [`SlidingMesh::new`] of `input` with `opts`, from a remembered mesh of the same geometry and
/// options but for the friction law when there is one.
pub(super) fn sliding_mesh(
    input: &SlidingMeshInput,
    opts: &SlidingOptions,
) -> Result<SlidingMesh, SlidingError> {
    static MEMO: Mutex<Memo> = Mutex::new(Vec::new());
    let key = SlidingOptions {
        friction: FrictionLaw::Constant(0.0),
        ..*opts
    };
    let found = {
        let memo = MEMO.lock().unwrap_or_else(|e| e.into_inner());
        memo.iter()
            .find(|(i, o, _)| i == input && *o == key)
            .map(|(_, _, m)| m.clone())
    };
    if let Some(m) = found {
        return m.with_friction(opts.friction);
    }
    let m = SlidingMesh::new(input, opts)?;
    let mut memo = MEMO.lock().unwrap_or_else(|e| e.into_inner());
    if memo.len() >= SLIDING_MEMO {
        memo.remove(0);
    }
    memo.push((*input, key, m.clone()));
    Ok(m)
}
