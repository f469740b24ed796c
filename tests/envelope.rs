//! The physics envelope (src/job/envelope.rs, docs/robustness.md "Physics envelope"): an option
//! that puts the oil outside the range of its Walther fit is refused up front with that range
//! (exit 1), and a run, steady point or map whose state leaves the range where its models hold
//! fails with exit 2, naming the time (or the equilibrium), the node and the model, and writes
//! nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const MODELS: [&str; 4] = [
    "models/fzg_c.toml",
    "models/at6_lepelletier.toml",
    "models/helical_stage.toml",
    "models/pt6_spur_pair.toml",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn geartherm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn out_arg(d: &Path) -> String {
    d.join("o").to_str().unwrap().to_string()
}

/// `run MODEL --cycle wltc --frozen-viscosity-c -60` finished with exit 0 on every bundled model
/// with node temperatures of 1.9e4 … 1.9e8 °C; −60 °C is below every bundled oil's range.
#[test]
fn frozen_viscosity_below_the_oil_range_is_refused_with_the_range() {
    for m in MODELS {
        let d = tempfile::tempdir().unwrap();
        let out = out_arg(d.path());
        let o = geartherm(&[
            "run",
            m,
            "--cycle",
            "wltc",
            "--frozen-viscosity-c",
            "-60",
            "--quiet",
            "--out",
            &out,
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{m}: {err}");
        assert!(
            err.contains("frozen_viscosity_c (--frozen-viscosity-c) = -60 °C: must lie in ["),
            "{m}: {err}"
        );
        assert!(err.contains("Walther fit of oil"), "{m}: {err}");
        assert!(o.stdout.is_empty(), "{m}");
        assert!(!d.path().join("o").exists(), "{m}: wrote {out}");
    }
}

/// Inside the oil's range but far below the run's temperatures, frozen oil properties make the
/// AT6's clutch drag heat the sump past the oil's range: exit 2, naming the interval, the node,
/// the oil's model and the largest loss item; nothing written.
#[test]
fn a_run_that_leaves_the_envelope_fails_naming_time_node_and_model() {
    let d = tempfile::tempdir().unwrap();
    let out = out_arg(d.path());
    let o = geartherm(&[
        "run",
        "models/at6_lepelletier.toml",
        "--cycle",
        "wltc",
        "--frozen-viscosity-c",
        "0",
        "--summary-only",
        "--quiet",
        "--out",
        &out,
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("models/at6_lepelletier.toml: "), "{err}");
    assert!(err.contains("between t = "), "{err}");
    assert!(err.contains("node sump at 20"), "{err}");
    assert!(err.contains("outside [-57.1, 200] °C"), "{err}");
    assert!(
        err.contains("Walther fit of oil Mobil Super DEXRON-VI ATF"),
        "{err}"
    );
    assert!(err.contains("largest loss there: clutch_drag:"), "{err}");
    assert!(!d.path().join("o").exists());
}

/// The oil temperature of `losses` and the initial temperature of a run are held to the oil's
/// range (FVA 3A: from −35 °C); the model's own initial temperature too (exit 1, nothing run).
#[test]
fn oil_temperatures_outside_the_oil_range_are_refused() {
    let o = geartherm(&[
        "losses",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "1450",
        "--torque-nm",
        "50",
        "--oil-temp-c",
        "-50",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("oil_temp_c (--oil-temp-c) = -50 °C: must lie in [-35, 200] °C"),
        "{}",
        stderr(&o)
    );
    for extra in [
        ["--initial-temp-c", "-50"],
        ["--set", "thermal.initial_temp_c=-50"],
    ] {
        let d = tempfile::tempdir().unwrap();
        let out = out_arg(d.path());
        let mut args = vec!["run", "models/fzg_c.toml", "--quiet", "--out", &out];
        args.extend(extra);
        let o = geartherm(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {err}");
        assert!(err.contains("[-35, 200] °C"), "{extra:?}: {err}");
        assert!(!d.path().join("o").exists());
    }
}

/// An equilibrium at −60 °C ambient without losses leaves the oil at −60 °C, below the DTE 24's
/// range (−47.8 °C): `steady` and `map` fail with exit 2 naming the node and the oil.
#[test]
fn an_equilibrium_outside_the_envelope_fails() {
    let o = geartherm(&[
        "steady",
        "models/helical_stage.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "0",
        "--torque-nm",
        "0",
        "--ambient-c",
        "-60",
        "--json",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(o.stdout.is_empty());
    assert!(
        err.contains("the equilibrium is outside the range where the models hold: node oil at -60.0 °C"),
        "{err}"
    );
    assert!(err.contains("Walther fit of oil Mobil DTE 24"), "{err}");
    let d = tempfile::tempdir().unwrap();
    let out = out_arg(d.path());
    let o = geartherm(&[
        "map",
        "models/helical_stage.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "0:100:2",
        "--torque-nm",
        "0:1:2",
        "--ambient-c",
        "-60",
        "--no-plots",
        "--quiet",
        "--out",
        &out,
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("0 rpm, 0 N m: the equilibrium is outside"), "{err}");
    assert!(!d.path().join("o").exists());
}
