//! Bundled drive cycles (`models/cycles/*.csv`, compiled into the binary; provenance in
//! `models/cycles/SOURCES.md`) and name resolution.

use std::sync::OnceLock;

use super::error::{CycleError, CycleErrorKind};
use super::parse::DriveCycle;

macro_rules! cycle_file {
    ($f:literal) => {
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/models/cycles/", $f))
    };
}

/// (canonical name, file name, text). Order = the order of [`bundled_names`].
const BUNDLED: [(&str, &str, &str); 10] = [
    ("wltc", "wltc_class3b.csv", cycle_file!("wltc_class3b.csv")),
    ("nedc", "nedc.csv", cycle_file!("nedc.csv")),
    ("ftp75", "ftp75_no_soak.csv", cycle_file!("ftp75_no_soak.csv")),
    ("udds", "udds.csv", cycle_file!("udds.csv")),
    ("hwfet", "hwfet.csv", cycle_file!("hwfet.csv")),
    ("us06", "us06.csv", cycle_file!("us06.csv")),
    (
        "artemis_urban",
        "artemis_urban.csv",
        cycle_file!("artemis_urban.csv"),
    ),
    (
        "artemis_road",
        "artemis_road.csv",
        cycle_file!("artemis_road.csv"),
    ),
    (
        "artemis_motorway130",
        "artemis_motorway130.csv",
        cycle_file!("artemis_motorway130.csv"),
    ),
    (
        "artemis_motorway150",
        "artemis_motorway150.csv",
        cycle_file!("artemis_motorway150.csv"),
    ),
];

/// Extra names: (alias, canonical name).
const ALIASES: [(&str, &str); 1] = [("artemis_motorway", "artemis_motorway130")];

const NAMES: [&str; 10] = [
    "wltc",
    "nedc",
    "ftp75",
    "udds",
    "hwfet",
    "us06",
    "artemis_urban",
    "artemis_road",
    "artemis_motorway130",
    "artemis_motorway150",
];

/// Canonical names of the bundled cycles (aliases and file stems are accepted too, see
/// [`DriveCycle::bundled`]).
pub fn bundled_names() -> &'static [&'static str] {
    &NAMES
}

/// Map a name (canonical, alias, or file stem such as `wltc_class3b`; case-insensitive; a
/// trailing `.csv` is ignored) to the bundled entry's index in [`BUNDLED`].
fn lookup(name: &str) -> Option<usize> {
    let n = name.trim().to_ascii_lowercase();
    let n = n.strip_suffix(".csv").unwrap_or(&n);
    let n = ALIASES.iter().find(|(a, _)| *a == n).map_or(n, |(_, c)| *c);
    BUNDLED
        .iter()
        .position(|(canon, file, _)| *canon == n || file.strip_suffix(".csv") == Some(n))
}

impl DriveCycle {
    /// A bundled cycle by name. Accepted: [`bundled_names`], the alias `artemis_motorway`
    /// (= `artemis_motorway130`), and the file stems (`wltc_class3b`, `ftp75_no_soak`).
    pub fn bundled(name: &str) -> Result<DriveCycle, CycleError> {
        let k = lookup(name).ok_or_else(|| {
            CycleError::new(
                CycleErrorKind::UnknownName,
                name,
                format!("not a bundled cycle; bundled: {}", NAMES.join(", ")),
            )
        })?;
        // Each bundled cycle is parsed once per process (a study runs one cycle many times).
        static PARSED: [OnceLock<Result<DriveCycle, CycleError>>; BUNDLED.len()] =
            [const { OnceLock::new() }; BUNDLED.len()];
        PARSED[k]
            .get_or_init(|| {
                let (canon, file, text) = BUNDLED[k];
                let mut c = DriveCycle::parse(text, &format!("bundled:{canon} (models/cycles/{file})"))?;
                c.name = canon.to_string();
                Ok(c)
            })
            .clone()
    }

    /// A bundled cycle if `arg` names one, else the file at path `arg`.
    pub fn resolve(arg: &str) -> Result<DriveCycle, CycleError> {
        resolve(arg)
    }
}

/// A bundled cycle if `arg` names one, else the file at path `arg` (a missing file gives an
/// error that lists the bundled names too).
pub fn resolve(arg: &str) -> Result<DriveCycle, CycleError> {
    if lookup(arg).is_some() {
        return DriveCycle::bundled(arg);
    }
    // A path that does not exist may be a misspelt bundled name (invalid input); a path that
    // exists but cannot be read (a directory, no permission) stays an I/O error.
    let missing = !std::path::Path::new(arg).exists();
    DriveCycle::load(arg).map_err(|mut e| {
        if e.kind == CycleErrorKind::Io && missing {
            e.kind = CycleErrorKind::UnknownName;
            e.allowed = format!("{} (and not a bundled cycle: {})", e.allowed, NAMES.join(", "));
        }
        e
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycle::parse::{CycleKind, KMH};
    use approx::assert_relative_eq;

    const TABLE: &str = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/cycles/verification_table.txt"
    ));

    struct Ref {
        file: String,
        n: usize,
        t_end: f64,
        vmax_kmh: f64,
        dist_km: f64,
        ref_km: f64,
    }

    fn table() -> Vec<Ref> {
        let mut out = Vec::new();
        for line in TABLE.lines() {
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.len() != 10 || !f[0].ends_with(".csv") {
                continue;
            }
            let p = |i: usize| f[i].parse::<f64>().unwrap();
            out.push(Ref {
                file: f[0].to_string(),
                n: f[1].parse().unwrap(),
                t_end: p(2),
                vmax_kmh: p(4),
                dist_km: p(6),
                ref_km: p(7),
            });
        }
        out
    }

    #[test]
    fn every_bundled_cycle_matches_the_verification_table() {
        let refs = table();
        assert_eq!(refs.len(), BUNDLED.len(), "table rows");
        for (canon, file, _) in BUNDLED {
            let r = refs
                .iter()
                .find(|r| r.file == file)
                .unwrap_or_else(|| panic!("{file} not in the table"));
            let c = DriveCycle::bundled(canon).unwrap();
            assert_eq!(c.kind, CycleKind::Vehicle);
            assert_eq!(c.name, canon);
            assert_eq!(c.len(), r.n, "{file} rows");
            assert_relative_eq!(c.start_time(), 0.0);
            assert_relative_eq!(c.duration(), r.t_end);
            // 1 Hz
            assert!(
                c.rows
                    .windows(2)
                    .all(|w| (w[1].time - w[0].time - 1.0).abs() < 1e-12),
                "{file} not 1 Hz"
            );
            assert!(
                (c.max_vehicle_speed() / KMH - r.vmax_kmh).abs() < 0.006,
                "{file} vmax"
            );
            // table distances are rounded to 1 m
            assert!(
                (c.distance() / 1000.0 - r.dist_km).abs() <= 0.0005 + 1e-9,
                "{file}: {}",
                c.distance()
            );
            // and within 0.1 % of the published distance
            assert!(
                (c.distance() / 1000.0 / r.ref_km - 1.0).abs() < 1e-3,
                "{file} vs published"
            );
        }
    }

    #[test]
    fn wltc_class3b_facts() {
        let c = DriveCycle::bundled("wltc").unwrap();
        assert_relative_eq!(c.duration(), 1800.0);
        assert!((c.distance() - 23266.0).abs() < 1.0, "{}", c.distance());
        assert!((c.max_vehicle_speed() / KMH - 131.3).abs() < 1e-9);
    }

    #[test]
    fn names_aliases_and_stems() {
        assert_eq!(bundled_names().len(), BUNDLED.len());
        for (i, n) in bundled_names().iter().enumerate() {
            assert_eq!(*n, BUNDLED[i].0);
            assert_eq!(DriveCycle::bundled(n).unwrap().name, *n);
        }
        assert_eq!(DriveCycle::bundled("wltc_class3b").unwrap().name, "wltc");
        assert_eq!(DriveCycle::bundled("FTP75_no_soak.csv").unwrap().name, "ftp75");
        assert_eq!(
            DriveCycle::bundled("artemis_motorway").unwrap().name,
            "artemis_motorway130"
        );
        let e = DriveCycle::bundled("wltp").unwrap_err();
        assert_eq!(e.kind, CycleErrorKind::UnknownName);
        assert!(e.to_string().contains("artemis_road"));
    }

    #[test]
    fn resolve_prefers_bundled_then_path() {
        assert_eq!(resolve("udds").unwrap().name, "udds");
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/models/cycles/hwfet.csv");
        let c = resolve(path).unwrap();
        assert_eq!(c.name, "hwfet");
        assert_eq!(c.source, path);
        let e = resolve("no_such_cycle_or_file.csv").unwrap_err();
        assert_eq!(e.kind, CycleErrorKind::UnknownName);
        assert!(e.to_string().contains("wltc"));
    }
}
