//! The acceptance set of docs/validation.md: every FZG pair GEARpie carries (C14, C40, S30, H501,
//! H701, H951) with one of the FZG group's tested oils named and nothing else set (every default,
//! the oil's own lubricant factor), against GEARpie's sliding loss at 40 / 80 / 90 °C, K5–K9,
//! motor 1000–3000 rpm (`validation/gearpie_*_tested_oils`, peer figures with repository, commit
//! and inputs in each reference.csv): within 5 % at every point.

use std::path::Path;

use geartherm::reference::{run_case, Case};

#[test]
fn every_fzg_pair_with_every_tested_oil_is_within_5_percent_of_gearpie() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("validation");
    let mut worst = (0.0_f64, String::new());
    let mut n = 0;
    for pair in ["c14", "c40", "s30", "h501", "h701", "h951"] {
        let case = Case::load(&root.join(format!("gearpie_{pair}_tested_oils"))).unwrap();
        let oils = case.oils();
        for o in ["m100", "m320", "e320", "g320", "p150", "p320", "prp"] {
            assert!(oils.contains(&Some(o.to_string())), "{pair}: {o}");
        }
        let rows = run_case(&case).unwrap();
        assert_eq!(rows.len(), 315, "{pair}");
        for r in rows {
            assert_eq!(r.model, "default");
            if r.relative_error.abs() > worst.0 {
                worst = (r.relative_error.abs(), format!("{pair} {}", r.point));
            }
            n += 1;
        }
    }
    assert_eq!(n, 6 * 315);
    assert!(worst.0 < 0.05, "worst {:.3} % at {}", 100.0 * worst.0, worst.1);
}
