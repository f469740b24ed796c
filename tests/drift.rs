//! One pipeline, three front ends: every row of `tests/data/option_limits.toml` (inputs at and
//! beyond every job option's limits) is sent through the CLI, a study case and the job layer
//! that the Python binding calls (python/tests/test_drift.py sends it through Python itself);
//! each must accept or refuse it alike, with the same message.

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::job::{self, LossesOptions, RatingOptions, RunOptions, SteadyOptions};
use geartherm::study::spec::{JobSpec, Meta, OutputSpec, ParamSpec, Sampling, StudySpec};
use geartherm::study::{ParamValue, Study, StudyError};
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
    let msg = String::from_utf8_lossy(&o.stderr).trim().to_string();
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
        }],
        outputs: OutputSpec::default(),
    };
    let s = match Study::new(spec, text.to_string(), root().join(MODEL)) {
        Ok(s) => s,
        Err(StudyError::Job(e)) => {
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
