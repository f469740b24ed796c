//! The per-sample loss terms an uncertainty study shares between its cases
//! (`scene::SampleCache`): a case solved with the terms computed from another case's scene equals
//! the same case solved with its own terms, bit for bit, and a scene whose compiled bearings,
//! converter or sliding power laws differ does not read them.

use std::path::Path;
use std::sync::Arc;

use geartherm::job::{self, run::Prepared};
use geartherm::scene::sample_cache::CacheParts;
use geartherm::study::uq::run::{Uq, UqOptions};
use geartherm::study::{run_outputs, Case, Job};

fn uq() -> Uq {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/studies/at6_wltc_uq.toml");
    let options = UqOptions {
        samples: Some(4),
        sobol: true,
        ..UqOptions::default()
    };
    Uq::from_file(&path, options).unwrap()
}

/// The model and prepared run of `sample` (overrides applied as the study applies them).
fn prepared(uq: &Uq, sample: usize) -> (job::Model, Prepared) {
    prepared_with(uq, sample, &[])
}

/// As [`prepared`] with `more` overrides after the sample's.
fn prepared_with(uq: &Uq, sample: usize, more: &[&str]) -> (job::Model, Prepared) {
    let s = &uq.study;
    let (mut ovs, _) = s.overrides(sample).unwrap();
    ovs.extend(
        more.iter()
            .map(|t| t.parse::<geartherm::model::Override>().unwrap()),
    );
    let m = job::Model::from_text(&s.model_text, &s.model_file, &ovs).unwrap();
    let case = Case {
        index: sample,
        sample,
        job: 0,
    };
    let Job::Run(o) = s.case_job(&case, false) else {
        panic!("a run job")
    };
    let mut p = job::run::prepare(&m, &o).unwrap();
    p.range_warnings = false;
    (m, p)
}

/// Every output of the summary (name, bits), every band series value (bits), the warnings.
type Bits = (Vec<(String, Option<u64>)>, Vec<u64>, usize);

/// Every output of the summary and every band series value, as bits.
fn bits(m: &job::Model, p: &Prepared) -> Bits {
    let (r, s) = job::series::solve_with_series(m, p, 201).unwrap();
    let outputs = run_outputs(&r.summary)
        .into_iter()
        .map(|(k, v)| (k, v.map(f64::to_bits)))
        .collect();
    let series = s.values.iter().flatten().map(|v| v.to_bits()).collect();
    (outputs, series, r.summary.warnings.len())
}

#[test]
fn a_case_solved_from_another_cases_terms_equals_its_own_solve_bit_for_bit() {
    let uq = uq();
    let (_, donor) = prepared(&uq, 5);
    let cache = Arc::new(donor.scene.sample_cache(donor.segs.iter().map(|s| s.inputs)));
    assert!(!cache.is_empty());
    for sample in [0, 2, 7] {
        let (m, fresh) = prepared(&uq, sample);
        let (_, mut cached) = prepared(&uq, sample);
        // The study varies heat transfer, oil level, cooler, multipliers and the ambient: the
        // bearings and the converter compile the same.
        let all = CacheParts {
            bearings: true,
            auto: true,
            slide: true,
        };
        assert_eq!(cached.scene.use_sample_cache(Arc::clone(&cache)), all);
        let a = bits(&m, &fresh);
        let b = bits(&m, &cached);
        assert!(!a.0.is_empty() && !a.1.is_empty());
        assert_eq!(a, b, "sample {sample}");
    }
}

#[test]
fn a_scene_with_other_bearings_or_converter_does_not_read_the_terms() {
    let uq = uq();
    let (_, donor) = prepared(&uq, 0);
    let cache = Arc::new(donor.scene.sample_cache(donor.segs.iter().map(|s| s.inputs)));
    // The EV reducer has bearings and no converter or pump: neither part compares equal.
    let ev = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/ev_reducer.toml");
    let m = job::Model::load(&ev, &[]).unwrap();
    let mut p = job::run::prepare(&m, &job::RunOptions::default()).unwrap();
    assert_eq!(
        p.scene.use_sample_cache(Arc::clone(&cache)),
        CacheParts::default()
    );
}

#[test]
fn a_scene_with_another_friction_law_reads_the_bearing_terms_and_not_the_sliding_powers() {
    let uq = uq();
    let (_, donor) = prepared(&uq, 1);
    let cache = Arc::new(donor.scene.sample_cache(donor.segs.iter().map(|s| s.inputs)));
    let other = ["losses.friction=\"constant\"", "losses.friction_coefficient=0.05"];
    let (m, fresh) = prepared_with(&uq, 3, &other);
    let (_, mut cached) = prepared_with(&uq, 3, &other);
    let parts = cached.scene.use_sample_cache(Arc::clone(&cache));
    let expected = CacheParts {
        bearings: true,
        auto: true,
        slide: false,
    };
    assert_eq!(parts, expected);
    assert_eq!(bits(&m, &fresh), bits(&m, &cached));
}

#[test]
fn a_cached_schedule_is_the_one_computed_and_a_changed_vehicle_gets_its_own() {
    use geartherm::cycle::DriveCycle;
    use geartherm::model::Override;
    use geartherm::solve::drive::segments;
    use geartherm::study::schedule_cache::ScheduleCache;

    let uq = uq();
    let cycle = DriveCycle::resolve("wltc").unwrap();
    let cache = ScheduleCache::default();
    let (first, _) = prepared(&uq, 3);
    let filled = cache.segments(&first.gearbox, &cycle).unwrap();
    assert_eq!(filled, segments(&first.gearbox, &cycle).unwrap());
    // Another sample (other oil level, heat transfer, cooler, ambient): the same schedule.
    let (other, _) = prepared(&uq, 6);
    assert_eq!(
        cache.segments(&other.gearbox, &cycle).unwrap(),
        segments(&other.gearbox, &cycle).unwrap()
    );
    // A heavier vehicle needs more torque: its own schedule, not the cached one.
    let s = &uq.study;
    let heavier: Override = "vehicle.mass_kg = 2400.0".parse().unwrap();
    let m = job::Model::from_text(&s.model_text, &s.model_file, &[heavier]).unwrap();
    let own = segments(&m.gearbox, &cycle).unwrap();
    assert_ne!(own.1, filled.1);
    assert_eq!(cache.segments(&m.gearbox, &cycle).unwrap(), own);
}
