//! `geartherm study`: a killed study resumes without recomputing finished cases and without a
//! damaged output; a case equals its stand-alone command; a failing case is a row, not the end;
//! shards merge into the same table.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A study of `n` LHS samples of the AT6 on a short rig-free slice: the bundled UDDS-free
/// "artemis_urban" is long; the FTP-75's first phase is not bundled alone, so the cycle is the
/// shortest bundled one that the AT6 drives.
fn study_file(dir: &Path, n: usize, extra: &str) -> PathBuf {
    let model = root().join("models/at6_lepelletier.toml");
    let text = format!(
        r#"
[study]
name = "t"
model = "{}"
[job]
kind = "run"
cycles = ["hwfet"]
[sampling]
plan = "lhs"
cases = {n}
seed = 3
[[parameters]]
path = "lubrication.oil_level_mm"
range = [40.0, 80.0]
[[parameters]]
path = "oil.catalogue"
values = ["dexron_vi_atf", "fva_3a"]
[[parameters]]
path = 'thermal.links["housing-air"].h_table.h_w_per_m2k'
scale = [0.5, 2.0]
{extra}
[outputs]
pareto = ["energy_total_j", "temp_max_sump_c"]
"#,
        model.display().to_string().replace('\\', "/")
    );
    let p = dir.join("study.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn journal_ids(dir: &Path) -> Vec<String> {
    let Ok(text) = std::fs::read_to_string(dir.join("journal.jsonl")) else {
        return Vec::new();
    };
    text.lines()
        .skip(1)
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter_map(|v| v.get("case").and_then(|c| c.as_str()).map(str::to_string))
        .collect()
}

#[test]
fn a_killed_study_resumes_without_recomputing_finished_cases() {
    let d = tempfile::tempdir().unwrap();
    // Enough cases (a few ms each) that the kill lands mid-study.
    let n = 200;
    let s = study_file(d.path(), n, "");
    let out = d.path().join("out");
    // Run a first time and kill it (SIGKILL) once a few cases are journaled.
    let mut child = bin()
        .args([
            "study",
            s.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .env("RAYON_NUM_THREADS", "2")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while journal_ids(&out).len() < 3 && t0.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let before = journal_ids(&out);
    assert!(
        before.len() >= 3 && before.len() < n,
        "killed after {} cases",
        before.len()
    );
    // Nothing half-written: no table yet (it is written whole at the end, or not at all).
    assert!(!out.join("study.csv").exists());

    let res = bin()
        .args([
            "study",
            s.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&res.stdout);
    assert!(
        res.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&res.stderr)
    );
    let after = journal_ids(&out);
    // Each case journaled exactly once: the finished ones were not recomputed.
    let mut sorted = after.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(sorted.len(), n, "{after:?}");
    assert_eq!(after.len(), n, "a case was computed twice: {after:?}");
    assert_eq!(&after[..before.len()], &before[..]);
    assert!(
        stdout.contains(&format!("{} cases solved", n - before.len()))
            && stdout.contains(&format!("{} already done", before.len())),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("study.csv")).unwrap();
    assert_eq!(csv.lines().count(), n + 1);
    assert!(!csv.contains("NaN"));
    for f in ["study.parquet", "main_effects.png", "pareto.png"] {
        assert!(out.join(f).metadata().unwrap().len() > 0, "{f}");
    }

    // A third run recomputes nothing and rewrites the same table.
    let res = bin()
        .args([
            "study",
            s.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&res.stdout).contains("0 cases solved"));
    assert_eq!(std::fs::read_to_string(out.join("study.csv")).unwrap(), csv);
}

#[test]
fn a_case_equals_its_stand_alone_command_and_failures_are_rows() {
    let d = tempfile::tempdir().unwrap();
    // An oil level far below every gear makes an invalid model? No: it is allowed. A cooler
    // effectiveness above 1 is not, so half of this list fails validation.
    let s = study_file(
        d.path(),
        2,
        r#"[[parameters]]
path = 'thermal.coolers["atf_cooler"].effectiveness'
range = [0.5, 1.5]"#,
    );
    let listing = bin()
        .args(["study", s.to_str().unwrap(), "--list"])
        .output()
        .unwrap();
    assert!(
        listing.status.success(),
        "{}",
        String::from_utf8_lossy(&listing.stderr)
    );
    let listing = String::from_utf8_lossy(&listing.stdout).to_string();
    let lines: Vec<&str> = listing.lines().collect();
    assert_eq!(lines.len(), 2);

    let out = d.path().join("out");
    let res = bin()
        .args([
            "study",
            s.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(res.status.success(), "{}", String::from_utf8_lossy(&res.stderr));
    let mut rdr = csv::Reader::from_path(out.join("study.csv")).unwrap();
    let head = rdr.headers().unwrap().clone();
    let col = |name: &str| head.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
    let statuses: Vec<&str> = rows.iter().map(|r| &r[col("status")]).collect();
    assert!(
        statuses.contains(&"ok") && statuses.contains(&"invalid"),
        "{statuses:?}"
    );
    let bad = rows.iter().find(|r| &r[col("status")] == "invalid").unwrap();
    assert!(bad[col("message")].contains("effectiveness") && bad[col("message")].contains("override"));
    assert_eq!(&bad[col("energy_total_j")], "");

    // The ok case, run alone from its listed command line, gives the same numbers.
    let good = rows.iter().find(|r| &r[col("status")] == "ok").unwrap();
    let line = lines.iter().find(|l| l.starts_with(&good[col("case")])).unwrap();
    let cmd = line.split_once('\t').unwrap().1;
    let args = shell_words(cmd);
    assert_eq!(args[0], "geartherm");
    let alone = bin()
        .args(&args[1..])
        .args([
            "--json",
            "--quiet",
            "--out",
            d.path().join("alone").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        alone.status.success(),
        "{cmd}: {}",
        String::from_utf8_lossy(&alone.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&alone.stdout).unwrap();
    let e = v["energy_lost_j"]["total"].as_f64().unwrap();
    let t = v["temperatures_c"]["sump"]["max"].as_f64().unwrap();
    assert_eq!(good[col("energy_total_j")].parse::<f64>().unwrap(), e);
    assert_eq!(good[col("temp_max_sump_c")].parse::<f64>().unwrap(), t);
}

/// Split a command line written by `Study::command_line` (words, single-quoted words).
fn shell_words(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut in_q = false;
    let mut any = false;
    let cs: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < cs.len() {
        let c = cs[i];
        if in_q {
            if c == '\'' {
                in_q = false;
            } else {
                cur.push(c);
            }
        } else if c == '\'' {
            in_q = true;
            any = true;
        } else if c == '\\' && i + 1 < cs.len() {
            cur.push(cs[i + 1]);
            i += 1;
        } else if c.is_whitespace() {
            if any || !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
                any = false;
            }
        } else {
            cur.push(c);
        }
        i += 1;
    }
    if any || !cur.is_empty() {
        out.push(cur);
    }
    out
}

#[test]
fn shards_merge_into_the_whole_table() {
    let d = tempfile::tempdir().unwrap();
    let s = study_file(d.path(), 3, "");
    let out = d.path().join("out");
    for shard in ["0/2", "1/2"] {
        let r = bin()
            .args([
                "study",
                s.to_str().unwrap(),
                "--quiet",
                "--shard",
                shard,
                "--out",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    assert!(!out.join("study.csv").exists());
    let r = bin()
        .args([
            "study",
            s.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(
        stdout.contains("0 cases solved") && stdout.contains("3 already done"),
        "{stdout}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("study.csv"))
            .unwrap()
            .lines()
            .count(),
        4
    );
    // Another study in the same directory is refused.
    let other = study_file(d.path(), 4, "");
    let r = bin()
        .args([
            "study",
            other.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("different study"));
}

/// The bundled example study (`models/studies/at6_wltc_lhs.toml`) runs to its table and both
/// figures, so its `effects` and `pareto` name columns the table has (a renamed output column once
/// broke it after all its cases had run). Run here with 4 of its 1000 cases: the same file with
/// `cases = 4` and the model path made absolute.
#[test]
fn the_bundled_example_study_runs_to_its_figures() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("models/studies/at6_wltc_lhs.toml")).unwrap();
    let model = root().join("models/at6_lepelletier.toml");
    let small = text.replace("cases = 1000", "cases = 4").replace(
        "\"../at6_lepelletier.toml\"",
        &format!("{:?}", model.display().to_string()),
    );
    assert_ne!(small, text);
    let file = tmp.path().join("study.toml");
    std::fs::write(&file, small).unwrap();
    let out = tmp.path().join("s");
    let o = bin()
        .arg("study")
        .arg(&file)
        .args(["--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["study.csv", "study.parquet", "main_effects.png", "pareto.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(out.join("study.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4, "{csv}");
}

/// A second writer of the same study directory is refused while the first holds it (exit 3, the
/// holder named), and nothing is journaled or written by the refused run; a different shard of
/// the same study is not blocked.
#[test]
fn a_second_writer_of_the_same_study_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let file = study_file(tmp.path(), 2, "");
    let out = tmp.path().join("s");
    let held = geartherm::report::files::lock_in_place(&out, "journal.jsonl").unwrap();
    let o = bin()
        .arg("study")
        .arg(&file)
        .args(["--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(&std::process::id().to_string()), "{err}");
    assert!(!out.join("journal.jsonl").exists() && !out.join("study.csv").exists());
    let o = bin()
        .arg("study")
        .arg(&file)
        .args(["--quiet", "--shard", "0/2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    drop(held);
    let o = bin()
        .arg("study")
        .arg(&file)
        .args(["--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("study.csv").is_file());
}
