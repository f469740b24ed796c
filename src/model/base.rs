//! A base model document read once and reused by many variants of it (the cases of a study):
//! a variant that overrides a few key paths reads anew only the top-level sections those paths
//! fall in and keeps the base's typed reading of every other section, and the base's solved
//! gear train and gear states when no path falls in the sections they are solved from.

use std::path::Path;

use toml::Table;

use super::file::{ModelFile, SECTIONS};
use super::overrides::{self, Step};
use super::problems::Problems;
use super::{annotate, from_document_with, parse, validate, Gearbox, ModelError, Override};

/// A parsed model document and, when it reads without a problem, its typed reading.
#[derive(Debug, Clone)]
pub struct BaseDocument {
    doc: Table,
    file: Option<ModelFile>,
    /// The file's solved gear train and gear states (None: its structure has a problem).
    kinematics: Option<validate::Kinematics>,
}

impl BaseDocument {
    /// Read `doc`'s sections once.
    pub fn new(doc: Table) -> BaseDocument {
        let mut problems = Problems::default();
        let file = parse::parse_table(doc.clone(), &mut problems).filter(|_| problems.is_empty());
        let kinematics = file.as_ref().and_then(validate::kinematics);
        BaseDocument {
            doc,
            file,
            kinematics,
        }
    }

    /// The document.
    pub fn doc(&self) -> &Table {
        &self.doc
    }

    /// The top-level sections `overrides` fall in, in [`SECTIONS`] order; None when one starts
    /// with anything else (an unknown key: the full reading reports it).
    fn sections_of(overrides: &[Override]) -> Option<Vec<&'static str>> {
        let mut touched = Vec::new();
        for ov in overrides {
            let Some(Step::Key(k)) = ov.path.0.first() else {
                return None;
            };
            touched.push(*SECTIONS.iter().find(|s| **s == k.as_str())?);
        }
        Some(SECTIONS.iter().copied().filter(|s| touched.contains(s)).collect())
    }
}

/// As [`from_document_with`] on a copy of `base`'s document, with the same result and the same
/// problems: only the sections the overrides fall in are copied, overridden and read again.
pub fn from_base_with(
    base: &BaseDocument,
    file: &Path,
    overrides: &[Override],
) -> Result<Gearbox, ModelError> {
    let (Some(typed), Some(keys)) = (&base.file, BaseDocument::sections_of(overrides)) else {
        return from_document_with(base.doc.clone(), file, overrides);
    };
    let invalid = |problems: Problems| ModelError::Invalid {
        file: file.to_path_buf(),
        problems: problems.into_vec(),
    };
    let mut part: Table = keys
        .iter()
        .filter_map(|k| base.doc.get(*k).map(|v| (k.to_string(), v.clone())))
        .collect();
    let mut problems = Problems::default();
    let mut applied = Vec::with_capacity(overrides.len());
    for ov in overrides {
        match overrides::apply(&mut part, ov) {
            Ok(canon) => applied.push((canon, ov.to_string())),
            Err(msg) => problems.push(ov.path.to_string(), &ov.value, msg),
        }
    }
    if !problems.is_empty() {
        return Err(invalid(problems));
    }
    let parsed = parse::reparse_sections(part, typed, &mut problems);
    // The kinematics are the base's when no override falls in the sections they are solved from.
    let same_train = !keys.iter().any(|k| validate::KINEMATIC_SECTIONS.contains(k));
    let known = base.kinematics.as_ref().filter(|_| same_train);
    let gearbox = parsed.and_then(|f| validate::validate_with(&f, known, &mut problems));
    match gearbox {
        Some(g) if problems.is_empty() => Ok(g),
        _ => Err(invalid(annotate(problems, &applied))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::overrides::KeyPath;

    fn models() -> Vec<(std::path::PathBuf, Table)> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
        let mut out = Vec::new();
        for e in std::fs::read_dir(dir).unwrap() {
            let path = e.unwrap().path();
            if path.extension().is_none_or(|x| x != "toml") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let mut p = Problems::default();
            let doc = parse::parse_document(&text, &mut p).unwrap();
            if doc.contains_key("gears") {
                out.push((path, doc));
            }
        }
        assert!(out.len() >= 5, "bundled models found: {}", out.len());
        out
    }

    fn ov(path: &str, value: toml::Value) -> Override {
        Override {
            path: path.parse::<KeyPath>().unwrap(),
            value,
        }
    }

    /// Both readings as text: the checked gearbox's debug form (every float printed to the
    /// bit) or the error report.
    fn both(doc: &Table, base: &BaseDocument, file: &Path, ovs: &[Override]) -> (String, String) {
        let show = |r: Result<Gearbox, ModelError>| match r {
            Ok(g) => format!("{g:?}"),
            Err(e) => e.report(),
        };
        (
            show(from_document_with(doc.clone(), file, ovs)),
            show(from_base_with(base, file, ovs)),
        )
    }

    #[test]
    fn sections_read_anew_over_another_model_equal_the_merged_document() {
        let all = models();
        let mut seen = std::collections::BTreeSet::new();
        for (_, base_doc) in &all {
            let typed = BaseDocument::new(base_doc.clone()).file.unwrap();
            for (path, doc) in &all {
                let mut merged = base_doc.clone();
                merged.extend(doc.clone());
                let (mut p, mut q) = (Problems::default(), Problems::default());
                let again = parse::reparse_sections(doc.clone(), &typed, &mut p);
                let whole = parse::parse_table(merged, &mut q);
                assert_eq!(format!("{again:?}"), format!("{whole:?}"), "{}", path.display());
                seen.extend(doc.keys().cloned());
            }
        }
        assert!(seen.len() >= 15, "sections covered: {seen:?}");
    }

    #[test]
    fn a_variant_of_the_base_equals_the_overridden_document() {
        let f = toml::Value::Float;
        let cases = [
            vec![ov("lubrication.oil_level_mm", f(41.5))],
            vec![
                ov("oil.lubricant_factor", f(0.9)),
                ov("losses.multiplier.churning", f(1.7)),
            ],
            vec![ov("gears[0].teeth", toml::Value::Integer(23))],
            vec![ov("gears[0].face_width_mm", f(-3.0))],
            vec![ov("lubrication.oil_level_mm", toml::Value::String("deep".into()))],
            vec![ov("thermal.nodes[0].mass_kg", f(0.0)), ov("model.name", f(1.0))],
            vec![ov("gears[99].teeth", toml::Value::Integer(20))],
            vec![ov("nonsense.key", f(1.0))],
            vec![ov("gears[0].name", toml::Value::String("a,b".into()))],
        ];
        for (path, doc) in models() {
            let base = BaseDocument::new(doc.clone());
            for ovs in &cases {
                let (whole, part) = both(&doc, &base, &path, ovs);
                assert_eq!(whole, part, "{} with {ovs:?}", path.display());
            }
        }
    }
}
