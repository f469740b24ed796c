//! Evaluating all losses of a gearbox at an operating point allocates nothing (counting allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use geartherm::model;
use geartherm::scene::{LossScene, OperatingPoint};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
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
        let before = ALLOCS.load(Ordering::SeqCst);
        for op in &ops {
            scene.evaluate(op, &mut out);
        }
        let after = ALLOCS.load(Ordering::SeqCst);
        assert_eq!(after - before, 0, "{m}: evaluation allocated");
        assert!(out.iter().all(|w| w.is_finite() && *w >= 0.0), "{m}: {out:?}");
    }
}
