//! K of every external mesh of the bundled models, as the scene builds it (the exact
//! infinitely-many-slices limit of the helical connected-slice model, 8-node Gauss–Legendre per
//! smooth sub-interval), against a high-resolution reference: the same integrand by adaptive
//! 24-node Gauss–Legendre to 1e-13 on a pocket table whose phase end and gap-kind switches were
//! located with an 8× finer scan. Criterion: within 1e-6 relative. Both sides use the
//! same pocket geometry: the teeth of `physics::geometry::ToothProfile` (involute + generated
//! trochoid root), the pocket model's only tooth outline.

use std::path::PathBuf;

use geartherm::model;
use geartherm::physics::geometry::MeshKind;
use geartherm::physics::losses::pocketing::{
    PocketFamilyKind, PocketMeshInput, PocketTable, PocketingMesh, PocketingOptions,
};

fn inputs(file: &str) -> Vec<(String, PocketMeshInput)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let gb = model::load(&root.join(format!("models/{file}.toml"))).expect("bundled model");
    gb.meshes
        .iter()
        .filter(|m| m.geometry.kind != MeshKind::Internal)
        .map(|m| {
            let (g1, g2) = (&gb.gears[m.gear1].geometry, &gb.gears[m.gear2].geometry);
            let input = PocketMeshInput::from_gears(g1, g2, m.geometry.a_w);
            (m.name.clone(), input)
        })
        .collect()
}

#[test]
fn k_of_every_mesh_is_within_1e_6_of_the_high_resolution_reference() {
    let cd = 0.65;
    let mut checked = 0;
    for file in ["at6_lepelletier", "fzg_c", "helical_stage", "pt6_spur_pair"] {
        for (name, inp) in inputs(file) {
            let built = PocketingMesh::with_options(
                &inp,
                &PocketingOptions {
                    discharge_coefficient: cd,
                    helix_slices: None,
                },
            )
            .expect("pocketing");
            for (i, kind) in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1]
                .into_iter()
                .enumerate()
            {
                let table = PocketTable::reference(&inp, kind).expect("reference table");
                let r1 = 0.5 * inp.module * inp.z1 as f64 / inp.helix_angle.cos();
                let s = inp.helix_angle.tan() / r1;
                let reference = if inp.helix_angle == 0.0 {
                    table.k_spur(cd)
                } else {
                    table.k_helical_continuum_with(cd, s, None).0
                };
                let k = built.k()[i];
                let rel = ((k - reference) / reference).abs();
                assert!(
                    rel < 1e-6,
                    "{file} {name} {kind:?}: {k} vs {reference} ({rel:.2e})"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 12, "{checked} families checked");
}
