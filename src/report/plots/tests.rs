//! Render synthetic run/map/bench directories and decode every PNG.

use std::fmt::Write as _;
use std::fs;
use std::path::Path;

use super::*;

/// Decode a PNG; return (width, height, variance of the grey level).
fn decode(path: &Path) -> (u32, u32, f64) {
    let file = fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let decoder = png::Decoder::new(file);
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png frame");
    let bpp = info.color_type.samples();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let px = &buf[..info.buffer_size()];
    let n = px.len() / bpp;
    let grey = |k: usize| {
        px[k * bpp..k * bpp + bpp.min(3)]
            .iter()
            .map(|&c| c as f64)
            .sum::<f64>()
            / bpp.min(3) as f64
    };
    let mean = (0..n).map(grey).sum::<f64>() / n as f64;
    let var = (0..n).map(|k| (grey(k) - mean).powi(2)).sum::<f64>() / n as f64;
    (info.width, info.height, var)
}

fn assert_png_ok(path: &Path) {
    let (w, h, var) = decode(path);
    assert_eq!((w, h), (1600, 1000), "{}", path.display());
    // A white page with a few axis lines has a variance of a few tens; real figures far more.
    assert!(var > 150.0, "{} looks blank (variance {var})", path.display());
}

/// Distinct-count of colours in a PNG (rough check that colour was used).
fn colour_count(path: &Path) -> usize {
    let decoder = png::Decoder::new(fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.color_type.samples();
    let mut set = std::collections::HashSet::new();
    for p in buf[..info.buffer_size()].chunks(bpp) {
        set.insert((p[0], p[1], p[2]));
    }
    set.len()
}

struct RunSpec {
    rows: usize,
    nodes: usize,
    items: usize,
    zero_losses: bool,
    constant: bool,
    with_gaps: bool,
}

impl Default for RunSpec {
    fn default() -> Self {
        RunSpec {
            rows: 300,
            nodes: 5,
            items: 6,
            zero_losses: false,
            constant: false,
            with_gaps: false,
        }
    }
}

const SOURCES: [&str; 3] = ["churning", "pocketing", "sliding"];

/// Write a run directory in the documented format.
fn write_run(dir: &Path, spec: &RunSpec) {
    let node_names: Vec<String> = (0..spec.nodes)
        .map(|k| match k {
            0 => "oil_sump".to_string(),
            1 => "ambient".to_string(),
            _ => format!("node_{k}"),
        })
        .collect();
    let items: Vec<(usize, String)> = (0..spec.items)
        .map(|k| (k % 3, format!("{}_gear_{}", ["g1", "mesh_a", "shaft"][k % 3], k)))
        .collect();
    let mut csv =
        String::from("time_s,vehicle_speed_kmh,gear,input_speed_rpm,input_torque_nm,output_power_w");
    for n in &node_names {
        let _ = write!(csv, ",temp_{n}_c");
    }
    for (s, n) in &items {
        let _ = write!(csv, ",loss_{}_{n}_w", SOURCES[*s]);
    }
    csv.push_str(",loss_churning_w,loss_pocketing_w,loss_sliding_w,loss_total_w,efficiency\n");
    let mut t: f64 = 0.0;
    for r in 0..spec.rows {
        // Non-uniform spacing: 1 s, with some 0.5 s steps.
        t += if r == 0 {
            0.0
        } else if r % 7 == 0 {
            0.5
        } else {
            1.0
        };
        let phase: f64 = t / 60.0;
        let speed = if spec.constant {
            50.0
        } else {
            (60.0 * phase.sin().abs()).max(0.0)
        };
        let gear = if speed < 1.0 {
            "N".to_string()
        } else {
            format!("{}", 1 + (speed / 15.0) as i32)
        };
        let gear = if !spec.constant && r % 97 == 5 {
            "R".to_string()
        } else {
            gear
        };
        let out_power = speed * 300.0;
        let _ = write!(csv, "{t},{speed},{gear},{},{},{out_power}", speed * 50.0, 100.0);
        for k in 0..spec.nodes {
            let v = if k == 1 || spec.constant {
                25.0
            } else {
                25.0 + (60.0 + 3.0 * k as f64) * (1.0 - (-t / 600.0).exp())
            };
            if spec.with_gaps && k == 2 && r % 50 == 10 {
                csv.push(',');
            } else {
                let _ = write!(csv, ",{v}");
            }
        }
        let mut by_src = [0.0; 3];
        for (k, (s, _)) in items.iter().enumerate() {
            let p = if spec.zero_losses {
                0.0
            } else {
                (5.0 + k as f64) * (1.0 + speed / 20.0) * (1.0 + *s as f64)
            };
            by_src[*s] += p;
            if spec.with_gaps && k == 0 && r % 40 == 3 {
                // A gap is an empty cell (`NaN` and `inf` cells are rejected: never written).
                csv.push(',');
            } else {
                let _ = write!(csv, ",{p}");
            }
        }
        let total: f64 = by_src.iter().sum();
        let eff = if out_power > 0.0 {
            format!("{}", out_power / (out_power + total))
        } else {
            String::new()
        };
        let _ = writeln!(csv, ",{},{},{},{total},{eff}", by_src[0], by_src[1], by_src[2]);
    }
    fs::write(dir.join("timeseries.csv"), csv).unwrap();

    let nodes_json: Vec<String> = node_names
        .iter()
        .map(|n| format!(r#"{{"name":"{n}","boundary":{}}}"#, n == "ambient"))
        .collect();
    let temps_json: Vec<String> = node_names
        .iter()
        .map(|n| format!(r#""{n}":{{"min":25.0,"max":80.0,"final":79.0}}"#))
        .collect();
    let items_json: Vec<String> = items
        .iter()
        .enumerate()
        .map(|(k, (s, n))| {
            let j = if spec.zero_losses {
                0.0
            } else {
                1000.0 * (k + 1) as f64
            };
            format!(r#"{{"source":"{}","name":"{n}","j":{j}}}"#, SOURCES[*s])
        })
        .collect();
    let summary = format!(
        r#"{{"model":"test box","cycle":"WLTC-like","solver":"bdf","rtol":1e-6,"atol":1e-6,"wall_time_s":0.42,
        "steps":1234,"energy_lost_j":{{"churning":1.0e5,"pocketing":5.0e4,"sliding":2.0e5,"total":3.5e5}},
        "energy_by_item_j":[{}],"energy_balance_relative":2.5e-7,"cycle_efficiency":0.962,
        "temperatures_c":{{{}}},"nodes":[{}],"oil_node":"oil_sump",
        "skipped":[{{"what":"gear g5","why":"never engaged in this cycle"}}],"extra_key":{{"x":1}}}}"#,
        items_json.join(","),
        temps_json.join(","),
        nodes_json.join(",")
    );
    fs::write(dir.join("summary.json"), summary).unwrap();
}

fn check_run(dir: &Path) {
    let paths = render_run_dir(dir).unwrap_or_else(|e| panic!("render_run: {e}"));
    assert_eq!(paths.len(), 5);
    for name in ["temperatures.png", "losses.png", "energy.png", "efficiency.png"] {
        let p = dir.join(name);
        assert!(paths.contains(&p));
        assert_png_ok(&p);
    }
    let md = fs::read_to_string(dir.join("report.md")).unwrap();
    for needle in [
        "temperatures.png",
        "losses.png",
        "energy.png",
        "efficiency.png",
        "Skipped",
    ] {
        assert!(md.contains(needle), "report.md lacks {needle}");
    }
    assert_no_temp_files(dir);
}

fn assert_no_temp_files(dir: &Path) {
    for e in fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(!name.starts_with('.'), "temporary file left behind: {name}");
    }
}

#[test]
fn run_report_renders() {
    let dir = tempfile::tempdir().unwrap();
    write_run(dir.path(), &RunSpec::default());
    check_run(dir.path());
    // Source colours are used: the losses figure has many colours, the report names the sources.
    assert!(colour_count(&dir.path().join("losses.png")) > 20);
    let md = fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(md.contains("| churning | 100.0 | 28.6 % |"), "{md}");
    assert!(md.contains("96.20 %"));
    assert!(md.contains("gear g5"));
}

#[test]
fn run_edge_cases_do_not_panic() {
    let specs = [
        RunSpec {
            rows: 1,
            ..Default::default()
        },
        RunSpec {
            rows: 2,
            ..Default::default()
        },
        RunSpec {
            constant: true,
            ..Default::default()
        },
        RunSpec {
            zero_losses: true,
            ..Default::default()
        },
        RunSpec {
            with_gaps: true,
            ..Default::default()
        },
        RunSpec {
            nodes: 0,
            items: 0,
            ..Default::default()
        },
        RunSpec {
            nodes: 45,
            items: 70,
            rows: 50,
            ..Default::default()
        },
    ];
    for spec in &specs {
        let dir = tempfile::tempdir().unwrap();
        write_run(dir.path(), spec);
        check_run(dir.path());
    }
}

#[test]
fn efficiency_never_defined_and_minimal_summary() {
    let dir = tempfile::tempdir().unwrap();
    let csv = "time_s,vehicle_speed_kmh,gear,input_speed_rpm,input_torque_nm,output_power_w,temp_oil_c,\
               loss_churning_w,loss_pocketing_w,loss_sliding_w,loss_total_w,efficiency\n\
               0,0,N,800,0,0,20,0,0,0,0,\n10,0,N,800,0,0,21,1,0,0,1,\n20,0,N,800,0,0,22,1,0,0,1,\n";
    fs::write(dir.path().join("timeseries.csv"), csv).unwrap();
    fs::write(dir.path().join("summary.json"), "{}").unwrap();
    check_run(dir.path());
}

#[test]
fn malformed_csv_names_the_file_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    write_run(
        dir.path(),
        &RunSpec {
            rows: 20,
            ..Default::default()
        },
    );
    // A previous good result must survive a failed render.
    fs::write(dir.path().join("temperatures.png"), b"previous").unwrap();
    let path = dir.path().join("timeseries.csv");
    let mut text = fs::read_to_string(&path).unwrap();
    text.push_str("1000,abc,3\n");
    fs::write(&path, &text).unwrap();
    let err = render_run_dir(dir.path()).unwrap_err();
    assert!(err.to_string().contains("timeseries.csv"), "{err}");
    assert!(matches!(err, PlotError::Csv { .. }), "{err:?}");
    assert_eq!(
        fs::read(dir.path().join("temperatures.png")).unwrap(),
        b"previous"
    );
    assert!(!dir.path().join("losses.png").exists());
    assert_no_temp_files(dir.path());

    // A non-numeric value with the right field count.
    let fixed: Vec<&str> = text.lines().collect();
    let mut bad = fixed[..fixed.len() - 1].join("\n");
    let last = fixed[fixed.len() - 2].replacen(',', ",fast_", 1);
    bad.push('\n');
    bad.push_str(&last);
    bad.push('\n');
    fs::write(&path, bad).unwrap();
    let err = render_run_dir(dir.path()).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("timeseries.csv") && msg.contains("vehicle_speed_kmh"),
        "{msg}"
    );

    // Missing required column.
    fs::write(&path, "time_s,gear\n0,1\n").unwrap();
    let err = render_run_dir(dir.path()).unwrap_err();
    assert!(err.to_string().contains("timeseries.csv"), "{err}");

    // Malformed JSON.
    write_run(
        dir.path(),
        &RunSpec {
            rows: 5,
            ..Default::default()
        },
    );
    fs::write(dir.path().join("summary.json"), "{\"model\": ").unwrap();
    let err = render_run_dir(dir.path()).unwrap_err();
    assert!(err.to_string().contains("summary.json"), "{err}");
    assert_no_temp_files(dir.path());
}

fn write_map(dir: &Path, nx: usize, ny: usize, shuffle: bool) {
    let mut rows = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let n = 500.0 + 5500.0 * i as f64 / (nx.max(2) - 1) as f64;
            let t = 20.0 * j as f64 / (ny.max(2) - 1) as f64 * 10.0;
            let loss = 20.0 + 0.01 * n + 0.002 * n * t.sqrt();
            let p_in = crate::physics::units::rpm_to_rad_s(n) * t;
            let eff = if p_in > 0.0 {
                format!("{}", (p_in - loss).max(0.0) / p_in)
            } else {
                String::new()
            };
            let converged = !(i == nx / 2 && j == ny / 3);
            let oil = 40.0 + 0.4 * loss.sqrt() * 3.0;
            rows.push(format!(
                "{n},{t},{eff},{loss},{},{},{},{oil},{},{converged}",
                0.5 * loss,
                0.2 * loss,
                0.3 * loss,
                3 + i % 4
            ));
        }
    }
    if shuffle {
        rows.reverse();
        let k = rows.len() / 3;
        rows.swap(0, k);
    }
    // Leave one grid point out entirely.
    if rows.len() > 4 {
        rows.remove(1);
    }
    let mut csv = String::from(
        "speed_rpm,torque_nm,efficiency,loss_total_w,loss_churning_w,loss_pocketing_w,loss_sliding_w,oil_temp_c,iterations,converged\n",
    );
    for r in rows {
        csv.push_str(&r);
        csv.push('\n');
    }
    fs::write(dir.join("map.csv"), csv).unwrap();
    fs::write(
        dir.join("map.json"),
        r#"{"model":"test box","gear":"3","other":[1,2]}"#,
    )
    .unwrap();
}

#[test]
fn maps_render() {
    for (nx, ny, shuffle) in [(30, 25, true), (6, 5, false), (1, 1, false), (1, 4, false)] {
        let dir = tempfile::tempdir().unwrap();
        write_map(dir.path(), nx, ny, shuffle);
        let paths = render_map_dir(dir.path()).unwrap_or_else(|e| panic!("{nx}x{ny}: {e}"));
        assert_eq!(paths.len(), 4, "three heat maps and report.md");
        let md = fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(
            md.contains("map_oil_temp.png") && md.contains("Converged points"),
            "{md}"
        );
        for name in ["map_efficiency.png", "map_total_loss.png", "map_oil_temp.png"] {
            assert_png_ok(&dir.path().join(name));
        }
        assert_no_temp_files(dir.path());
    }
}

#[test]
fn malformed_map_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    write_map(dir.path(), 4, 4, false);
    let p = dir.path().join("map.csv");
    let mut t = fs::read_to_string(&p).unwrap();
    t.push_str("100,5,0.9,1,1,1,1,40,3,maybe\n");
    fs::write(&p, t).unwrap();
    let err = render_map_dir(dir.path()).unwrap_err();
    assert!(err.to_string().contains("map.csv"), "{err}");
    assert_no_temp_files(dir.path());
}

#[test]
fn contour_of_a_plane_is_straight() {
    // z = x on a 3×3 grid: the level-1.5 contour is the vertical line x = 1.5.
    let xs = [0.0, 1.0, 2.0];
    let ys = [0.0, 1.0, 2.0];
    let z: Vec<f64> = (0..9).map(|k| (k % 3) as f64).collect();
    let segs = heatmap::contour_segments(&xs, &ys, &z, 1.5);
    assert_eq!(segs.len(), 2);
    for s in segs {
        for p in s {
            assert!((p.0 - 1.5).abs() < 1e-12);
        }
    }
    let edges = heatmap::cell_edges(&[0.0, 1.0, 3.0]);
    assert_eq!(edges, vec![-0.5, 0.5, 2.0, 4.0]);
}

fn write_bench(dir: &Path) {
    let mut csv = String::from(
        "solver,rtol,atol,wall_time_s,steps,rejected,rhs_evals,jac_evals,lu_count,err_final_k,err_max_k,err_rms_k,energy_balance_relative,default\n",
    );
    for (s, (name, cost, order)) in [
        ("bdf", 0.05f64, 1.0f64),
        ("esdirk34", 0.08, 3.0),
        ("tr_bdf2", 0.06, 2.0),
    ]
    .iter()
    .enumerate()
    {
        for k in 3..=10 {
            let rtol = 10f64.powi(-k);
            let err = 50.0 * rtol.powf(1.0 / order.max(1.0) * 0.9) * (1.0 + s as f64);
            let time = cost * (1.0 / rtol).powf(0.25 / order);
            let default = *name == "bdf" && k == 6;
            let _ = writeln!(
                csv,
                "{name},{rtol},{rtol},{time},{},0,{},{},{},{err},{err},{},{},{default}",
                100 * k,
                500 * k,
                10 * k,
                10 * k,
                err / 2.0,
                rtol
            );
        }
    }
    // A zero-error row (reference itself) and a missing wall time.
    csv.push_str("bdf,1e-12,1e-12,3.0,9000,0,1,1,1,0,0,0,0,false\n");
    csv.push_str("radau,1e-6,1e-6,,1,0,1,1,1,0.1,0.1,0.1,0,false\n");
    fs::write(dir.join("bench.csv"), csv).unwrap();
    fs::write(
        dir.join("bench.json"),
        r#"{"model":"test box","cycle":"WLTC-like"}"#,
    )
    .unwrap();
}

#[test]
fn bench_renders() {
    let dir = tempfile::tempdir().unwrap();
    write_bench(dir.path());
    let p = render_bench_dir(dir.path()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(p, dir.path().join("work_precision.png"));
    assert_png_ok(&p);
    assert_no_temp_files(dir.path());
}

#[test]
fn performance_large_run() {
    let dir = tempfile::tempdir().unwrap();
    write_run(
        dir.path(),
        &RunSpec {
            rows: 1800,
            nodes: 20,
            items: 30,
            ..Default::default()
        },
    );
    let start = std::time::Instant::now();
    check_run(dir.path());
    let secs = start.elapsed().as_secs_f64();
    eprintln!("render_run, 1800 rows × 20 nodes × 30 items: {secs:.3} s");
    assert!(secs < 20.0, "too slow: {secs} s");
}

/// Writes sample figures to $GEARTHERM_PLOT_SAMPLES for visual inspection (ignored by default).
#[test]
#[ignore]
fn write_samples() {
    let Ok(out) = std::env::var("GEARTHERM_PLOT_SAMPLES") else {
        return;
    };
    let out = Path::new(&out);
    for (name, spec) in [
        (
            "run",
            RunSpec {
                rows: 1800,
                nodes: 12,
                items: 14,
                with_gaps: true,
                ..Default::default()
            },
        ),
        (
            "run_big",
            RunSpec {
                rows: 1800,
                nodes: 20,
                items: 30,
                ..Default::default()
            },
        ),
        (
            "run_one",
            RunSpec {
                rows: 1,
                ..Default::default()
            },
        ),
    ] {
        let d = out.join(name);
        fs::create_dir_all(&d).unwrap();
        write_run(&d, &spec);
        render_run_dir(&d).unwrap();
    }
    let extra = [
        (
            "run_many",
            RunSpec {
                rows: 50,
                nodes: 45,
                items: 70,
                ..Default::default()
            },
        ),
        (
            "run_zero",
            RunSpec {
                zero_losses: true,
                items: 1,
                ..Default::default()
            },
        ),
    ];
    for (name, spec) in extra {
        let d = out.join(name);
        fs::create_dir_all(&d).unwrap();
        write_run(&d, &spec);
        render_run_dir(&d).unwrap();
    }
    for (name, nx, ny) in [("map", 30, 25), ("map_small", 6, 5)] {
        let d = out.join(name);
        fs::create_dir_all(&d).unwrap();
        write_map(&d, nx, ny, true);
        render_map_dir(&d).unwrap();
    }
    let d = out.join("bench");
    fs::create_dir_all(&d).unwrap();
    write_bench(&d);
    render_bench_dir(&d).unwrap();
}

#[test]
fn table_numbers_fit_their_cells() {
    use style::{fmt_fixed, fmt_share};
    assert_eq!(fmt_fixed(81.14, 1), "81.1");
    assert_eq!(fmt_fixed(1809.0, 0), "1809");
    assert_eq!(fmt_fixed(1e300, 1), "1.000e300");
    assert_eq!(fmt_fixed(f64::INFINITY, 1), "–");
    assert_eq!(fmt_share(54.79, 324.4), format!("{:.1} %", 100.0 * 54.79 / 324.4));
    // 100·part overflows; the share does not.
    assert_eq!(fmt_share(1e308, 1e308), "100.0 %");
    assert_eq!(fmt_share(1e300, 1e-3), "1.000e305 %");
    assert_eq!(fmt_share(1e308, 1e-3), "–");
    assert_eq!(fmt_share(1.0, 0.0), "–");
    assert_eq!(fmt_share(f64::NAN, 1.0), "–");
}
