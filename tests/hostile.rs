//! Hostile input: each defect class the hostile-input review and its campaigns found, as a
//! regression test on the release binary (exit code, message, what is written); each fails on a
//! build without its fix (docs/robustness.md).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The binary under test; `GEARTHERM_BIN` points the suite at another build (to show that
/// each test fails on a build without the fixes).
fn bin() -> Command {
    match std::env::var_os("GEARTHERM_BIN") {
        Some(p) => Command::new(p),
        None => Command::new(env!("CARGO_BIN_EXE_geartherm")),
    }
}

/// Run with a 10 s limit: a command still running then is killed and the test fails (a hang).
fn run(args: &[&str]) -> Output {
    use std::process::Stdio;
    let mut child = bin()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    let t = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if t.elapsed() > Duration::from_secs(10) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("hang: geartherm {} still running after 10 s", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().expect("output")
}

fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
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

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Hang: a 1e100 km/h cycle would be integrated at full CPU for 90 s and more under
/// `--max-steps 100`. It is refused at the edge with line and allowed range, quickly.
#[test]
fn an_impossible_vehicle_speed_is_refused_with_its_line() {
    let d = tempfile::tempdir().unwrap();
    let c = write(d.path(), "c.csv", "time_s,speed_kmh\n0,0\n1,1e100\n2,0\n");
    let out = d.path().join("out");
    let t = Instant::now();
    let o = run(&[
        "run",
        "models/fzg_c.toml",
        "--cycle",
        s(&c),
        "--max-steps",
        "100",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert!(t.elapsed() < Duration::from_secs(10), "took {:?}", t.elapsed());
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("line 3") && e.contains("speed_kmh") && e.contains("500"),
        "{e}"
    );
    assert!(!out.exists(), "nothing written");
}

/// Nonsense: a cycle with 1e-12 s steps exited 0 with an energy-balance residual of 1.
#[test]
fn time_steps_below_a_millisecond_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let c = write(d.path(), "c.csv", "time_s,speed_kmh\n0,0\n1e-12,10\n2e-12,0\n");
    let o = run(&[
        "run",
        "models/fzg_c.toml",
        "--cycle",
        s(&c),
        "--out",
        s(&d.path().join("o")),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("line 3") && stderr(&o).contains("0.001"),
        "{}",
        stderr(&o)
    );
}

/// Nonsense: FZG C at 1450 rpm, 0.1 N·m printed efficiency −1.7576.
#[test]
fn efficiency_lies_in_0_1_when_losses_exceed_the_power() {
    let o = run(&[
        "losses",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "1450",
        "--torque-nm",
        "0.1",
        "--oil-temp-c",
        "23",
        "--json",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let eta = v["efficiency"].as_f64().unwrap();
    let p = v["input_power_w"].as_f64().unwrap();
    let l = v["loss_total_w"].as_f64().unwrap();
    assert!(l > p, "the case has more loss than power ({l} W vs {p} W)");
    assert!((0.0..=1.0).contains(&eta), "{eta}");
    assert!((eta - p / (p + l)).abs() < 1e-12, "{eta}");
}

/// Nonsense: `losses --speed-rpm 1e-300` printed `null` (NaN) items on all four models.
#[test]
fn losses_never_print_null_numbers() {
    for m in [
        "models/fzg_c.toml",
        "models/at6_lepelletier.toml",
        "models/helical_stage.toml",
        "models/pt6_spur_pair.toml",
    ] {
        let o = run(&[
            "losses",
            m,
            "--gear",
            "1",
            "--speed-rpm",
            "1e-300",
            "--torque-nm",
            "10",
            "--oil-temp-c",
            "40",
            "--json",
        ]);
        let out = stdout(&o);
        match code(&o) {
            0 => {
                let v: serde_json::Value = serde_json::from_str(&out).unwrap();
                for it in v["items"].as_array().unwrap() {
                    assert!(it["w"].is_f64(), "{m}: {it}");
                }
                assert!(v["loss_total_w"].is_f64(), "{m}");
                let e = &v["efficiency"];
                assert!(
                    e.is_null() || (0.0..=1.0).contains(&e.as_f64().unwrap()),
                    "{m}: {e}"
                );
            }
            c => {
                assert!(c == 1 || c == 2, "{m}: exit {c}: {}", stderr(&o));
                assert!(out.is_empty(), "--json prints the document or nothing: {out}");
            }
        }
    }
}

/// Corrupt CSV at exit 0: a mesh named `a\nb,c"d` passed `check` and broke the CSV header.
#[test]
fn names_that_would_need_quoting_are_refused_with_their_key_path() {
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string("models/fzg_c.toml")
        .unwrap()
        .replace("name = \"pinion/wheel\"", "name = \"a\\nb,c\\\"d\"");
    let m = write(d.path(), "m.toml", &text);
    let o = run(&["check", s(&m)]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("meshes[0].name"), "{}", stderr(&o));
}

/// Wrong exit codes: a missing or unreadable model file and a cycle path that is a directory
/// exited 1 instead of 3 (I/O).
#[test]
fn io_failures_on_inputs_exit_3() {
    let d = tempfile::tempdir().unwrap();
    let o = run(&["check", s(&d.path().join("missing.toml"))]);
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let o = run(&["info", s(d.path())]);
    assert_eq!(code(&o), 3, "a directory as model: {}", stderr(&o));
    let o = run(&[
        "run",
        "models/fzg_c.toml",
        "--cycle",
        s(d.path()),
        "--out",
        s(&d.path().join("o")),
    ]);
    assert_eq!(code(&o), 3, "a directory as cycle: {}", stderr(&o));
    assert!(!d.path().join("o").exists());
}

/// Wrong exit codes: `report` on malformed JSON/CSV exited 3 instead of 1; `report` accepted
/// NaN cells and wrote `inf` into report.md.
#[test]
fn report_on_malformed_or_non_finite_inputs_exits_1_and_keeps_the_directory() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path().join("r");
    std::fs::create_dir(&dir).unwrap();
    let header = "time_s,vehicle_speed_kmh,gear,input_speed_rpm,input_torque_nm,output_power_w,temp_oil_c,\
                  loss_churning_w,loss_pocketing_w,loss_sliding_w,loss_total_w,efficiency\n";
    write(
        &dir,
        "timeseries.csv",
        &format!("{header}0,0,1,0,0,0,23,0,0,0,0,\n1,10,1,1000,10,1000,NaN,1,0,0,1,0.99\n"),
    );
    write(
        &dir,
        "summary.json",
        r#"{"model":"m","cycle":"c","nodes":[{"name":"oil","boundary":false}],"oil_node":"oil"}"#,
    );
    let before = names(&dir);
    let o = run(&["report", s(&dir)]);
    assert_eq!(code(&o), 1, "NaN cell: {}", stderr(&o));
    assert!(stderr(&o).contains("temp_oil_c"), "{}", stderr(&o));
    assert_eq!(names(&dir), before, "nothing written");
    write(
        &dir,
        "timeseries.csv",
        &format!("{header}0,0,1,0,0,0,23,0,0,0,0,\n1,10,1,1000,10,1000,24,1,0,0,1,0.99\n"),
    );
    write(&dir, "summary.json", "{ not json");
    let o = run(&["report", s(&dir)]);
    assert_eq!(code(&o), 1, "malformed JSON: {}", stderr(&o));
    assert_eq!(names(&dir), before);
}

/// Stale files: a `--summary-only` run after a full one must not leave the old timeseries.csv
/// and PNGs.
#[test]
fn a_rerun_replaces_the_whole_result_set() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    let c = write(d.path(), "c.csv", "time_s,speed_kmh\n0,0\n30,50\n60,0\n");
    let o = run(&[
        "run",
        "models/at6_lepelletier.toml",
        "--cycle",
        s(&c),
        "--out",
        s(&out),
        "--report",
        "--quiet",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(out.join("efficiency.png").is_file());
    let o = run(&[
        "run",
        "models/at6_lepelletier.toml",
        "--cycle",
        s(&c),
        "--out",
        s(&out),
        "--summary-only",
        "--quiet",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert_eq!(names(&out), [".geartherm-output", "summary.json"]);
    assert_eq!(
        names(d.path()),
        ["c.csv", "o"],
        "no temporaries beside the target"
    );
}

/// Partial files: `map` exited 2 yet wrote map.csv. A map whose points fail writes nothing.
/// And `report` on a map directory wrote no report.md.
#[test]
fn report_on_a_map_directory_writes_report_md() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("m");
    let o = run(&[
        "map",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "500:1500:2",
        "--torque-nm",
        "50:100:2",
        "--out",
        s(&out),
        "--no-plots",
        "--quiet",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = run(&["report", s(&out)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("map_efficiency.png"), "{md}");
    assert!(!md.contains("inf") && !md.contains("NaN"), "{md}");
    assert!(out.join("map.csv").is_file() && out.join("map_oil_temp.png").is_file());
}

/// Crash: 2000 × 2000 points aborted on an allocation failure. Refused up front, limit stated.
#[test]
fn an_oversized_map_is_refused_with_the_limit() {
    let d = tempfile::tempdir().unwrap();
    let o = run(&[
        "map",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "500:3000:2000",
        "--torque-nm",
        "10:100:2000",
        "--out",
        s(&d.path().join("m")),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("at most 40000 points"), "{}", stderr(&o));
    let o = run(&[
        "map",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "500:3000:2001",
        "--torque-nm",
        "10:100:2",
    ]);
    assert_eq!(code(&o), 1);
    assert!(
        stderr(&o).contains("2000"),
        "the per-axis limit is stated: {}",
        stderr(&o)
    );
}

/// Messages: errors in `[vehicle]` said only `vehicle: invalid type`.
#[test]
fn vehicle_errors_name_the_key_path() {
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string("models/at6_lepelletier.toml").unwrap();
    let at = text.find("\n[vehicle]").expect("the AT6 has a vehicle");
    let (head, tail) = text.split_at(at);
    let line = tail
        .lines()
        .find(|l| l.trim_start().starts_with("mass_kg"))
        .expect("the AT6 has a vehicle mass")
        .to_string();
    let text = format!("{head}{}", tail.replacen(&line, "mass_kg = \"1100.0\"", 1));
    let m = write(d.path(), "m.toml", &text);
    let o = run(&["check", s(&m)]);
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("vehicle.mass_kg"), "{}", stderr(&o));
}

/// Output files were created with mode 0600.
#[cfg(unix)]
#[test]
fn outputs_get_the_usual_mode() {
    use std::os::unix::fs::PermissionsExt;
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    let c = write(d.path(), "c.csv", "time_s,speed_kmh\n0,0\n20,40\n40,0\n");
    let o = run(&[
        "run",
        "models/fzg_c.toml",
        "--cycle",
        s(&c),
        "--out",
        s(&out),
        "--quiet",
    ]);
    if code(&o) != 0 {
        // FZG C has no vehicle: use a rig cycle.
        let c = write(
            d.path(),
            "r.csv",
            "time_s,input_speed_rpm,input_torque_nm,gear\n0,1000,50,1\n20,1000,50,1\n",
        );
        let o = run(&[
            "run",
            "models/fzg_c.toml",
            "--cycle",
            s(&c),
            "--out",
            s(&out),
            "--quiet",
            "--report",
        ]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
    }
    let probe = d.path().join("probe");
    std::fs::File::create(&probe).unwrap();
    let usual = std::fs::metadata(&probe).unwrap().permissions().mode() & 0o777;
    for n in names(&out) {
        let m = std::fs::metadata(out.join(&n)).unwrap().permissions().mode() & 0o777;
        assert_eq!(m, usual, "{n}: {m:o}");
    }
}

/// Two commands writing into one directory: the second is refused with a clear message
/// while the first holds it; the directory never mixes their files.
#[test]
fn a_second_writer_is_refused_while_the_first_writes() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    let c = write(
        d.path(),
        "r.csv",
        "time_s,input_speed_rpm,input_torque_nm,gear\n0,1000,50,1\n3600,3000,150,1\n7200,1000,50,1\n",
    );
    let args = [
        "run",
        "models/fzg_c.toml",
        "--cycle",
        s(&c),
        "--out",
        s(&out),
        "--quiet",
        "--rtol",
        "1e-9",
    ];
    let mut first = bin().args(args).spawn().unwrap();
    // Wait for the first to take the lock: the file exists from its open, but the first holds
    // the lock only once it has written its PID there (a second writer started between the two
    // could take the lock first, and then the first is the one refused).
    let lock = d.path().join(".o.geartherm-lock");
    let held = || std::fs::read_to_string(&lock).is_ok_and(|s| !s.trim().is_empty());
    let t = Instant::now();
    while !held() && t.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let second = run(&args);
    let st = first.wait().unwrap();
    assert!(st.success());
    if lock.exists() || code(&second) != 0 {
        assert_eq!(code(&second), 3, "{}", stderr(&second));
        assert!(
            stderr(&second).contains("another geartherm"),
            "{}",
            stderr(&second)
        );
    }
    assert_eq!(
        names(&out),
        [".geartherm-output", "summary.json", "timeseries.csv"]
    );
}

/// Hostile-input campaign, seed 23, case 79658: a cycle of 1e-308 / 1e-300 rpm on the AT6. A NaN
/// bearing drag there would give a NaN first step size, which never becomes "too small" and keeps
/// `run --max-steps 100000` busy for ever; `losses` at such speeds must not fail either.
/// Vanishing speeds are standstill: exit 0, finite numbers, at once.
#[test]
fn vanishing_speeds_are_standstill_not_failures() {
    for m in [
        "models/fzg_c.toml",
        "models/at6_lepelletier.toml",
        "models/helical_stage.toml",
        "models/pt6_spur_pair.toml",
    ] {
        for n in ["1e-300", "1e-200", "1e-100"] {
            let o = run(&[
                "losses",
                m,
                "--gear",
                "1",
                "--speed-rpm",
                n,
                "--torque-nm",
                "100",
                "--oil-temp-c",
                "23",
                "--json",
            ]);
            assert_eq!(code(&o), 0, "{m} at {n} rpm: {}", stderr(&o));
            let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
            assert!(
                v["loss_total_w"].as_f64().is_some_and(f64::is_finite),
                "{m} at {n}"
            );
        }
    }
    let d = tempfile::tempdir().unwrap();
    let cycle = write(
        d.path(),
        "c.csv",
        "time_s,input_speed_rpm,input_torque_nm,gear\n0.5,1e-308,100,3\n10.5,1e-300,1e-308,3\n",
    );
    let out = d.path().join("o");
    let o = run(&[
        "run",
        "models/at6_lepelletier.toml",
        "--cycle",
        s(&cycle),
        "--out",
        s(&out),
        "--quiet",
        "--max-steps",
        "100000",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let sum = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(!sum.contains("NaN") && !sum.contains("null"), "{sum}");
    // The input torque once divided the converter's and the engine-driven pump's loss by the
    // vanishing input speed: `inf` in timeseries.csv at exit 0 (same campaign, second run).
    let ts = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    for cell in ts.lines().skip(1).flat_map(|l| l.split(',')) {
        assert!(
            cell.is_empty() || cell.parse::<f64>().map_or(true, f64::is_finite),
            "non-finite cell {cell:?} in timeseries.csv"
        );
    }
}

/// Allocations sized by user input are refused up front: a housing meshed into 100 000 patches
/// (the most `[thermal.wall_mesh]` allows) over a WLTC would keep 1801 rows × 100 067 values
/// (1.4 GB of states, a CSV of several GB); the run is refused with the figures, exit 1, nothing
/// written, in well under a second.
#[test]
fn a_run_too_large_to_keep_is_refused_with_its_size() {
    let d = tempfile::tempdir().unwrap();
    let mut text = std::fs::read_to_string("models/at6_lepelletier.toml").unwrap();
    text.push_str(
        "\n[thermal.wall_mesh]\nnode = \"housing\"\naround = 400\nalong = 250\ncircumference_m = 1.4\n\
         length_m = 0.5\nthickness_mm = 15.0\nconductivity_w_per_mk = 100.0\n",
    );
    let model = write(d.path(), "mesh.toml", &text);
    let out = d.path().join("o");
    let o = run(&["run", s(&model), "--cycle", "wltc", "--out", s(&out), "--quiet"]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("1801 rows") && e.contains("limit of 50000000"), "{e}");
    assert!(e.contains("fewer wall patches"), "{e}");
    assert!(!out.exists(), "nothing written");
}
