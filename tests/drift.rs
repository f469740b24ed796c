//! One pipeline, three front ends: every row of `tests/data/option_limits.toml` (inputs at and
//! beyond every job option's limits) is sent through the CLI, a study case and the job layer
//! that the Python binding calls (python/tests/test_drift.py sends it through Python itself);
//! each must accept or refuse it alike, with the same message. Every form of a case selection
//! (`--shard I/N`, `--cases LIST`, both) is accepted or refused alike by the CLI and the study
//! layer that Python and its Dask path call (python/tests/test_drift.py: Python and Dask).

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::job::{self, LossesOptions, RatingOptions, RunOptions, SteadyOptions};
use geartherm::study::spec::{JobSpec, Meta, OutputSpec, ParamSpec, Sampling, StudySpec};
use geartherm::study::{ParamValue, Selection, Study};
use toml::{Table, Value};

const MODEL: &str = "models/fzg_c.toml";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// What a front end made of a row: accepted (and then ok, or a numerical failure with its
/// message) or refused with its message.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    Ok,
    Failed(String),
    Refused(String),
}

struct Row {
    job: String,
    options: Table,
    expect_accept: bool,
}

fn rows() -> Vec<Row> {
    let text = std::fs::read_to_string(root().join("tests/data/option_limits.toml")).unwrap();
    let doc: Table = text.parse().unwrap();
    let base = doc["base"].as_table().unwrap();
    doc["row"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let job = r["job"].as_str().unwrap().to_string();
            let mut options = base[&job].as_table().unwrap().clone();
            for (k, v) in r["set"].as_table().unwrap() {
                options.insert(k.clone(), v.clone());
            }
            if job == "run" {
                options.insert("summary_only".into(), Value::Boolean(true));
            }
            Row {
                job,
                options,
                expect_accept: r["expect"].as_str() == Some("accept"),
            }
        })
        .collect()
}

fn flag(k: &str) -> String {
    format!("--{}", k.replace('_', "-"))
}

/// A CLI message as the job layer wrote it: the CLI adds the flag after an option named at
/// the message's start (`speed_rpm (--speed-rpm) = …`); the other front ends name the option
/// only. Every other word must be the same.
fn unspelled(msg: &str, options: &Table) -> String {
    let names: Vec<&str> = options.keys().map(String::as_str).collect();
    unspelled_names(msg, &names)
}

/// [`unspelled`] for the options `names` (and the options named by the job layer itself).
fn unspelled_names(msg: &str, names: &[&str]) -> String {
    for k in names.iter().copied().chain(["gear", "solver", "solvers"]) {
        let spelled = format!("{k} ({})", flag(k));
        if let Some(rest) = msg.strip_prefix(&spelled) {
            return format!("{k}{rest}");
        }
    }
    msg.to_string()
}

fn cli(row: &Row, out: &Path) -> Outcome {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_geartherm"));
    cmd.current_dir(root()).arg(&row.job).arg(MODEL);
    for (k, v) in &row.options {
        match v {
            Value::Boolean(true) => {
                cmd.arg(flag(k));
            }
            Value::Boolean(false) => {}
            Value::String(s) => {
                cmd.arg(flag(k)).arg(s);
            }
            Value::Float(x) => {
                cmd.arg(format!("{}={x}", flag(k)));
            }
            Value::Array(a) => {
                let items: Vec<String> = a.iter().map(|v| v.to_string()).collect();
                cmd.arg(format!("{}={}", flag(k), items.join(",")));
            }
            other => {
                cmd.arg(format!("{}={other}", flag(k)));
            }
        }
    }
    if row.job == "run" || row.job == "rating" {
        cmd.arg("--quiet").arg("--out").arg(out);
    }
    let o = cmd.output().unwrap();
    let msg = unspelled(String::from_utf8_lossy(&o.stderr).trim(), &row.options);
    match o.status.code() {
        Some(0) => Outcome::Ok,
        Some(1) => Outcome::Refused(msg),
        Some(2) => Outcome::Failed(msg),
        c => panic!("{}: exit {c:?}: {msg}", row.job),
    }
}

fn model() -> job::Model {
    job::Model::load(&root().join(MODEL), &[]).unwrap()
}

fn outcome<T>(r: Result<T, job::JobError>) -> Outcome {
    match r {
        Ok(_) => Outcome::Ok,
        Err(e) if e.is_invalid() => Outcome::Refused(e.message),
        Err(e) => Outcome::Failed(e.message),
    }
}

fn options<T: serde::de::DeserializeOwned>(row: &Row) -> T {
    Value::Table(row.options.clone())
        .try_into()
        .unwrap_or_else(|e| panic!("{:?}: {e}", row.options))
}

/// The job layer as the Python binding calls it: options deserialised from a mapping.
fn library(row: &Row, m: &job::Model) -> Outcome {
    match row.job.as_str() {
        "losses" => outcome(job::losses::losses(m, &options::<LossesOptions>(row))),
        "steady" => outcome(job::steady::steady(m, &options::<SteadyOptions>(row))),
        "run" => outcome(job::run::run(m, &options::<RunOptions>(row), &mut |_, _| {})),
        "rating" => outcome(job::rating::rating(m, &options::<RatingOptions>(row), &|| {})),
        other => panic!("{other}"),
    }
}

/// A one-case study of the row's job; its refusal loses the study's key path in front.
fn study(row: &Row, text: &str) -> Option<Outcome> {
    let job = match row.job.as_str() {
        "steady" => JobSpec::Steady {
            points: vec![options(row)],
        },
        "run" => {
            let o: RunOptions = options(row);
            JobSpec::Run {
                cycles: vec![o.cycle.clone()],
                options: Some(o),
            }
        }
        _ => return None,
    };
    let spec = StudySpec {
        study: Meta {
            name: "drift".into(),
            model: String::new(),
        },
        job,
        sampling: Sampling::default(),
        parameters: vec![ParamSpec {
            path: "lubrication.oil_level_mm".into(),
            values: Some(vec![ParamValue::Number(150.0)]),
            range: None,
            scale: None,
            levels: None,
            factors: false,
        }],
        uncertainty: None,
        outputs: OutputSpec::default(),
    };
    let s = match Study::new(spec, text.to_string(), root().join(MODEL)) {
        Ok(s) => s,
        Err(e) if e.is_invalid() => {
            let (_key, msg) = e.message.split_once(": ").unwrap();
            return Some(Outcome::Refused(msg.to_string()));
        }
        Err(e) => panic!("{e}"),
    };
    let (r, _) = s.run_case(&s.cases()[0], false);
    Some(match r.status.as_str() {
        "ok" => Outcome::Ok,
        "failed" => Outcome::Failed(r.message),
        _ => Outcome::Refused(r.message),
    })
}

#[test]
fn every_front_end_accepts_and_refuses_alike() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join(MODEL)).unwrap();
    let m = job::Model {
        file: PathBuf::from(MODEL),
        ..model()
    };
    let (mut refused, mut accepted) = (0, 0);
    for (k, row) in rows().iter().enumerate() {
        let what = format!("row {k}: {} {:?}", row.job, row.options);
        let c = cli(row, &tmp.path().join(format!("r{k}")));
        let l = library(row, &m);
        assert_eq!(c, l, "{what}: CLI vs job layer");
        if let Some(s) = study(row, &text) {
            // The study names the model by the path it was given, the CLI by the relative one.
            let abs = root().join(MODEL).display().to_string();
            let s = match s {
                Outcome::Failed(x) => Outcome::Failed(x.replace(&abs, MODEL)),
                Outcome::Refused(x) => Outcome::Refused(x.replace(&abs, MODEL)),
                Outcome::Ok => Outcome::Ok,
            };
            assert_eq!(c, s, "{what}: CLI vs study case");
        }
        match &c {
            Outcome::Refused(msg) => {
                assert!(!row.expect_accept, "{what}: refused: {msg}");
                refused += 1;
            }
            _ => {
                assert!(row.expect_accept, "{what}: accepted: {c:?}");
                accepted += 1;
            }
        }
    }
    eprintln!("{accepted} rows accepted, {refused} refused alike by the CLI, a study case and the job layer");
    assert!(refused > 20 && accepted > 15);
}

/// A four-case steady study of the FZG C model (`tests/data/selection_study.toml`).
const SELECTION_STUDY: &str = "tests/data/selection_study.toml";

/// The shard and case-list forms of the drift tests, valid and not (python/tests/test_drift.py
/// sends the numeric ones through Python and Dask).
const SHARDS: &[&str] = &[
    "0/2", "1/2", "3/4", "0/1", "2/2", "3/2", "0/0", "-1/2", "1/-2", "x/2", "1", "1/2/3",
];
const CASE_LISTS: &[&str] = &["0", "3,0", "0,1,2,3", "4", "-1", "1,1", "", "a", "2,-3"];

/// The CLI's `study --list` with the selection flags: the case ids listed, or the refusal.
fn cli_select(flags: &[(&str, &str)]) -> Result<Vec<String>, (i32, String)> {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_geartherm"));
    cmd.current_dir(root()).args(["study", SELECTION_STUDY, "--list"]);
    for (flag, value) in flags {
        cmd.arg(format!("{flag}={value}"));
    }
    let o = cmd.output().unwrap();
    match o.status.code() {
        Some(0) => Ok(String::from_utf8_lossy(&o.stdout)
            .lines()
            .map(|l| l.split('\t').next().unwrap().to_string())
            .collect()),
        Some(c) => Err((
            c,
            unspelled_names(String::from_utf8_lossy(&o.stderr).trim(), &["shard", "cases"]),
        )),
        None => panic!("killed"),
    }
}

/// The study layer's selection (what Python and the Dask path call) from the same text.
fn layer_select(s: &Study, cases: Option<&str>, shard: Option<&str>) -> Result<Vec<String>, (i32, String)> {
    let picked = Selection::parse(cases, shard).and_then(|sel| s.select(&sel));
    match picked {
        Ok(list) => Ok(list.iter().map(|c| s.case_id(c)).collect()),
        Err(e) => Err((e.exit_code(), e.message)),
    }
}

#[test]
fn every_case_selection_is_accepted_or_refused_alike() {
    let s = Study::from_file(&root().join(SELECTION_STUDY)).unwrap();
    assert_eq!(s.cases().len(), 4);
    let mut forms: Vec<(Option<&str>, Option<&str>)> = Vec::new();
    forms.extend(SHARDS.iter().map(|x| (None, Some(*x))));
    forms.extend(CASE_LISTS.iter().map(|x| (Some(*x), None)));
    forms.extend([(Some("0"), Some("0/2")), (Some("9"), Some("5/2"))]);
    let (mut accepted, mut refused) = (0, 0);
    for (cases, shard) in forms {
        let mut flags = Vec::new();
        flags.extend(cases.map(|c| ("--cases", c)));
        flags.extend(shard.map(|x| ("--shard", x)));
        let c = cli_select(&flags);
        let l = layer_select(&s, cases, shard);
        assert_eq!(c, l, "cases {cases:?}, shard {shard:?}");
        match c {
            Ok(ids) => {
                assert!(!ids.is_empty() || shard.is_some(), "{cases:?} {shard:?}");
                accepted += 1;
            }
            Err((code, msg)) => {
                assert_eq!(code, 1, "{msg}");
                refused += 1;
            }
        }
    }
    // The forms' outcomes, as the study layer defines them.
    assert_eq!(
        layer_select(&s, None, Some("1/2")).unwrap(),
        ["000001-p0000", "000003-p0000"]
    );
    assert_eq!(
        layer_select(&s, Some("3,0"), None).unwrap(),
        ["000003-p0000", "000000-p0000"]
    );
    assert_eq!(
        layer_select(&s, None, Some("3/2")).unwrap_err().1,
        "shard = 3/2: expected I/N with 0 ≤ I < N"
    );
    assert_eq!(
        layer_select(&s, Some("4"), None).unwrap_err().1,
        "cases: 4: must lie in [0, 4) (the study has 4 cases)"
    );
    eprintln!("{accepted} selections accepted, {refused} refused alike by the CLI and the study layer");
    assert!(accepted >= 6 && refused >= 12, "{accepted} {refused}");
}

/// A model, cycle, trace or study file that is read but is not UTF-8 text is bad input (exit 1,
/// the file named), the same fault sorted the same way by every reader; a missing one is I/O.
#[test]
fn a_file_that_is_not_utf8_is_bad_input_for_every_reader() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("bad.csv");
    std::fs::write(&bad, b"time_s,speed_kmh\n0,0\n1,\xff\xfe\n").unwrap();
    let b = bad.display().to_string();
    let out = tmp.path().join("out").display().to_string();
    let missing = tmp.path().join("missing.csv").display().to_string();
    let runs: Vec<(Vec<&str>, i32)> = vec![
        (vec!["check", &b], 1),
        (vec!["run", MODEL, "--cycle", &b, "--quiet", "--out", &out], 1),
        (vec!["trace", &b], 1),
        (vec!["study", &b, "--quiet", "--out", &out], 1),
        (vec!["trace", &missing], 3),
        (vec!["study", &missing], 3),
    ];
    for (args, code) in runs {
        let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
            .current_dir(root())
            .args(&args)
            .output()
            .unwrap();
        let msg = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {msg}");
        let file = if code == 1 { "bad.csv" } else { "missing.csv" };
        assert!(msg.contains(file), "{args:?}: {msg}");
    }
    assert!(!tmp.path().join("out").exists(), "nothing written");
}

/// The model of tests/uq_cli.rs: the PT6 spur pair's gears with one capacity node between an
/// ambient and a coolant boundary, with `uncertainty` appended.
fn uq_model(uncertainty: &str) -> String {
    let pt6 = std::fs::read_to_string(root().join("models/pt6_spur_pair.toml")).unwrap();
    let head = &pt6[..pt6.find("\n[thermal]").unwrap()];
    format!(
        "{head}\n[thermal]\noil_node = \"oil\"\ninitial_temp_c = 10.0\n\n[[thermal.nodes]]\nname = \"oil\"\ncapacity_j_per_k = 2000.0\n\n\
         [[thermal.boundaries]]\nname = \"ambient\"\ntemp_c = 20.0\n\n[[thermal.boundaries]]\nname = \"coolant\"\ntemp_c = 60.0\n\n\
         [[thermal.links]]\nname = \"oil-air\"\nbetween = [\"oil\", \"ambient\"]\nconductance_w_per_k = 3.0\n\n\
         [[thermal.links]]\nname = \"oil-coolant\"\nbetween = [\"oil\", \"coolant\"]\nconductance_w_per_k = 1.0\n\n{uncertainty}"
    )
}

/// `[uncertainty]` sections and `uq` options, valid and not (python/tests/test_drift.py sends
/// the same through `Model.uq`): (inputs, options as `--flag=value`).
const UQ_ROWS: &[(&str, &[&str])] = &[
    ("amb normal 20 2", &[]),
    ("amb normal 20 -1", &[]),
    ("link uniform 4 2", &[]),
    ("link uniform 2 4", &[]),
    ("link normal 3 2", &[]),
    ("amb lognormal 20 0.1", &[]),
    ("nope uniform 2 4", &[]),
    ("amb normal 20 2", &["--samples=0"]),
    ("amb normal 20 2", &["--samples=1000001"]),
    ("amb normal 20 2", &["--samples=1000000", "--sobol"]),
    ("amb normal 20 2", &["--limit=nope=100"]),
    ("amb normal 20 2", &["--limit=oil=25"]),
    ("amb normal 20 2", &["--percentiles=95,5"]),
    ("amb normal 20 2", &["--confidence=1"]),
    ("amb normal 20 2", &["--bootstrap=10001"]),
    ("amb normal 20 2", &["--series-points=1"]),
    ("amb normal 20 2", &["--sobol"]),
    ("samples 0", &[]),
];

/// The `[[uncertainty.inputs]]` text of a row's inputs (`what dist a b`; `samples N`: the
/// section's sample count with the ambient input).
fn uq_inputs(row: &str) -> String {
    let w: Vec<&str> = row.split(' ').collect();
    if w[0] == "samples" {
        return format!(
            "[uncertainty]\nsamples = {}\n{}",
            w[1],
            uq_inputs("amb normal 20 2")
        );
    }
    let path = match w[0] {
        "amb" => "thermal.boundaries[\"ambient\"].temp_c",
        "link" => "thermal.links[\"oil-air\"].conductance_w_per_k",
        _ => "thermal.links[\"nope\"].conductance_w_per_k",
    };
    let keys = match w[1] {
        "normal" => ["mean", "sd"],
        "lognormal" => ["median", "sigma_ln"],
        _ => ["lo", "hi"],
    };
    format!(
        "[[uncertainty.inputs]]\npath = '{path}'\ndist = \"{}\"\n{} = {}\n{} = {}\n",
        w[1], keys[0], w[2], keys[1], w[3]
    )
}

/// The use case's options of `flags` (as the CLI converts them).
fn uq_options(flags: &[&str], cycle: &Path) -> geartherm::study::uq::run::UqOptions {
    use geartherm::study::uq::run::{Limit, UqJob, UqOptions};
    let mut o = UqOptions {
        job: Some(UqJob::Run(RunOptions {
            cycle: cycle.display().to_string(),
            rtol: job::run::DEFAULT_RTOL,
            summary_only: true,
            ..RunOptions::default()
        })),
        samples: Some(8),
        ..UqOptions::default()
    };
    for f in flags {
        let (k, v) = f.split_once('=').unwrap_or((f, ""));
        match k {
            "--samples" => o.samples = v.parse().ok(),
            "--sobol" => o.sobol = true,
            "--limit" => {
                let (node, t) = v.split_once('=').unwrap();
                o.limits.push(Limit {
                    node: node.into(),
                    temp_c: t.parse().unwrap(),
                });
            }
            "--percentiles" => o.percentiles = v.split(',').map(|x| x.parse().unwrap()).collect(),
            "--confidence" => o.confidence = v.parse().unwrap(),
            "--bootstrap" => o.bootstrap = v.parse().unwrap(),
            "--series-points" => o.series_points = v.parse().unwrap(),
            other => panic!("{other}"),
        }
    }
    o
}

#[test]
fn uq_accepts_and_refuses_alike_from_the_cli_and_the_use_case() {
    let tmp = tempfile::tempdir().unwrap();
    let cycle = tmp.path().join("standstill.csv");
    let mut s = String::from("time_s,input_speed_rpm,input_torque_nm,gear\n");
    for k in 0..=20 {
        s.push_str(&format!("{},0,0,1\n", k * 50));
    }
    std::fs::write(&cycle, s).unwrap();
    let (mut refused, mut accepted) = (0, 0);
    for (k, (inputs, flags)) in UQ_ROWS.iter().enumerate() {
        let model = tmp.path().join(format!("m{k}.toml"));
        let text = uq_model(&uq_inputs(inputs));
        std::fs::write(&model, &text).unwrap();
        let out = tmp.path().join(format!("o{k}"));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_geartherm"));
        cmd.arg("uq")
            .arg(&model)
            .arg("--cycle")
            .arg(&cycle)
            .arg("--quiet");
        cmd.arg("--out").arg(&out);
        if !flags.iter().any(|f| f.starts_with("--samples")) {
            cmd.arg("--samples=8");
        }
        let o = cmd.args(flags.iter()).output().unwrap();
        let names = [
            "samples",
            "limit",
            "percentiles",
            "confidence",
            "bootstrap",
            "series_points",
        ];
        let c = match o.status.code() {
            Some(0) => Outcome::Ok,
            Some(1) => Outcome::Refused(unspelled_names(String::from_utf8_lossy(&o.stderr).trim(), &names)),
            c => panic!("row {k}: exit {c:?}: {}", String::from_utf8_lossy(&o.stderr)),
        };
        let l = match geartherm::study::uq::run::Uq::new(text, model.clone(), uq_options(flags, &cycle)) {
            Ok(_) => Outcome::Ok,
            Err(e) if e.is_invalid() => Outcome::Refused(e.message),
            Err(e) => Outcome::Failed(e.message),
        };
        assert_eq!(c, l, "row {k}: {inputs} {flags:?}: CLI vs use case");
        if matches!(c, Outcome::Refused(_)) {
            assert!(!out.exists(), "row {k}: refused but wrote {}", out.display());
            refused += 1;
        } else {
            accepted += 1;
        }
    }
    eprintln!("uq: {accepted} rows accepted, {refused} refused alike by the CLI and the use case");
    assert!(
        refused >= 12 && accepted >= 4,
        "{accepted} accepted, {refused} refused"
    );
}

/// The options a calibrate message may name at its start (the CLI adds the flag after it).
const CALIBRATE_NAMES: &[&str] = &[
    "fit",
    "holdout",
    "rtol",
    "atol",
    "max_steps",
    "max_iterations",
    "segment",
    "residuals",
    "prior",
    "profile",
    "gearbox_kind",
    "rated",
    "trace",
    "band_quantile",
];

/// The calibrate rows of `tests/data/option_limits.toml`: the model, the options (base and
/// `set` on top) and whether the checks accept them.
fn calibrate_rows() -> Vec<(String, Table, bool)> {
    let text = std::fs::read_to_string(root().join("tests/data/option_limits.toml")).unwrap();
    let doc: Table = text.parse().unwrap();
    let mut base = doc["base"]["calibrate"].as_table().unwrap().clone();
    let model = base.remove("model").unwrap().as_str().unwrap().to_string();
    doc["calibrate_row"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let mut options = base.clone();
            options.extend(r["set"].as_table().unwrap().clone());
            (model.clone(), options, r["expect"].as_str() == Some("accept"))
        })
        .collect()
}

/// `geartherm calibrate` with the row's options: each list item a flag of its own, `segments`
/// the `--segment` flag.
fn calibrate_cli(model: &str, options: &Table, out: &Path) -> Outcome {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_geartherm"));
    cmd.current_dir(root()).arg("calibrate").arg(model);
    for (k, v) in options {
        let f = flag(if k == "segments" { "segment" } else { k });
        let items = match v {
            Value::Array(a) => a.clone(),
            other => vec![other.clone()],
        };
        for item in items {
            match item {
                Value::String(s) => cmd.arg(format!("{f}={s}")),
                other => cmd.arg(format!("{f}={other}")),
            };
        }
    }
    let o = cmd.arg("--out").arg(out).output().unwrap();
    let msg = unspelled_names(String::from_utf8_lossy(&o.stderr).trim(), CALIBRATE_NAMES);
    match o.status.code() {
        Some(0) => Outcome::Ok,
        Some(1) => Outcome::Refused(msg),
        Some(2) => Outcome::Failed(msg),
        c => panic!("calibrate: exit {c:?}: {msg}"),
    }
}

/// The job layer as the Python binding calls it: options deserialised from a mapping, the
/// trace read from its text (one segment: `Model.calibrate`; `segments`: the several-trace fit
/// of `Model.calibrate(segments=…)`, the trace named by its file's stem).
fn calibrate_library(m: &job::Model, text: &str, options: &Table) -> Outcome {
    use geartherm::job::calibrate::{self, stack, stack_fit, trace_file, CalibrateOptions};
    let o: CalibrateOptions = Value::Table(options.clone()).try_into().unwrap();
    let csv = std::fs::read_to_string(root().join(&o.trace)).unwrap();
    if o.segments.is_some() {
        let stem = Path::new(&o.trace)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        return outcome((|| {
            let file = trace_file::read(&csv, &stem, o.missing())?;
            let files = [(stem.clone(), file)];
            let inputs = stack::inputs(&files, &o)?;
            let s = stack::prepare(m, text, &inputs, &o)?;
            stack_fit::fit(m, &s, &o, &|th| s.evaluate(th))
        })());
    }
    outcome((|| {
        let file = trace_file::read(&csv, &o.trace, o.missing())?;
        let trace = file
            .select(o.segment)
            .map_err(|e| job::JobError::invalid(e.to_string()))?;
        calibrate::calibrate(m, text, trace, &o)
    })())
}

/// Calibrate's options at and beyond their limits (the calibrate rows of
/// `tests/data/option_limits.toml`): the CLI and the job layer the Python binding calls accept
/// or refuse each alike, with the same message (python/tests/test_drift.py: `Model.calibrate`).
/// Studies do not calibrate: no study front end applies.
#[test]
fn calibrate_accepts_and_refuses_alike_from_the_cli_and_the_job_layer() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut refused, mut accepted) = (0, 0);
    for (k, (model, options, expect_accept)) in calibrate_rows().iter().enumerate() {
        let text = std::fs::read_to_string(root().join(model)).unwrap();
        let m = job::Model {
            file: PathBuf::from(model),
            ..job::Model::load(&root().join(model), &[]).unwrap()
        };
        let out = tmp.path().join(format!("c{k}"));
        let c = calibrate_cli(model, options, &out);
        let l = calibrate_library(&m, &text, options);
        assert_eq!(c, l, "calibrate row {k}: {options:?}: CLI vs job layer");
        match &c {
            Outcome::Refused(msg) => {
                assert!(!expect_accept, "calibrate row {k}: {options:?}: refused: {msg}");
                assert!(
                    !out.exists(),
                    "calibrate row {k}: refused but wrote {}",
                    out.display()
                );
                refused += 1;
            }
            _ => {
                assert!(expect_accept, "calibrate row {k}: {options:?}: accepted: {c:?}");
                accepted += 1;
            }
        }
    }
    eprintln!("calibrate: {accepted} rows accepted, {refused} refused alike by the CLI and the job layer");
    assert!(
        refused >= 30 && accepted >= 15,
        "{accepted} accepted, {refused} refused"
    );
}
