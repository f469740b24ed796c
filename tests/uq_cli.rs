//! `geartherm uq` end to end on a linear network with a closed-form answer, a calibration's
//! covariance sampled as a multivariate normal, and bad distributions refused (exit 1, the key
//! path named, nothing written).

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::report::uq::{read_bands_csv, UqSummary};
use geartherm::study::uq::stats::normal_cdf;

const BIN: &str = env!("CARGO_BIN_EXE_geartherm");

/// The PT6 spur pair's gears and lubrication with one capacity node (C = 2000 J/K, starting at
/// 10 °C) linked to the ambient (G1 = 3 W/K) and to a coolant (G2 = 1 W/K): at standstill no
/// loss heats it, so C dT/dt = G1 (Ta − T) + G2 (Tc − T), linear in the two boundary
/// temperatures: T(t) = T∞ + (T0 − T∞) e^(−t/τ), T∞ = (G1 Ta + G2 Tc)/(G1 + G2), τ = C/(G1 + G2)
/// = 500 s. With Ta ~ N(20, 2²) and Tc ~ N(60, 4²) independent, T(t) is normal with mean
/// m(t) = m∞ + (T0 − m∞) e^(−t/τ), m∞ = 30 °C, and sd s(t) = (1 − e^(−t/τ)) s∞,
/// s∞ = √((0.75·2)² + (0.25·4)²).
fn linear_model(uncertainty: &str) -> String {
    let pt6 =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("models/pt6_spur_pair.toml"))
            .unwrap();
    let head = &pt6[..pt6.find("\n[thermal]").unwrap()];
    format!(
        "{head}\n[thermal]\noil_node = \"oil\"\ninitial_temp_c = 10.0\n\n[[thermal.nodes]]\nname = \"oil\"\ncapacity_j_per_k = 2000.0\n\n\
         [[thermal.boundaries]]\nname = \"ambient\"\ntemp_c = 20.0\n\n[[thermal.boundaries]]\nname = \"coolant\"\ntemp_c = 60.0\n\n\
         [[thermal.links]]\nname = \"oil-air\"\nbetween = [\"oil\", \"ambient\"]\nconductance_w_per_k = 3.0\n\n\
         [[thermal.links]]\nname = \"oil-coolant\"\nbetween = [\"oil\", \"coolant\"]\nconductance_w_per_k = 1.0\n\n{uncertainty}"
    )
}

const NORMAL_INPUTS: &str = "[[uncertainty.inputs]]\npath = 'thermal.boundaries[\"ambient\"].temp_c'\ndist = \"normal\"\nmean = 20.0\nsd = 2.0\n\n\
     [[uncertainty.inputs]]\npath = 'thermal.boundaries[\"coolant\"].temp_c'\ndist = \"normal\"\nmean = 60.0\nsd = 4.0\n";

/// A rig cycle at standstill, 1000 s.
fn standstill(dir: &Path) -> PathBuf {
    let mut s = String::from("time_s,input_speed_rpm,input_torque_nm,gear\n");
    for k in 0..=100 {
        s.push_str(&format!("{},0,0,1\n", k * 10));
    }
    let f = dir.join("standstill.csv");
    std::fs::write(&f, s).unwrap();
    f
}

fn setup(uncertainty: &str) -> (tempfile::TempDir, PathBuf, PathBuf) {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("linear.toml");
    std::fs::write(&m, linear_model(uncertainty)).unwrap();
    let c = standstill(d.path());
    (d, m, c)
}

fn uq(model: &Path, args: &[&str]) -> std::process::Output {
    Command::new(BIN)
        .arg("uq")
        .arg(model)
        .args(args)
        .arg("--quiet")
        .output()
        .unwrap()
}

const S_INF: f64 = 1.802_775_637_731_994_6; // √(1.5² + 1²)

fn analytic(t: f64) -> (f64, f64) {
    let e = (-t / 500.0).exp();
    (30.0 + (10.0 - 30.0) * e, (1.0 - e) * S_INF)
}

#[test]
fn bands_and_exceedance_of_a_linear_network_match_the_normal_distribution() {
    let (d, m, cycle) = setup(NORMAL_INPUTS);
    let out = d.path().join("out");
    let (m_end, s_end) = analytic(1000.0);
    let limit = m_end + s_end; // P = 1 − Φ(1) ≈ 0.159
    let o = uq(
        &m,
        &[
            "--cycle",
            cycle.to_str().unwrap(),
            "--samples",
            "1024",
            "--percentiles",
            "5,50,95",
            "--limit",
            &format!("oil={limit}"),
            "--rtol",
            "1e-8",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bands = read_bands_csv(&std::fs::read_to_string(out.join("bands.csv")).unwrap()).unwrap();
    let oil = bands
        .series
        .iter()
        .find(|s| s.name == "oil" && s.unit == "°C")
        .unwrap();
    let z95 = 1.644_853_626_951_472_2;
    let mut worst: f64 = 0.0;
    for (k, &t) in bands.time_s.iter().enumerate() {
        let (mean, sd) = analytic(t);
        for (p, q, z) in [(0, 0.05f64, -z95), (1, 0.5, 0.0), (2, 0.95, z95)] {
            let err = (oil.values[p][k] - (mean + z * sd)).abs();
            // Twice the standard error of a sample percentile of 1024 independent draws,
            // √(q(1 − q)/n)/φ(z)·sd (scrambled Sobol' points do at least as well), plus the
            // journal's rounding and the integration's error.
            let phi = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
            let tol = 2.0 * (q * (1.0 - q) / 1024.0).sqrt() / phi * sd + 2e-3;
            assert!(
                err < tol,
                "t = {t}: p{p} {} vs {} (tolerance {tol})",
                oil.values[p][k],
                mean + z * sd
            );
            worst = worst.max(err / sd.max(1e-9));
        }
    }
    eprintln!("largest band error {worst:.4} sd (sd at the end {s_end:.3} K)");
    let s = UqSummary::from_json(&std::fs::read_to_string(out.join("uq.json")).unwrap()).unwrap();
    let e = &s.exceedance[0];
    let exact = 1.0 - normal_cdf(1.0);
    eprintln!(
        "P(T > {limit:.3}) = {} [{}, {}], exact {exact:.4}",
        e.probability, e.lo, e.hi
    );
    assert!(
        (e.probability - exact).abs() < 0.02,
        "{} vs {exact}",
        e.probability
    );
    assert!(e.lo <= exact && exact <= e.hi);
    // Resume: the same command again solves nothing and writes the same bands.
    let again = uq(
        &m,
        &[
            "--cycle",
            cycle.to_str().unwrap(),
            "--samples",
            "1024",
            "--limit",
            &format!("oil={limit}"),
            "--rtol",
            "1e-8",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let text = String::from_utf8_lossy(&again.stdout);
    assert!(
        text.contains("0 samples solved") && text.contains("1024 already done"),
        "{text}"
    );
}

#[test]
fn a_calibrations_covariance_is_sampled_as_a_multivariate_normal() {
    let (d, m, cycle) = setup("");
    let cal = d.path().join("calibrated.toml");
    // As `geartherm calibrate` writes it: ln G1, ln G2 with sd 0.1 and 0.2, correlation 0.2.
    std::fs::write(
        &cal,
        "[model]\nname = \"x\"\n\n# The fitted parameters' covariance ...\n# [calibration]\n\
         # parameters = [\"thermal.links[\\\"oil-air\\\"].conductance_w_per_k\", \"thermal.links[\\\"oil-coolant\\\"].conductance_w_per_k\"]\n\
         # scale = [\"log\", \"log\"]\n# value = [3.0, 1.0]\n# covariance = [[0.01, 0.004], [0.004, 0.04]]\n",
    )
    .unwrap();
    let out = d.path().join("out");
    let o = uq(
        &m,
        &[
            "--cycle",
            cycle.to_str().unwrap(),
            "--samples",
            "1024",
            "--from-calibration",
            cal.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = csv::Reader::from_path(out.join("study.csv")).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (a, b) = (
        col("thermal.links[\"oil-air\"].conductance_w_per_k"),
        col("thermal.links[\"oil-coolant\"].conductance_w_per_k"),
    );
    let rows: Vec<(f64, f64)> = r
        .records()
        .map(|x| {
            let x = x.unwrap();
            (
                x[a].parse::<f64>().unwrap().ln(),
                x[b].parse::<f64>().unwrap().ln(),
            )
        })
        .collect();
    let n = rows.len() as f64;
    let (ma, mb) = (
        rows.iter().map(|r| r.0).sum::<f64>() / n,
        rows.iter().map(|r| r.1).sum::<f64>() / n,
    );
    let cov = |f: &dyn Fn(&(f64, f64)) -> f64| rows.iter().map(f).sum::<f64>() / (n - 1.0);
    let vaa = cov(&|r| (r.0 - ma).powi(2));
    let vbb = cov(&|r| (r.1 - mb).powi(2));
    let vab = cov(&|r| (r.0 - ma) * (r.1 - mb));
    eprintln!("means {ma:.4} {mb:.4}, cov [[{vaa:.5}, {vab:.5}], [{vab:.5}, {vbb:.5}]]");
    assert_eq!(rows.len(), 1024);
    assert!((ma - 3f64.ln()).abs() < 0.01 && mb.abs() < 0.02);
    assert!((vaa / 0.01 - 1.0).abs() < 0.15 && (vbb / 0.04 - 1.0).abs() < 0.15);
    assert!((vab / (vaa * vbb).sqrt() - 0.2).abs() < 0.08);
    // The bands widen: the conductances move T∞ only through the weights.
    let s = UqSummary::from_json(&std::fs::read_to_string(out.join("uq.json")).unwrap()).unwrap();
    assert!(s.inputs.iter().all(|i| i.distribution.starts_with("calibrated")));
}

/// A bad `[uncertainty]`: exit 1, the message names `what`, no output directory.
fn refused(uncertainty: &str, extra: &[&str], what: &str) {
    let (d, m, cycle) = setup(uncertainty);
    let out = d.path().join("out");
    let mut args = vec!["--cycle", cycle.to_str().unwrap(), "--out", out.to_str().unwrap()];
    if !extra.contains(&"--samples") {
        args.extend(["--samples", "16"]);
    }
    args.extend_from_slice(extra);
    let o = uq(&m, &args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(what), "`{what}` not in: {err}");
    assert!(!out.exists(), "{err}");
    // A problem of the model file's own `[uncertainty]`: `check` reports it the same way.
    if extra.is_empty() {
        let o = Command::new(BIN).arg("check").arg(&m).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "check: {err}");
        assert!(err.contains(what), "check: `{what}` not in: {err}");
    }
}

#[test]
fn check_reports_every_problem_of_the_section_at_once() {
    let amb = "thermal.boundaries[\"ambient\"].temp_c";
    let cap = "thermal.nodes[\"oil\"].capacity_j_per_k";
    let (_d, m, _) = setup(&format!(
        "[uncertainty]\nsamples = 0\n{}{}{}",
        input(amb, "dist = \"lognormal\"\nmedian = 20.0\nsigma_ln = 0.1"),
        input(cap, "dist = \"normal\"\nmean = 2000.0\nsd = 2000.0"),
        input(
            "thermal.links[\"oil-air\"].conductance_w_per_k",
            "dist = \"uniform\"\nlo = 4.0\nhi = 2.0"
        ),
    ));
    let o = Command::new(BIN).arg("check").arg(&m).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    for what in [
        "uncertainty.samples = 0: must lie in [1, 1000000]",
        "uncertainty.inputs[0].dist = \"lognormal\": a log-normal on a value that may be negative",
        "uncertainty.inputs[1] = ",
        "the model refuses this value of thermal.nodes[\"oil\"].capacity_j_per_k",
        "uncertainty.inputs[2].hi = 2: must be > lo = 4 (bounds reversed)",
        "4 problem(s)",
    ] {
        assert!(err.contains(what), "`{what}` not in: {err}");
    }
    assert!(o.stdout.is_empty());
}

#[test]
fn check_accepts_good_uncertain_inputs_and_uq_takes_their_sample_count() {
    let g = "thermal.links[\"oil-air\"].conductance_w_per_k";
    let (d, m, cycle) = setup(&format!(
        "[uncertainty]\nsamples = 8\n{}",
        input(g, "dist = \"uniform\"\nlo = 2.0\nhi = 4.0")
    ));
    let o = Command::new(BIN).arg("check").arg(&m).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = d.path().join("out");
    let o = uq(
        &m,
        &["--cycle", cycle.to_str().unwrap(), "--out", out.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = UqSummary::from_json(&std::fs::read_to_string(out.join("uq.json")).unwrap()).unwrap();
    assert_eq!(s.samples, 8, "uncertainty.samples is the default of --samples");
}

fn input(path: &str, body: &str) -> String {
    format!("[[uncertainty.inputs]]\npath = '{path}'\n{body}\n")
}

#[test]
fn bad_distributions_are_refused_naming_the_key_path_and_nothing_is_written() {
    let amb = "thermal.boundaries[\"ambient\"].temp_c";
    let g = "thermal.links[\"oil-air\"].conductance_w_per_k";
    // Negative width (sd).
    refused(
        &input(amb, "dist = \"normal\"\nmean = 20.0\nsd = -1.0"),
        &[],
        &format!("uncertainty.inputs[0].sd = -1: must be > 0 (normal on {amb})"),
    );
    // Bounds reversed.
    refused(
        &input(g, "dist = \"uniform\"\nlo = 4.0\nhi = 2.0"),
        &[],
        &format!("uncertainty.inputs[0].hi = 2: must be > lo = 4 (bounds reversed) (uniform on {g})"),
    );
    refused(
        &input(
            g,
            "dist = \"normal\"\nmean = 3.0\nsd = 0.5\ntruncate = [4.0, 2.0]",
        ),
        &[],
        "uncertainty.inputs[0].truncate[1] = 2: must be > lo = 4 (bounds reversed)",
    );
    // A log-normal on a value that may be negative (a temperature in °C).
    refused(
        &input(amb, "dist = \"lognormal\"\nmedian = 20.0\nsigma_ln = 0.1"),
        &[],
        "uncertainty.inputs[0].dist = \"lognormal\": a log-normal on a value that may be negative",
    );
    // A distribution reaching values the model refuses (a negative conductance).
    refused(
        &input(g, "dist = \"normal\"\nmean = 3.0\nsd = 2.0"),
        &[],
        &format!("the model refuses this value of {g}"),
    );
    // Correlations not positive definite.
    let three = format!(
        "{}{}{}",
        input(amb, "dist = \"normal\"\nmean = 20.0\nsd = 1.0"),
        input(
            "thermal.boundaries[\"coolant\"].temp_c",
            "dist = \"normal\"\nmean = 60.0\nsd = 1.0"
        ),
        input(g, "dist = \"uniform\"\nlo = 2.0\nhi = 4.0"),
    );
    let corr = |a: &str, b: &str, r: f64| {
        format!("[[uncertainty.correlations]]\nbetween = ['{a}', '{b}']\nrank = {r}\n")
    };
    let bad = format!(
        "{three}{}{}{}",
        corr(amb, "thermal.boundaries[\"coolant\"].temp_c", 0.9),
        corr(amb, g, 0.9),
        corr("thermal.boundaries[\"coolant\"].temp_c", g, -0.9)
    );
    refused(
        &bad,
        &[],
        "uncertainty.correlations: the rank correlation matrix is not",
    );
    // A key path that does not exist.
    refused(
        &input(
            "thermal.links[\"nope\"].conductance_w_per_k",
            "dist = \"uniform\"\nlo = 2.0\nhi = 4.0",
        ),
        &[],
        "uncertainty.inputs[0].path = 'thermal.links[\"nope\"].conductance_w_per_k': not a key path of the model",
    );
    refused(
        &input(
            "thermal.links[\"oil-air\"].conductance",
            "dist = \"uniform\"\nlo = 2.0\nhi = 4.0",
        ),
        &[],
        "uncertainty.inputs[0].path = 'thermal.links[\"oil-air\"].conductance': not a key path of the model",
    );
    // Sample counts of 0 and over the limit.
    let ok = input(g, "dist = \"uniform\"\nlo = 2.0\nhi = 4.0");
    refused(
        &ok,
        &["--samples", "0"],
        "samples (--samples) = 0: must lie in [1, 1000000]",
    );
    refused(&ok, &["--samples", "1000001"], "samples (--samples) = 1000001");
    refused(&ok, &["--samples", "1000000", "--sobol"], "N(d + 2)");
    // The model file's own sample count.
    let zero = format!("[uncertainty]\nsamples = 0\n{ok}");
    refused(&zero, &[], "uncertainty.samples = 0: must lie in [1, 1000000]");
    let over = format!("[uncertainty]\nsamples = 1000001\n{ok}");
    refused(
        &over,
        &[],
        "uncertainty.samples = 1000001: must lie in [1, 1000000]",
    );
    // Options: a limit on a node the model lacks, percentiles out of order.
    refused(&ok, &["--limit", "sump=100"], "no thermal node `sump`");
    refused(&ok, &["--percentiles", "95,5"], "percentiles");
}
