//! Study files the hostile campaign (scripts/hostile_campaign.py, family `study_spec` and
//! `study_huge`) found accepted: each is refused before any case runs (exit 1), nothing
//! written.

use std::path::Path;
use std::process::{Command, Output};

const HEAD: &str = "[study]\nname = \"NAME\"\nmodel = \"MODEL\"\n";

fn study(dir: &Path, text: &str, extra: &[&str]) -> Output {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/fzg_c.toml");
    let file = dir.join("s.toml");
    std::fs::write(&file, text.replace("MODEL", model.to_str().unwrap())).unwrap();
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .arg("study")
        .arg(&file)
        .arg("--quiet")
        .args(extra)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn refused(o: &Output, what: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(what), "{err}");
}

const STEADY: &str =
    "[job]\nkind = \"steady\"\npoints = [{gear = \"1\", speed_rpm = 1450.0, torque_nm = 50.0}]\n";
const PARAM: &str = "[[parameters]]\npath = \"lubrication.oil_level_mm\"\nvalues = [40.0, 50.0]\n";

/// `name = "../../x"` made the default output directory `studies/../../x`, outside `studies/`.
#[test]
fn a_study_name_that_climbs_out_of_studies_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let cwd = d.path().join("a/b");
    std::fs::create_dir_all(&cwd).unwrap();
    for name in ["../../x", "a/b", "..", ".", ""] {
        let o = study(&cwd, &(HEAD.replace("NAME", name) + STEADY + PARAM), &[]);
        refused(&o, "study.name");
    }
    let mut left: Vec<String> = walk(d.path());
    left.sort();
    assert_eq!(left, ["a", "a/b", "a/b/s.toml"], "written outside the study file");
}

fn walk(d: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(d).unwrap() {
        let p = e.unwrap().path();
        out.push(p.file_name().unwrap().to_string_lossy().into_owned());
        if p.is_dir() {
            let name = out.last().unwrap().clone();
            out.extend(walk(&p).into_iter().map(|s| format!("{name}/{s}")));
        }
    }
    out
}

/// The same cycle twice gave two cases one id: the table held one id twice and a resumed
/// study would take one case for the other.
#[test]
fn two_cycles_with_one_case_id_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let rig = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/rig_short.csv");
    let rig = rig.to_str().unwrap();
    for cycles in [
        format!("[\"{rig}\", \"{rig}\"]"),
        "[\"wltc\", \"wltc\"]".to_string(),
    ] {
        let job = format!("[job]\nkind = \"run\"\ncycles = {cycles}\n");
        let o = study(
            d.path(),
            &(HEAD.replace("NAME", "s") + &job + PARAM),
            &["--out", "o"],
        );
        refused(&o, "give the same case id");
        assert!(!d.path().join("o").exists());
    }
}

/// A map job of 1 × 3000 points ran (`geartherm map` refuses an axis of more than 2000), and
/// 10⁷ samples × 40 000 map points = 4·10¹¹ cases aborted on allocation; both are refused from
/// their sizes.
#[test]
fn oversized_map_jobs_and_case_counts_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let axis: Vec<String> = (0..3000).map(|k| format!("{}.0", 500 + k)).collect();
    let job = format!(
        "[job]\nkind = \"map\"\ngear = \"1\"\nspeed_rpm = [1000.0]\ntorque_nm = [{}]\n",
        axis.join(", ")
    );
    let o = study(d.path(), &(HEAD.replace("NAME", "s") + &job + PARAM), &["--list"]);
    refused(&o, "a map axis has 1 to 2000 points");
    let axis: Vec<String> = (0..200).map(|k| format!("{}.0", 500 + k)).collect();
    let job = format!(
        "[job]\nkind = \"map\"\ngear = \"1\"\nspeed_rpm = [{a}]\ntorque_nm = [{a}]\n\
         [sampling]\nplan = \"lhs\"\ncases = 10000000\n",
        a = axis.join(", ")
    );
    let range = "[[parameters]]\npath = \"lubrication.oil_level_mm\"\nrange = [30.0, 50.0]\n";
    let o = study(d.path(), &(HEAD.replace("NAME", "s") + &job + range), &["--list"]);
    refused(&o, "10000000 samples × 40000 jobs: more than 10000000 cases");
    assert!(o.stdout.is_empty());
}

/// 10⁷ LHS samples of 64 parameters aborted on allocation (about 35 GB of sampled values).
#[test]
fn a_plan_with_too_many_sampled_values_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let mut text = HEAD.replace("NAME", "s") + STEADY + "[sampling]\nplan = \"lhs\"\ncases = 10000000\n";
    // 64 distinct key paths (each path once; the count is refused before any is looked up).
    for k in 0..64 {
        text += &format!("[[parameters]]\npath = \"thermal.p{k}\"\nrange = [20.0, 30.0]\n");
    }
    let o = study(d.path(), &text, &["--list"]);
    refused(&o, "10000000 samples × 64 parameters");
}

/// `oil.catalogue` varied by two parameters (numbers, then names): refused, each key path once
/// (such a study's figures had a text parameter without text values to colour by).
#[test]
fn a_key_path_varied_twice_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let twice =
        "[sampling]\nplan = \"list\"\n[[parameters]]\npath = \"oil.catalogue\"\nvalues = [1.0, 1.0]\n\
                 [[parameters]]\npath = \"oil.catalogue\"\nvalues = [\"fva_3a\", \"w326\"]\n";
    let o = study(
        d.path(),
        &(HEAD.replace("NAME", "s") + STEADY + twice),
        &["--out", "o"],
    );
    refused(&o, "parameters[1].path `oil.catalogue`: given twice");
    assert!(!d.path().join("o").exists());
}
