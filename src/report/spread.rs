//! The model-form spread block of `losses`, `steady` and a run's summary: every applicable
//! model's value of each loss item (or each source's energy), and its text lines
//! (docs/uq.md, "Model-form spread").

use std::fmt::Write as _;

use serde::Serialize;

use crate::scene::{ItemSpread, SourceSpread};

/// The spread at one operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpreadBlock {
    /// Every loss item with every applicable model of its source.
    pub items: Vec<ItemSpread>,
    /// One line per item the job warns about (its applicable models disagree by more than a
    /// factor 3 and the choice moves the point's total loss; `job::spread`).
    pub warnings: Vec<String>,
}

impl SpreadBlock {
    /// The block of `items` with the job's disagreement `warnings`.
    pub fn new(items: Vec<ItemSpread>, warnings: Vec<String>) -> SpreadBlock {
        SpreadBlock { items, warnings }
    }

    /// Text lines: each item with more than one model choice, its default, minimum, maximum
    /// and every model's value (`*` the default, `!` outside a validity range, `n/a` not
    /// applicable, with why).
    pub fn to_text(&self) -> String {
        let mut s = String::from(
            "\nmodel-form spread (the applicable published models, not a probability; docs/uq.md):\n",
        );
        let mut any = false;
        for it in self.items.iter().filter(|it| it.models.len() > 1) {
            any = true;
            let _ = writeln!(
                s,
                "  {:<10} {:<24} default {:>10.3} W  min {:>10.3}  max {:>10.3}  {}",
                it.source.as_str(),
                it.name,
                it.default_w,
                it.min_w,
                it.max_w,
                it.factor.map_or("×∞".into(), |f| format!("×{f:.1}"))
            );
            for m in &it.models {
                let mark = if m.default { "*" } else { " " };
                match (m.w, &m.not_applicable) {
                    (Some(w), _) => {
                        let out = if m.outside.is_empty() {
                            String::new()
                        } else {
                            format!("  ! {}", m.outside.join("; "))
                        };
                        let _ = writeln!(s, "      {mark}{:<22} {w:>12.3} W{out}", m.label);
                    }
                    (None, why) => {
                        let _ = writeln!(
                            s,
                            "      {mark}{:<22} {:>12}   {}",
                            m.label,
                            "n/a",
                            why.as_deref().unwrap_or("")
                        );
                    }
                }
            }
        }
        if !any {
            s.push_str("  every item's source has one model\n");
        }
        s
    }
}

/// Text lines of a run's per-source energy spread.
pub fn energies_text(spread: &[SourceSpread]) -> String {
    let mut s = String::from("model-form spread of the energy per source along the run's trajectory, kJ:\n");
    for e in spread {
        let _ = write!(
            s,
            "  {:<10} default {:.1}, min {:.1}, max {:.1}:",
            e.source.as_str(),
            e.default_j / 1e3,
            e.min_j / 1e3,
            e.max_j / 1e3
        );
        for m in &e.models {
            let v = m.j.map_or("n/a".into(), |j| format!("{:.1}", j / 1e3));
            let _ = write!(s, " {}{} {v};", if m.default { "*" } else { "" }, m.label);
        }
        s.push('\n');
    }
    s
}
