//! Faults while writing outputs: a run killed at any moment, an unwritable destination, a
//! file-size limit. The output directory holds the complete previous result set or the complete
//! new one, never a mix, and the next run into it removes what a killed run left beside it.
//! A full disk is simulated with a 256 kB tmpfs mounted in a user and mount namespace
//! (`unshare -rm`); where the kernel refuses such namespaces the test says so and checks nothing.

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
    // A kill before the commit must leave `before` byte for byte: checked at the first delay,
    // which lands long before any commit (the scene compile and integration come first).
    let mut child = bin().args(run_args(&out)).spawn().unwrap();
    std::thread::sleep(Duration::from_millis(2));
    let _ = child.kill();
    if !child.wait().unwrap().success() {
        assert_whole(&out);
        assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), before);
    }
    for delay_ms in [20u64, 150, 400, 800, 1500] {
        let mut child = bin().args(run_args(&out)).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill(); // SIGKILL
        let st = child.wait().unwrap();
        assert_whole(&out);
        let now = std::fs::read(out.join("summary.json")).unwrap();
        if !st.success() && now != before {
            // Killed after its commit and before its exit (a run takes about 0.1 s): the
            // new set, whole (checked above) — never a mix. Otherwise the previous set, byte
            // for byte.
            eprintln!("killed after {delay_ms} ms, after its commit");
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

/// Runs `script` with `$T` a fresh 256 kB tmpfs (a user + mount namespace, no root needed).
/// None when this machine does not allow unprivileged namespaces.
fn on_small_tmpfs(script: &str) -> Option<std::process::Output> {
    let probe = Command::new("unshare").args(["-rm", "true"]).output();
    if !matches!(probe, Ok(ref o) if o.status.success()) {
        eprintln!("disk-full test not run: unprivileged user/mount namespaces are not available");
        return None;
    }
    let full =
        format!("set -u; T=$(mktemp -d); mount -t tmpfs -o size=256k tmpfs \"$T\" || exit 99; {script}");
    let o = Command::new("unshare")
        .args(["-rm", "sh", "-c", &full])
        .env("G", env!("CARGO_BIN_EXE_geartherm"))
        .output()
        .unwrap();
    if o.status.code() == Some(99) {
        eprintln!("disk-full test not run: tmpfs cannot be mounted here");
        return None;
    }
    Some(o)
}

#[test]
fn a_full_disk_fails_the_run_with_an_io_error_and_keeps_the_previous_result() {
    // A --summary-only result fits in 256 kB; the full set (timeseries.csv of about 800 kB) does
    // not. The full run must exit 3 (I/O), leave the summary-only set byte for byte, and leave no
    // temporary behind; a later small run into the same place succeeds.
    let script = r#"
        M=models/at6_lepelletier.toml
        "$G" run $M --cycle wltc --summary-only --quiet --out "$T/o" >/dev/null 2>&1; echo "first=$?"
        A=$(cksum < "$T/o/summary.json")
        "$G" run $M --cycle wltc --report --quiet --out "$T/o" 2>"$T/../err"; echo "full=$?"
        echo "err=$(head -c 300 "$T/../err" | tr '\n' ' ')"
        B=$(cksum < "$T/o/summary.json")
        [ "$A" = "$B" ] && echo same=yes || echo same=no
        echo "top=$(ls -A "$T" | tr '\n' ' ')"
        echo "set=$(ls -A "$T/o" | tr '\n' ' ')"
        "$G" run $M --cycle wltc --summary-only --quiet --out "$T/o" >/dev/null 2>&1; echo "again=$?"
    "#;
    let Some(o) = on_small_tmpfs(script) else {
        return;
    };
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let field = |k: &str| -> String {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{k}=")))
            .unwrap_or_else(|| {
                panic!(
                    "no {k}= in {text:?} (stderr {:?})",
                    String::from_utf8_lossy(&o.stderr)
                )
            })
            .trim()
            .to_string()
    };
    assert_eq!(field("first"), "0", "{text}");
    assert_eq!(field("full"), "3", "a full disk is an I/O failure: {text}");
    assert!(
        field("err").contains("No space left"),
        "the message names the cause: {text}"
    );
    assert_eq!(field("same"), "yes", "the previous summary survives: {text}");
    assert_eq!(field("top"), "o", "no temporaries beside the output: {text}");
    assert_eq!(field("set"), ".geartherm-output summary.json", "{text}");
    assert_eq!(field("again"), "0", "{text}");
}

#[test]
fn validate_writes_its_result_set_as_one_transaction() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("v");
    let validate = |cases: &Path, out: &Path| {
        bin()
            .args([
                "validate",
                cases.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    let o = validate(Path::new("validation"), &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let full_set = names(&out);
    assert!(full_set.contains(&"validation.csv".to_string()), "{full_set:?}");
    let all_rows = std::fs::read(out.join("validation.csv")).unwrap();
    // A case directory that does not parse: exit 1, the previous set byte for byte.
    let bad = d.path().join("bad");
    std::fs::create_dir_all(bad.join("case1")).unwrap();
    std::fs::write(bad.join("case1/case.toml"), "kind = 3\n").unwrap();
    let o = validate(&bad, &out);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(names(&out), full_set);
    assert_eq!(std::fs::read(out.join("validation.csv")).unwrap(), all_rows);
    // One case only: the new set replaces the old one as a whole.
    let one = d.path().join("one");
    std::fs::create_dir_all(&one).unwrap();
    let src = Path::new("validation/gearpie_c14_sliding");
    let copy = one.join("gearpie_c14_sliding");
    std::fs::create_dir_all(&copy).unwrap();
    for e in std::fs::read_dir(src).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), copy.join(e.file_name())).unwrap();
    }
    let o = validate(&one, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = std::fs::read_to_string(out.join("validation.csv")).unwrap();
    assert!(rows.len() < all_rows.len() && rows.contains("gearpie_c14_sliding"));
    assert!(
        !rows.contains("gearpie_c40_sliding"),
        "no row of the previous set survives"
    );
    // Someone else's directory: refused, untouched.
    let mine = d.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), b"precious").unwrap();
    let o = validate(Path::new("validation"), &mine);
    assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(names(&mine), ["notes.txt"]);
    assert_eq!(
        names(d.path()),
        ["bad", "mine", "one", "v"],
        "no temporaries left"
    );
}
