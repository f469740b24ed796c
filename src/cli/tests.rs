//! The CLI's own tests: every job's options rendered as a command line (as `study --list`
//! prints it) parse back into the same options.

use std::path::Path;

use crate::job::command::{command_line, split, validate_line, ToArgs};
use crate::job::{
    BenchOptions, LossesOptions, MapOptions, RatingOptions, RunOptions, SteadyOptions, ValidateOptions,
};
use crate::model::Override;
use clap::Parser;

use super::{Cli, Command};

fn parse(line: &str) -> Command {
    let words = split(line).unwrap_or_else(|e| panic!("{line}: {e}"));
    Cli::try_parse_from(words)
        .unwrap_or_else(|e| panic!("{line}: {e}"))
        .command
}

fn overrides() -> Vec<Override> {
    [
        "lubrication.oil_level_mm = 55.5",
        "oil.catalogue = \"fva_3a\"",
        "thermal.links[\"housing-air\"].area_m2 = 0.9",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect()
}

fn line<T: ToArgs>(o: &T) -> String {
    command_line(Path::new("models/it's a model.toml"), &overrides(), o)
}

fn check_source(s: &super::ModelSource) {
    assert_eq!(s.model, Path::new("models/it's a model.toml"));
    assert_eq!(s.set, overrides());
}

#[test]
fn run_options_round_trip() {
    let all = [
        RunOptions::default(),
        RunOptions {
            cycle: "my cycles/rig 1.csv".into(),
            cycle_text: None,
            solver: "tr-bdf2".into(),
            rtol: 1.2345678901234e-7,
            atol: 3e-9,
            initial_temp_c: Some(-7.25),
            ambient_c: Some(-40.0),
            frozen_viscosity_c: Some(0.1 + 0.2),
            max_steps: 12345,
            summary_only: true,
            evaluate_all: true,
            spread: true,
        },
    ];
    for o in all {
        let l = line(&o);
        let Command::Run(a) = parse(&l) else { panic!("{l}") };
        check_source(&a.source);
        assert_eq!(a.options(), o, "{l}");
    }
}

#[test]
fn steady_options_round_trip() {
    for ambient_c in [None, Some(-12.5)] {
        let o = SteadyOptions {
            gear: "R".into(),
            speed_rpm: 1234.5,
            torque_nm: -250.125,
            vehicle_speed_kmh: 88.8,
            ambient_c,
        };
        let l = line(&o);
        let Command::Steady(a) = parse(&l) else {
            panic!("{l}")
        };
        check_source(&a.point.source);
        assert_eq!(a.options(), o, "{l}");
    }
}

#[test]
fn losses_options_round_trip() {
    let o = LossesOptions {
        gear: "3".into(),
        speed_rpm: 2500.0,
        torque_nm: 150.75,
        oil_temp_c: -20.5,
    };
    let l = line(&o);
    let Command::Losses(a) = parse(&l) else {
        panic!("{l}")
    };
    check_source(&a.source);
    assert_eq!(a.options(), o, "{l}");
}

#[test]
fn map_options_round_trip() {
    let o = MapOptions {
        gear: "6".into(),
        speed_rpm: vec![1000.0, 1500.5, 1.0 / 3.0],
        torque_nm: vec![-50.0, 0.0, 200.0],
        vehicle_speed_kmh: 0.0,
        ambient_c: Some(35.0),
    };
    let l = line(&o);
    let Command::Map(a) = parse(&l) else { panic!("{l}") };
    check_source(&a.point.source);
    assert_eq!(a.options().unwrap(), o, "{l}");
}

#[test]
fn rating_options_round_trip() {
    for (speeds, torque_max_nm, ambient_c) in [
        (vec![3000.0], None, None),
        (vec![0.0, 1234.5, 1.0 / 3.0], Some(450.25), Some(-20.5)),
    ] {
        let o = RatingOptions {
            gear: "D".into(),
            speed_rpm: speeds,
            oil_limit_c: 0.1 + 0.2,
            vehicle_speed_kmh: 55.5,
            ambient_c,
            torque_min_nm: 12.125,
            torque_max_nm,
        };
        let l = line(&o);
        let Command::Rating(a) = parse(&l) else {
            panic!("{l}")
        };
        check_source(&a.point.source);
        assert_eq!(a.options().unwrap(), o, "{l}");
    }
}

#[test]
fn bench_options_round_trip() {
    let o = BenchOptions {
        cycle: "nedc".into(),
        repeats: 5,
        min_rtol: 1e-8,
        solvers: vec!["ros3".into(), "bdf".into()],
        max_steps: 1000,
    };
    let l = line(&o);
    let Command::Bench(a) = parse(&l) else {
        panic!("{l}")
    };
    check_source(&a.source);
    assert_eq!(a.options(), o, "{l}");
}

#[test]
fn validate_options_round_trip() {
    let o = ValidateOptions {
        dir: "my cases/validation".into(),
    };
    let l = validate_line(&o);
    let Command::Validate(a) = parse(&l) else {
        panic!("{l}")
    };
    assert_eq!(a.options(), o, "{l}");
}

#[test]
fn calibrate_options_round_trip() {
    use crate::job::CalibrateOptions;
    let all = [
        CalibrateOptions {
            trace: "traces/rig 1.csv".into(),
            ..CalibrateOptions::default()
        },
        CalibrateOptions {
            trace: "t.csv".into(),
            fit: vec![
                "thermal.links[\"oil-housing\"].h_w_per_m2k=50:2000".into(),
                "thermal.nodes[\"oil\"].mass_kg".into(),
            ],
            holdout: vec!["0:600".into(), "3000:3600".into()],
            rtol: 1.25e-7,
            atol: 3e-9,
            max_steps: 1234,
            max_iterations: 7,
            initial_from_trace: false,
            segment: Some(2),
            refuse_missing: true,
            traces: Vec::new(),
            segments: None,
            residuals: "independent".into(),
            band_quantile: "t".into(),
            prior: vec!["thermal.nodes[\"oil\"].mass_kg=lognormal:2:0.5".into()],
            profile: vec!["thermal.nodes[\"oil\"].mass_kg".into()],
            gearbox_kind: Some("wind-turbine".into()),
            rated: Some("1680:-11600".into()),
        },
        CalibrateOptions {
            trace: "a.csv".into(),
            traces: vec!["b.csv".into()],
            fit: vec!["losses.multiplier.churning@*=0.1:10".into()],
            ..CalibrateOptions::default()
        },
        CalibrateOptions {
            trace: "a.csv".into(),
            segments: Some("0,2".into()),
            ..CalibrateOptions::default()
        },
    ];
    for o in all {
        let l = line(&o);
        let Command::Calibrate(a) = parse(&l) else {
            panic!("{l}")
        };
        check_source(&a.source);
        assert_eq!(a.options(), o, "{l}");
    }
}
