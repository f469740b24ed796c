//! A writer killed while it holds its output lock leaves the lock file beside the output
//! directory (`.<name>.geartherm-lock`, or `.<name>.<journal>.geartherm-lock` for a study): the
//! kernel drops the `flock`, but nobody removes the file. The next writer into the same target
//! is not refused by it (the lock is the `flock`, not the file's existence), and removes it when
//! it finishes (docs/robustness.md, "Output directories as transactions").

use std::path::Path;
use std::process::{Child, Command};
use std::time::{Duration, Instant};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_geartherm"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A rig cycle of `rows` one-second rows alternating between two operating points (a run over
/// it takes a few seconds: long enough to be killed while it writes).
fn long_cycle(path: &Path, rows: usize) {
    let mut s = String::from("time_s,input_speed_rpm,input_torque_nm,gear\n");
    for k in 0..rows {
        s.push_str(&format!(
            "{k},{},{},1\n",
            if k % 2 == 0 { 3000 } else { 1000 },
            50 + k % 3 * 25
        ));
    }
    std::fs::write(path, s).unwrap();
}

/// Start `cmd`, wait until `lock` exists (the child holds it), then SIGKILL the child. None
/// if the child finished before its lock was seen.
fn kill_holding(mut cmd: Command, lock: &Path) -> Option<()> {
    let mut child: Child = cmd.spawn().unwrap();
    let start = Instant::now();
    while !lock.exists() {
        if child.try_wait().unwrap().is_some() || start.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    // Hold a moment so that the kill lands inside the work, not at the lock's creation.
    std::thread::sleep(Duration::from_millis(50));
    child.kill().unwrap();
    let st = child.wait().unwrap();
    assert!(!st.success(), "the writer finished before it was killed");
    Some(())
}

#[test]
fn a_killed_runs_stale_lock_is_removed_by_the_next_run() {
    let d = tempfile::tempdir().unwrap();
    let cycle = d.path().join("long.csv");
    long_cycle(&cycle, 600_000);
    let parent = d.path().join("outs");
    let out = parent.join("o");
    let lock = parent.join(".o.geartherm-lock");
    let run = |cycle: &Path| {
        let mut c = bin();
        c.args(["run", "models/fzg_c.toml", "--summary-only", "--quiet", "--cycle"])
            .arg(cycle)
            .arg("--out")
            .arg(&out);
        c
    };
    kill_holding(run(&cycle), &lock).expect("the run ended before its lock was seen");
    assert!(lock.exists(), "a killed writer leaves its lock file");
    let left = names(&parent);
    assert!(left.contains(&".o.geartherm-lock".to_string()), "{left:?}");
    // The next writer is not refused by the dead writer's lock file, and removes it (and the
    // dead writer's temporary directory) when it finishes.
    let o = run(Path::new("wltc")).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        names(&parent),
        ["o"],
        "stale lock or temporary left beside the target"
    );
    assert!(out.join("summary.json").exists());
}

#[test]
fn a_killed_studys_stale_lock_is_removed_by_the_next_study() {
    let d = tempfile::tempdir().unwrap();
    let cycle = d.path().join("long.csv");
    long_cycle(&cycle, 300_000);
    let root = env!("CARGO_MANIFEST_DIR");
    let study = d.path().join("s.toml");
    std::fs::write(
        &study,
        format!(
            "[study]\nname = \"s\"\nmodel = \"{root}/models/fzg_c.toml\"\n\n[job]\nkind = \"run\"\n\
             cycles = [\"{}\"]\noptions = {{ summary_only = true }}\n\n[sampling]\nplan = \"grid\"\n\n\
             [[parameters]]\npath = \"lubrication.oil_level_mm\"\nvalues = [40.0, 45.0, 50.0, 55.0]\n",
            cycle.display()
        ),
    )
    .unwrap();
    let parent = d.path().join("outs");
    let out = parent.join("o");
    let lock = parent.join(".o.journal.jsonl.geartherm-lock");
    let go = || {
        let mut c = bin();
        c.arg("study").arg(&study).arg("--quiet").arg("--out").arg(&out);
        c
    };
    kill_holding(go(), &lock).expect("the study ended before its lock was seen");
    assert!(lock.exists(), "a killed study leaves its lock file");
    let o = go().output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        names(&parent),
        ["o"],
        "stale lock left beside the study directory"
    );
    let csv = std::fs::read_to_string(out.join("study.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "every case exactly once:\n{csv}");
}
