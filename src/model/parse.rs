//! TOML text → [`ModelFile`], reporting every section's type errors at once.
//!
//! The text is first parsed as plain TOML (syntax errors carry line and column). Then each
//! top-level section, and each entry of an array of tables, is deserialized on its own, so one bad
//! gear does not hide the problems of the next; each error carries its key path
//! (`gears[3].module_mm`).

use serde::de::DeserializeOwned;
use toml::{Table, Value};

use super::file::{ModelFile, SECTIONS};
use super::problems::Problems;
use super::sections::*;

/// Line and column (1-based) of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let upto = &text[..offset.min(text.len())];
    let line = upto.matches('\n').count() + 1;
    let col = upto.rfind('\n').map_or(upto.len(), |p| upto.len() - p - 1) + 1;
    (line, col)
}

/// A value as messages show it: strings quoted and escaped (a message stays on one line),
/// tables and arrays summarised.
fn describe(v: &Value) -> String {
    match v {
        Value::String(s) => format!("{s:?}"),
        Value::Table(_) => "{table}".into(),
        Value::Array(a) => format!("[array of {}]", a.len()),
        other => other.to_string(),
    }
}

fn de<T: DeserializeOwned>(value: Value, path: &str, problems: &mut Problems) -> Option<T> {
    match serde_path_to_error::deserialize::<_, T>(value.clone()) {
        Ok(t) => Some(t),
        Err(e) => {
            let inner = e.path().to_string();
            let full = if inner == "." || inner.is_empty() {
                path.to_string()
            } else if inner.starts_with('[') {
                format!("{path}{inner}")
            } else {
                format!("{path}.{inner}")
            };
            // Find the offending value for the message when the path resolves.
            let found = lookup(&value, &inner).map(describe).unwrap_or_default();
            let msg = e.into_inner().to_string();
            let first = msg.lines().next().unwrap_or("").trim().to_string();
            problems.push(full, found, first);
            None
        }
    }
}

/// Resolve a serde_path_to_error path (`a.b[2].c`) inside a value.
fn lookup<'a>(value: &'a Value, path: &str) -> Option<&'a Value> {
    let mut cur = value;
    if path == "." || path.is_empty() {
        return Some(cur);
    }
    for part in path.split('.') {
        let (key, idx) = match part.find('[') {
            Some(p) => (&part[..p], Some(&part[p..])),
            None => (part, None),
        };
        if !key.is_empty() {
            cur = cur.as_table()?.get(key)?;
        }
        if let Some(mut rest) = idx {
            while let Some(end) = rest.find(']') {
                let i: usize = rest[1..end].parse().ok()?;
                cur = cur.as_array()?.get(i)?;
                rest = &rest[end + 1..];
            }
        }
    }
    Some(cur)
}

fn section<T: DeserializeOwned>(
    table: &mut Table,
    key: &str,
    required: bool,
    problems: &mut Problems,
) -> Option<T> {
    match table.remove(key) {
        Some(v) => de(v, key, problems),
        None => {
            if required {
                problems.push(key, "", format!("required section [{key}] is missing"));
            }
            None
        }
    }
}

fn array<T: DeserializeOwned>(
    table: &mut Table,
    key: &str,
    required: bool,
    problems: &mut Problems,
) -> Vec<T> {
    match table.remove(key) {
        Some(Value::Array(items)) => items
            .into_iter()
            .enumerate()
            .filter_map(|(i, v)| de(v, &format!("{key}[{i}]"), problems))
            .collect(),
        Some(other) => {
            problems.push(
                key,
                describe(&other),
                format!("must be an array of tables ([[{key}]])"),
            );
            Vec::new()
        }
        None => {
            if required {
                problems.push(key, "", format!("required section [[{key}]] is missing"));
            }
            Vec::new()
        }
    }
}

/// Longest name of a model part.
pub const MAX_NAME_LEN: usize = 64;

/// Characters a part name may not contain: they would need quoting or escaping in a CSV column
/// name, a Markdown table cell or a shell word.
pub const NAME_FORBIDDEN: &[char] = &[',', '"', '\'', '|', '\\', ';', '`'];

/// True for a part name: 1–64 characters, no control character (newline, tab, …), none of
/// [`NAME_FORBIDDEN`], no leading or trailing space. Names become CSV column names
/// (`temp_<node>_c`, `loss_sliding_<mesh>_w`), JSON keys and Markdown cells, and with this
/// rule no writer ever needs to quote them (`pinion/wheel` and `pinion-oil still` are fine).
pub fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.chars().count() <= MAX_NAME_LEN
        && name.trim() == name
        && !name
            .chars()
            .any(|c| c.is_control() || NAME_FORBIDDEN.contains(&c))
}

/// A step of a key path while [`check_names`] walks the document.
#[derive(Clone, Copy)]
enum At<'a> {
    Key(&'a str),
    Index(usize),
}

/// The key path of `steps` (`gears[3].name`).
fn path_of(steps: &[At<'_>]) -> String {
    let mut s = String::new();
    for step in steps {
        match step {
            At::Key(k) if s.is_empty() => s.push_str(k),
            At::Key(k) => {
                s.push('.');
                s.push_str(k);
            }
            At::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Every `name` key of the file (except the free-text `model.name` and `oil.name`) must be an
/// identifier ([`is_plain_name`]); one problem per bad name, with its key path (`steps`: the
/// path of `value`).
fn check_names<'a>(value: &'a Value, steps: &mut Vec<At<'a>>, problems: &mut Problems) {
    match value {
        Value::Table(t) => {
            for (k, v) in t {
                let free_text = matches!(steps.as_slice(), [At::Key("model" | "oil")]);
                steps.push(At::Key(k));
                if k == "name" && !free_text {
                    check_name(v, steps, problems);
                } else {
                    check_names(v, steps, problems);
                }
                steps.pop();
            }
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                steps.push(At::Index(i));
                check_names(v, steps, problems);
                steps.pop();
            }
        }
        _ => {}
    }
}

/// [`check_names`] over every top-level entry of a document.
fn check_table_names(table: &Table, problems: &mut Problems) {
    let mut steps = Vec::new();
    for (k, v) in table {
        steps.push(At::Key(k));
        check_names(v, &mut steps, problems);
        steps.pop();
    }
}

/// A `name` value at `steps` that is a string must be a plain name (other types are the typed
/// reading's to report).
fn check_name(v: &Value, steps: &[At<'_>], problems: &mut Problems) {
    let Value::String(s) = v else { return };
    if !is_plain_name(s) {
        problems.push(
            path_of(steps),
            describe(v),
            format!(
                "must be a plain name: 1–{MAX_NAME_LEN} characters, no control characters, none of , \" ' | \\ ; `, no leading or trailing space"
            ),
        );
    }
}

/// Parse model-file text. Returns the file when every section deserialized, else `None`, with all
/// problems found recorded in `problems`.
pub fn parse_model(text: &str, problems: &mut Problems) -> Option<ModelFile> {
    let table = parse_document(text, problems)?;
    parse_table(table, problems)
}

/// Parse model-file text as a plain TOML document (syntax errors carry line and column).
pub fn parse_document(text: &str, problems: &mut Problems) -> Option<Table> {
    match text.parse() {
        Ok(t) => Some(t),
        Err(e) => {
            let e: toml::de::Error = e;
            let where_ = e
                .span()
                .map(|s| {
                    let (l, c) = line_col(text, s.start);
                    format!("line {l}, column {c}")
                })
                .unwrap_or_else(|| "unknown position".into());
            problems.push("", "", format!("TOML syntax error at {where_}: {}", e.message()));
            None
        }
    }
}

/// A parsed TOML document → [`ModelFile`], every section's type errors reported at once.
pub fn parse_table(mut table: Table, problems: &mut Problems) -> Option<ModelFile> {
    let unknown: Vec<String> = table
        .keys()
        .filter(|k| !SECTIONS.contains(&k.as_str()))
        .cloned()
        .collect();
    for k in unknown {
        problems.push(
            k.clone(),
            "",
            format!("unknown top-level key; allowed sections: {}", SECTIONS.join(", ")),
        );
    }
    check_table_names(&table, problems);
    let before = problems.len();
    let model = section::<model::ModelMeta>(&mut table, "model", true, problems);
    let oil = section::<oil::OilSpec>(&mut table, "oil", true, problems);
    let members = array::<members::MemberSpec>(&mut table, "members", false, problems);
    let gears = array::<gears::GearSpecFile>(&mut table, "gears", true, problems);
    let meshes = array::<meshes::MeshSpec>(&mut table, "meshes", false, problems);
    let planetary_sets =
        array::<planetary_sets::PlanetarySetSpec>(&mut table, "planetary_sets", false, problems);
    let shift_elements =
        array::<shift_elements::ShiftElementSpec>(&mut table, "shift_elements", false, problems);
    let gear_states = array::<gear_states::GearStateSpec>(&mut table, "gear_states", false, problems);
    let train = section::<train::TrainSpec>(&mut table, "train", true, problems);
    let lubrication = section::<lubrication::LubricationSpec>(&mut table, "lubrication", true, problems);
    let losses = section::<losses::LossesSpec>(&mut table, "losses", false, problems);
    let thermal = section::<thermal::ThermalSpec>(&mut table, "thermal", false, problems);
    let vehicle = section::<vehicle::VehicleSpec>(&mut table, "vehicle", false, problems);
    let clutch_packs = array::<clutch_packs::ClutchPackSpec>(&mut table, "clutch_packs", false, problems);
    let pump = section::<pump::PumpSpec>(&mut table, "pump", false, problems);
    let launch = section::<launch::LaunchSpec>(&mut table, "launch", false, problems);
    let bearings = array::<bearings::BearingSpec>(&mut table, "bearings", false, problems);
    let seals = array::<seals::SealSpec>(&mut table, "seals", false, problems);
    let circuit = section::<circuit::CircuitSpec>(&mut table, "circuit", false, problems);
    let uncertainty = section::<uncertainty::UncertaintySpec>(&mut table, "uncertainty", false, problems);
    if problems.len() > before || !problems.is_empty() {
        return None;
    }
    Some(ModelFile {
        model: model?,
        oil: oil?,
        members,
        gears,
        meshes,
        planetary_sets,
        shift_elements,
        gear_states,
        train: train?,
        lubrication: lubrication?,
        losses,
        thermal,
        vehicle,
        clutch_packs,
        pump,
        launch,
        bearings,
        seals,
        circuit,
        uncertainty,
    })
}

/// `base` with the top-level sections of `table` read anew (every other section kept as it is):
/// the file [`parse_table`] gives for `base`'s document with those sections replaced, with the
/// same problems in the same order. Every key of `table` must be one of [`SECTIONS`].
pub fn reparse_sections(mut table: Table, base: &ModelFile, problems: &mut Problems) -> Option<ModelFile> {
    check_table_names(&table, problems);
    let mut f = base.clone();
    let p = problems;
    let present: Vec<&str> = SECTIONS
        .iter()
        .copied()
        .filter(|k| table.contains_key(*k))
        .collect();
    for key in present {
        let t = &mut table;
        match key {
            "model" => set(&mut f.model, section(t, key, true, p)),
            "oil" => set(&mut f.oil, section(t, key, true, p)),
            "members" => f.members = array(t, key, false, p),
            "gears" => f.gears = array(t, key, true, p),
            "meshes" => f.meshes = array(t, key, false, p),
            "planetary_sets" => f.planetary_sets = array(t, key, false, p),
            "shift_elements" => f.shift_elements = array(t, key, false, p),
            "gear_states" => f.gear_states = array(t, key, false, p),
            "train" => set(&mut f.train, section(t, key, true, p)),
            "lubrication" => set(&mut f.lubrication, section(t, key, true, p)),
            "losses" => f.losses = section(t, key, false, p),
            "thermal" => f.thermal = section(t, key, false, p),
            "vehicle" => f.vehicle = section(t, key, false, p),
            "clutch_packs" => f.clutch_packs = array(t, key, false, p),
            "pump" => f.pump = section(t, key, false, p),
            "launch" => f.launch = section(t, key, false, p),
            "bearings" => f.bearings = array(t, key, false, p),
            "seals" => f.seals = array(t, key, false, p),
            "circuit" => f.circuit = section(t, key, false, p),
            "uncertainty" => f.uncertainty = section(t, key, false, p),
            _ => {}
        }
    }
    p.is_empty().then_some(f)
}

/// Replace a required section by its new reading (a failed reading has recorded its problem).
fn set<T>(slot: &mut T, read: Option<T>) {
    if let Some(v) = read {
        *slot = v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn syntax_error_has_line_and_column() {
        let mut p = Problems::default();
        assert!(parse_model("[model]\nname = \"x\"\nbad = = 3\n", &mut p).is_none());
        let msg = p.as_slice()[0].to_string();
        assert!(msg.contains("line 3"), "{msg}");
        assert!(msg.contains("column"), "{msg}");
    }

    #[test]
    fn reports_every_bad_gear_with_its_path() {
        let text = r#"
[model]
name = "t"
[oil]
catalogue = "FVA 3A"
[[gears]]
name = "a"
member = "m"
teeth = "sixteen"
module_mm = 4.5
face_width_mm = 14
[[gears]]
name = "b"
member = "m"
teeth = 24
modul_mm = 4.5
face_width_mm = 14
[train]
input = "m"
output = "m"
[lubrication]
oil_level_mm = 0
centre_height_mm = {}
"#;
        let mut p = Problems::default();
        assert!(parse_model(text, &mut p).is_none());
        let all: Vec<String> = p.as_slice().iter().map(|x| x.to_string()).collect();
        assert!(all.iter().any(|m| m.starts_with("gears[0].teeth")), "{all:?}");
        assert!(
            all.iter()
                .any(|m| m.starts_with("gears[1]") && m.contains("modul_mm")),
            "{all:?}"
        );
    }

    #[test]
    fn names_must_be_plain() {
        assert!(is_plain_name("sun1"));
        assert!(is_plain_name("R"));
        assert!(is_plain_name("pinion_a.2"));
        assert!(!is_plain_name(""));
        assert!(!is_plain_name("a\nb,c\"d"));
        assert!(is_plain_name("pinion/wheel"));
        assert!(is_plain_name("pinion-oil still"));
        assert!(!is_plain_name(" a"));
        assert!(!is_plain_name("a|b"));
        assert!(!is_plain_name(&"x".repeat(MAX_NAME_LEN + 1)));
        let mut p = Problems::default();
        let v: Value =
            toml::from_str("[model]\nname = \"free text, ok\"\n[[gears]]\nname = \"a\\nb,c\\\"d\"\n")
                .unwrap();
        check_table_names(v.as_table().unwrap(), &mut p);
        let all: Vec<String> = p.as_slice().iter().map(|x| x.to_string()).collect();
        assert_eq!(all.len(), 1, "{all:?}");
        assert!(all[0].starts_with("gears[0].name"), "{all:?}");
    }

    #[test]
    fn line_col_counts_from_one() {
        assert_eq!(line_col("ab\ncd", 0), (1, 1));
        assert_eq!(line_col("ab\ncd", 4), (2, 2));
    }
}
