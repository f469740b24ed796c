//! The CLI's contract where a hostile user pushes it: an unwritable or closed standard output
//! (exit 3, or a quiet 141 for a closed pipe; the previous result set kept), a study refused
//! before it runs (unknown output column, bad option), a study whose model file cannot be read
//! (exit 3, as for `check` and `run`), and `bench --set`.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_geartherm"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn dev_full() -> Option<File> {
    File::options().write(true).open("/dev/full").ok()
}

fn code(c: &mut Command) -> (i32, String) {
    let o = c.output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn an_unwritable_stdout_is_exit_3_and_keeps_the_old_result() {
    let Some(_) = dev_full() else { return };
    let (c, e) = code(
        bin()
            .args(["info", "models/fzg_c.toml"])
            .stdout(dev_full().unwrap()),
    );
    assert_eq!(c, 3, "{e}");
    assert!(e.contains("standard output"), "{e}");

    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("r");
    let args = [
        "run",
        "models/fzg_c.toml",
        "--cycle",
        "tests/data/rig_short.csv",
        "--quiet",
        "--out",
    ];
    let (c, e) = code(bin().args(args).arg(&out));
    assert_eq!(c, 0, "{e}");
    let before = std::fs::read(out.join("summary.json")).unwrap();
    // A second run into the same directory whose stdout cannot be written: exit 3, and the
    // directory still holds the first run's result set, whole, with no temporary left beside.
    let (c, e) = code(
        bin()
            .args(args)
            .arg(&out)
            .args(["--initial-temp-c", "40"])
            .stdout(dev_full().unwrap()),
    );
    assert_eq!(c, 3, "{e}");
    assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), before);
    let stray: Vec<_> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "r")
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
}

#[test]
fn a_closed_pipe_ends_quietly_with_141() {
    let d = tempfile::tempdir().unwrap();
    let s = study_file(d.path(), 20_000, "");
    let mut child = bin()
        .args(["study", s.to_str().unwrap(), "--list"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read one line, then close the pipe (as `| head -1` does).
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 64];
    let _ = stdout.read(&mut first).unwrap();
    drop(stdout);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(141), "{err}");
    assert!(!err.contains("panicked") && err.trim().is_empty(), "{err}");
}

fn study_file(dir: &Path, n: usize, outputs: &str) -> PathBuf {
    let model = root().join("models/fzg_c.toml");
    let cycle = root().join("tests/data/rig_short.csv");
    let text = format!(
        r#"
[study]
name = "t"
model = "{}"
[job]
kind = "run"
cycles = ["{}"]
[sampling]
plan = "lhs"
cases = {n}
[[parameters]]
path = "lubrication.oil_level_mm"
range = [120.0, 160.0]
{outputs}
"#,
        model.display(),
        cycle.display()
    );
    let p = dir.join("study.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_study_with_an_unknown_output_column_is_refused_before_it_runs() {
    let d = tempfile::tempdir().unwrap();
    let s = study_file(
        d.path(),
        3,
        "[outputs]\npareto = [\"energy_total_j\", \"no_such_column\"]",
    );
    let out = d.path().join("out");
    let (c, e) = code(
        bin()
            .args(["study", s.to_str().unwrap(), "--quiet", "--out"])
            .arg(&out),
    );
    assert_eq!(c, 1, "{e}");
    assert!(
        e.contains("outputs.pareto: no output column `no_such_column`"),
        "{e}"
    );
    assert!(
        !out.exists(),
        "nothing may be written: {:?}",
        std::fs::read_dir(&out).ok().map(|d| d.count())
    );
}

#[test]
fn a_study_with_a_bad_option_is_refused_before_it_runs() {
    let d = tempfile::tempdir().unwrap();
    let s = study_file(d.path(), 3, "");
    let text = std::fs::read_to_string(&s)
        .unwrap()
        .replace("[sampling]", "options = { rtol = 0.5 }\n[sampling]");
    std::fs::write(&s, text).unwrap();
    let out = d.path().join("out");
    let (c, e) = code(
        bin()
            .args(["study", s.to_str().unwrap(), "--quiet", "--out"])
            .arg(&out),
    );
    assert_eq!(c, 1, "{e}");
    assert!(e.contains("job.options: rtol = 0.5: must lie in"), "{e}");
    assert!(!out.exists());
}

#[test]
fn a_study_whose_model_cannot_be_read_is_exit_3_like_check_and_run() {
    let d = tempfile::tempdir().unwrap();
    let s = study_file(d.path(), 3, "");
    for model in [d.path().join("missing.toml"), d.path().to_path_buf()] {
        let text = std::fs::read_to_string(&s).unwrap();
        let text = text
            .lines()
            .map(|l| {
                if l.starts_with("model = ") {
                    format!("model = \"{}\"", model.display())
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let s2 = d.path().join("s2.toml");
        std::fs::write(&s2, text).unwrap();
        let (c, e) = code(bin().args(["study", s2.to_str().unwrap(), "--quiet"]));
        let (c_check, _) = code(bin().arg("check").arg(&model));
        assert_eq!(c_check, 3);
        assert_eq!(c, 3, "{}: {e}", model.display());
    }
}

#[test]
fn bench_takes_set_like_every_command_that_reads_a_model() {
    let (c, e) = code(bin().args([
        "bench",
        "models/fzg_c.toml",
        "--set",
        "oil.catalogue=\"no_such_oil\"",
        "--out",
        "/nonexistent/never-written",
        "--cycle",
        "tests/data/rig_short.csv",
    ]));
    // The override is applied and checked like the file: an invalid value names its key path.
    assert_eq!(c, 1, "{e}");
    assert!(e.contains("oil.catalogue") && e.contains("no_such_oil"), "{e}");
}

/// A solver that fails at a tolerance (tsit45 on a housing of 10 mg: far too stiff for an
/// explicit method) keeps its row: the message in `failure`, nulls in bench.json, and
/// `FAILED: …` in its printed line in place of its figures, never `NaN`.
#[test]
fn a_failed_bench_row_prints_no_nan() {
    let d = tempfile::tempdir().unwrap();
    let out = bin()
        .args([
            "bench",
            "models/fzg_c.toml",
            "--set",
            "thermal.nodes[\"housing\"].mass_kg=1e-08",
            "--cycle",
            "tests/data/rig_short.csv",
            "--repeats",
            "1",
            "--min-rtol",
            "1e-3",
            "--solvers",
            "ros3,tsit45",
            "--out",
        ])
        .arg(d.path().join("b"))
        .current_dir(root())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("tsit45") && text.contains("FAILED: numerical failure"),
        "{text}"
    );
    assert!(!text.contains("NaN"), "{text}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("b/bench.json")).unwrap()).unwrap();
    let failed = &json["rows"][1];
    assert!(
        failed["failure"]
            .as_str()
            .is_some_and(|f| f.contains("step budget")),
        "{failed}"
    );
    assert!(
        failed["wall_time_s"].is_null() && failed["err_max_k"].is_null(),
        "{failed}"
    );
}
