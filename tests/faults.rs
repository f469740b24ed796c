//! Faults while writing outputs: a run killed at any moment, an unwritable destination, a
//! file-size limit. The output directory holds the complete previous result set or the complete
//! new one, never a mix, and the next run into it removes what a killed run left beside it.
//! (Disk-full is not simulated: it needs a mounted small file system, which CI does not have;
//! a full disk fails the same `write` calls as the file-size limit below.)

use std::path::Path;
use std::process::Command;
use std::time::Duration;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

const FULL: [&str; 8] = [
    ".geartherm-output",
    "efficiency.png",
    "energy.png",
    "losses.png",
    "report.md",
    "summary.json",
    "temperatures.png",
    "timeseries.csv",
];

fn run_args(out: &Path) -> Vec<String> {
    [
        "run",
        "models/at6_lepelletier.toml",
        "--cycle",
        "wltc",
        "--report",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

fn complete_run(out: &Path) {
    let o = bin().args(run_args(out)).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(names(out), FULL);
}

/// The target holds exactly the complete set, with a summary that parses.
fn assert_whole(out: &Path) {
    assert_eq!(names(out), FULL, "a mixed or partial result set");
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert!(s["cycle_efficiency"].is_f64());
}

#[test]
fn a_run_killed_at_any_moment_leaves_the_previous_result_whole_and_the_next_run_cleans_up() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    complete_run(&out);
    let before = std::fs::read(out.join("summary.json")).unwrap();
    for delay_ms in [20u64, 150, 400, 800, 1500] {
        let mut child = bin().args(run_args(&out)).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill(); // SIGKILL
        let st = child.wait().unwrap();
        assert_whole(&out);
        if !st.success() {
            // Killed before its commit: the previous result, byte for byte.
            assert_eq!(
                std::fs::read(out.join("summary.json")).unwrap(),
                before,
                "after {delay_ms} ms"
            );
        }
    }
    complete_run(&out);
    assert_eq!(
        names(d.path()),
        ["o"],
        "stale temporaries and lock removed by the next run"
    );
}

#[test]
fn a_file_size_limit_fails_the_run_and_keeps_the_previous_result() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    complete_run(&out);
    let before = std::fs::read(out.join("timeseries.csv")).unwrap();
    // 64 blocks (32–64 kB) is far below the ~800 kB timeseries.csv: the write fails (EFBIG) or
    // the process is killed (SIGXFSZ), depending on the signal disposition.
    let cmd = format!(
        "ulimit -f 64; exec {} {}",
        env!("CARGO_BIN_EXE_geartherm"),
        run_args(&out).join(" ")
    );
    let o = Command::new("sh").arg("-c").arg(cmd).output().unwrap();
    assert!(!o.status.success(), "the run cannot succeed under the limit");
    if let Some(c) = o.status.code() {
        assert_eq!(c, 3, "an I/O failure: {}", String::from_utf8_lossy(&o.stderr));
    }
    assert_whole(&out);
    assert_eq!(std::fs::read(out.join("timeseries.csv")).unwrap(), before);
    complete_run(&out);
    assert_eq!(names(d.path()), ["o"]);
}

#[test]
fn an_unwritable_destination_is_an_io_error_and_writes_nothing() {
    let d = tempfile::tempdir().unwrap();
    // The parent of --out is a regular file: nothing can be created there (even as root).
    let file = d.path().join("f");
    std::fs::write(&file, b"keep").unwrap();
    let o = bin().args(run_args(&file.join("o"))).output().unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&file).unwrap(), b"keep");
    // --out is itself a regular file.
    let o = bin().args(run_args(&file)).output().unwrap();
    assert_eq!(o.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a directory"));
    assert_eq!(std::fs::read(&file).unwrap(), b"keep");
    // --out is a directory of someone else's files: refused, not swapped away.
    let mine = d.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("thesis.tex"), b"precious").unwrap();
    let o = bin().args(run_args(&mine)).output().unwrap();
    assert_eq!(o.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&o.stderr).contains("thesis.tex"));
    assert_eq!(names(&mine), ["thesis.tex"]);
    assert_eq!(names(d.path()), ["f", "mine"], "no temporaries left");
}
