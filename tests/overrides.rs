//! Overrides by key path: the same validation and messages as the file, the override named in
//! the message, unknown paths rejected; and `--set` on the CLI.

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::model::{self, ModelError, Override};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn at6() -> PathBuf {
    root().join("models/at6_lepelletier.toml")
}

fn ov(s: &str) -> Override {
    s.parse().unwrap()
}

fn messages(e: ModelError) -> Vec<String> {
    match e {
        ModelError::Invalid { problems, .. } => problems.iter().map(|p| p.to_string()).collect(),
        other => panic!("expected invalid, got {other}"),
    }
}

#[test]
fn an_override_changes_the_value_as_if_written_in_the_file() {
    let base = model::load(&at6()).unwrap();
    let gb = model::load_with(
        &at6(),
        &[
            ov("lubrication.oil_level_mm = 45"),
            ov(r#"oil.catalogue = "fva_3a""#),
        ],
    )
    .unwrap();
    assert!((base.oil_level - 0.060).abs() < 1e-12);
    assert!((gb.oil_level - 0.045).abs() < 1e-12);
    assert!(gb.oil.name.contains("FVA 3A"), "{}", gb.oil.name);
    // The same text written into the file gives the same gearbox.
    let text = std::fs::read_to_string(at6())
        .unwrap()
        .replace("oil_level_mm = 60.0", "oil_level_mm = 45")
        .replace("catalogue = \"dexron_vi_atf\"", "catalogue = \"fva_3a\"");
    let written = model::from_str(&text, Path::new("edited.toml")).unwrap();
    assert_eq!(format!("{written:?}"), format!("{gb:?}"));
}

#[test]
fn a_named_entry_is_overridden_and_an_invalid_value_names_the_override() {
    let gb = model::load_with(
        &at6(),
        &[ov(r#"thermal.coolers["atf_cooler"].effectiveness = 0.9"#)],
    )
    .unwrap();
    let c = &gb.thermal.as_ref().unwrap().coolers[0];
    assert!((c.conductance - 0.9 * 140.0).abs() < 1e-9, "{}", c.conductance);

    let e = model::load_with(
        &at6(),
        &[ov(r#"thermal.coolers["atf_cooler"].effectiveness = 1.5"#)],
    )
    .unwrap_err();
    let m = messages(e);
    assert!(
        m.iter().any(|x| x.starts_with("thermal.coolers[0].effectiveness")
            && x.contains(r#"set by override `thermal.coolers["atf_cooler"].effectiveness = 1.5`"#)),
        "{m:?}"
    );
    let e = model::load_with(&at6(), &[ov("gears[1].face_width_mm = -3")]).unwrap_err();
    let m = messages(e);
    assert!(
        m.iter()
            .any(|x| x.starts_with("gears[1].face_width_mm") && x.contains("set by override")),
        "{m:?}"
    );
    // A type error from the schema, with the same path.
    let e = model::load_with(&at6(), &[ov(r#"lubrication.oil_level_mm = "high""#)]).unwrap_err();
    let m = messages(e);
    assert!(
        m.iter()
            .any(|x| x.starts_with("lubrication.oil_level_mm") && x.contains("override")),
        "{m:?}"
    );
}

#[test]
fn unknown_paths_are_rejected_clearly() {
    let m = messages(model::load_with(&at6(), &[ov("lubrication.oil_levle_mm = 50")]).unwrap_err());
    assert!(
        m.iter()
            .any(|x| x.contains("oil_levle_mm") && x.contains("override")),
        "{m:?}"
    );
    let m = messages(model::load_with(&at6(), &[ov(r#"thermal.links["cooler"].area_m2 = 1"#)]).unwrap_err());
    assert!(
        m.iter()
            .any(|x| x.contains("no entry named \"cooler\"") && x.contains("housing-air")),
        "{m:?}"
    );
    let m = messages(model::load_with(&at6(), &[ov("gears[99].teeth = 3")]).unwrap_err());
    assert!(m.iter().any(|x| x.contains("out of range")), "{m:?}");
}

#[test]
fn cli_set_applies_and_rejects() {
    let bin = env!("CARGO_BIN_EXE_geartherm");
    let out = Command::new(bin)
        .args(["info", "--json", "--set", "lubrication.oil_level_mm=45"])
        .arg(at6())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = Command::new(bin)
        .args([
            "check",
            "--set",
            "thermal.coolers[\"atf_cooler\"].effectiveness=2",
        ])
        .arg(at6())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("thermal.coolers[0].effectiveness") && err.contains("override"),
        "{err}"
    );
    let out = Command::new(bin)
        .args(["check", "--set", "oil.catalogue=fva_3a"])
        .arg(at6())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("strings need quotes"));
}
