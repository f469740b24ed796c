//! Every value of every model-file section (a number, a string, an array, a table, a whole
//! section), written with the wrong type, is reported at its full key path
//! (`launch.lockup.slip_rpm`, `thermal.links[2].h_law.h1`, `gears[3]`, `vehicle.road_load`), with
//! the value found. The walk covers the AT6 model, to which the keys no bundled model uses are
//! added ([[meshes]], inline oil data, every [losses] key, a bearing with every key,
//! [[thermal.heat]], [thermal.wall_mesh], an [uncertainty] with every key).

use geartherm::model::file::SECTIONS;
use geartherm::model::parse::parse_table;
use geartherm::model::Problems;
use toml::{Table, Value};

/// The AT6 model with every key no bundled model uses.
fn full_document() -> Table {
    let text = std::fs::read_to_string("models/at6_lepelletier.toml").unwrap();
    let mut doc: Table = text.parse().unwrap();
    let extra: Table = r#"
[oil]
name = "inline"
nu40_cst = 35.0
nu100_cst = 7.0
rho15_kg_m3 = 850.0
thermal_expansion_per_k = -6.5e-4
walther = "c08"
base = "pao"
lubricant_factor = 0.8

[[meshes]]
name = "extra"
gears = ["s1_sun", "s1_planet"]
kind = "external"
centre_distance_mm = 50.0

[losses]
churning = "seetharaman"
pocketing = "on"
sliding = "detailed"
friction = "constant"
friction_coefficient = 0.05
lubricant_factor = 1.0
contact_line_load = "face_width"
load_sharing = "33:67"
helical_distribution = "niemann_richer"
loss_form = "moment_balance"
helical_slices = 50
helical_time_samples = 8
sliding_heat_to_gear1 = 0.5
pocketing_discharge_coefficient = 0.65
pocketing_mixture_density_kg_m3 = 10.0
seetharaman_transition_reynolds = 5e5
seetharaman_cavity = "form_drag"
stavytskyi_ks = 0.85
changenet_low = [1.0, 0.45, 0.1, -0.6, -0.21]
changenet_high = [1.0, 0.45, 0.1, -0.6, -0.21]

[[bearings]]
name = "extra"
planet = "s1_planet"
designation = "6208"
position_mm = 10.0
locating = true
model = "skf"
radial_preload_n = 10.0
axial_preload_n = 5.0
sealed = true
lubrication = "grease"
mu_bl = 0.1
mu_ehl = 0.05
drag_form = "skf_older"
drag_vm = 0.001
heat_to = [["sump", 1.0]]
source = "test"

[[thermal.heat]]
source = "sliding"
to = { sump = 1.0 }

[[thermal.heat]]
item = "churning:s1_ring"
to = { sump = 0.5, housing = 0.5 }

[[thermal.coolers]]
name = "fan_cooler"
hot = "sump"
cold = "coolant"
effectiveness = 0.5
capacity_rate_w_per_k = 40.0
air_density_reference_c = 20.0

[[thermal.controls]]
name = "fan"
kind = "two_point"
sensor = "sump"
on_c = 90.0
off_c = 85.0
initial_on = false
link = "shafts-oil"
off_fraction = 0.2
note = "test"

[[thermal.controls]]
name = "heater"
kind = "two_point"
sensor = "sump"
on_c = 20.0
off_c = 30.0
heater_w = 500.0
heater_node = "sump"

[[thermal.controls]]
name = "bypass"
kind = "valve"
sensor = "sump"
closed_c = 70.0
open_c = 85.0
min_share = 0.05
max_share = 0.95
cooler = "fan_cooler"

[thermal.wall_mesh]
node = "housing"
around = 4
along = 2
circumference_m = 1.4
length_m = 0.5
thickness_mm = 15.0
conductivity_w_per_mk = 100.0
oil_wetted_fraction = 0.3

[uncertainty]
samples = 64

[[uncertainty.inputs]]
path = "lubrication.oil_level_mm"
dist = "triangular"
mean = 1.0
sd = 1.0
median = 1.0
sigma_ln = 0.1
lo = 1.0
mode = 2.0
hi = 3.0
truncate = [1.0, 3.0]
relative = false
note = "test"

[[uncertainty.correlations]]
between = ["lubrication.oil_level_mm", "oil.nu40_cst"]
rank = 0.5

[uncertainty.calibration]
parameters = ["oil.nu40_cst"]
scale = ["log"]
value = [35.0]
covariance = [[0.01]]
"#
    .parse()
    .unwrap();
    for (section, v) in extra {
        match (doc.get_mut(&section), v) {
            (Some(Value::Table(t)), Value::Table(add)) => t.extend(add),
            (Some(Value::Array(a)), Value::Array(add)) => a.extend(add),
            (None, v) => {
                doc.insert(section, v);
            }
            _ => panic!("{section}"),
        }
    }
    // [thermal] is a table with sub-tables: its extras came in as one table above.
    doc
}

/// The key path of every value in `v` (tables and arrays too, the root aside), written as the
/// problems write it.
fn values(v: &Value, path: String, out: &mut Vec<String>) {
    if !path.is_empty() {
        out.push(path.clone());
    }
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        Value::Table(t) => t.iter().for_each(|(k, v)| values(v, join(k), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, v)| values(v, format!("{path}[{i}]"), out)),
        _ => {}
    }
}

/// The value at `path` (as [`values`] writes it), mutable.
fn at<'a>(doc: &'a mut Table, path: &str) -> &'a mut Value {
    let mut parts = path.split('.');
    let first = parts.next().unwrap();
    let (key, idx) = split_index(first);
    let mut cur = index(doc.get_mut(key).unwrap(), idx);
    for part in parts {
        let (key, idx) = split_index(part);
        cur = index(cur.as_table_mut().unwrap().get_mut(key).unwrap(), idx);
    }
    cur
}

fn split_index(part: &str) -> (&str, Vec<usize>) {
    match part.find('[') {
        None => (part, vec![]),
        Some(p) => (
            &part[..p],
            part[p + 1..part.len() - 1]
                .split("][")
                .map(|i| i.parse().unwrap())
                .collect(),
        ),
    }
}

fn index(mut v: &mut Value, idx: Vec<usize>) -> &mut Value {
    for i in idx {
        v = &mut v.as_array_mut().unwrap()[i];
    }
    v
}

/// A value of the wrong type for `v`: a number for a string, the string "NaN" for anything else.
fn wrong(v: &Value) -> (Value, &'static str) {
    match v {
        Value::String(_) => (Value::Integer(1), "1"),
        _ => (Value::String("NaN".into()), "\"NaN\""),
    }
}

#[test]
fn the_full_document_parses() {
    let mut problems = Problems::default();
    assert!(
        parse_table(full_document(), &mut problems).is_some(),
        "{:?}",
        problems.as_slice()
    );
}

#[test]
fn every_wrongly_typed_value_is_reported_at_its_full_key_path() {
    let doc = full_document();
    let mut paths = Vec::new();
    values(&Value::Table(doc.clone()), String::new(), &mut paths);
    assert!(paths.len() > 500, "{} values", paths.len());
    let mut failures = Vec::new();
    for path in &paths {
        let mut bad = doc.clone();
        let v = at(&mut bad, path);
        let (w, shown) = wrong(v);
        *v = w;
        let mut problems = Problems::default();
        let parsed = parse_table(bad, &mut problems);
        let want = format!("{path} = {shown}: ");
        let found = problems
            .as_slice()
            .iter()
            .any(|p| p.to_string().starts_with(&want));
        if parsed.is_some() || !found {
            failures.push(format!("{path}: {:?}", problems.as_slice()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Every section and sub-table was walked.
    for section in SECTIONS.iter().chain(&[
        "thermal.nodes",
        "thermal.boundaries",
        "thermal.links",
        "thermal.coolers",
        "thermal.heat",
        "thermal.wall_mesh",
        "vehicle.road_load",
        "vehicle.shift",
        "launch.lockup",
        "pump.line_pressure",
        "uncertainty.inputs",
        "uncertainty.correlations",
        "uncertainty.calibration",
    ]) {
        assert!(
            paths.iter().any(|p| p.starts_with(section)),
            "no value of {section} walked"
        );
    }
}

#[test]
fn a_launch_value_written_as_a_string_names_launch_and_its_key() {
    let mut doc = full_document();
    *at(&mut doc, "launch.idle_speed_rpm") = Value::String("NaN".into());
    let mut problems = Problems::default();
    assert!(parse_table(doc, &mut problems).is_none());
    assert_eq!(
        problems.as_slice()[0].to_string(),
        "launch.idle_speed_rpm = \"NaN\": invalid type: string \"NaN\", expected f64"
    );
}

#[test]
fn a_bad_choice_lists_the_allowed_names_at_its_key_path() {
    for (path, allowed) in [
        (
            "losses.churning",
            "must be one of: changenet, seetharaman, stavytskyi, off",
        ),
        (
            "losses.load_sharing",
            "must be one of: uniform, 33:67, 45:55, ramp",
        ),
        (
            "planetary_sets[0].kind",
            "must be one of: simple, double_pinion, ravigneaux",
        ),
        (
            "thermal.heat[0].source",
            "must be one of: churning, pocketing, sliding, bearing, seal, clutch_drag, pump, converter, windage, jet, fling",
        ),
        ("vehicle.overrun", "must be one of: zero, transmit"),
        ("oil.walther", "must be one of: astm_d341, c06, c08"),
        (
            "oil.base",
            "must be one of: mineral, pao, ester, pag, pag_water_soluble, phosphate_ester, traction_fluid",
        ),
        (
            "losses.contact_line_load",
            "must be one of: contact_line, face_width",
        ),
        ("bearings[11].drag_form", "must be one of: skf_current, skf_older"),
    ] {
        let mut doc = full_document();
        let slot = if path == "vehicle.overrun" {
            doc["vehicle"]
                .as_table_mut()
                .unwrap()
                .insert("overrun".into(), Value::from("brake"));
            at(&mut doc, path)
        } else {
            at(&mut doc, path)
        };
        *slot = Value::from("magic");
        let mut problems = Problems::default();
        assert!(parse_table(doc, &mut problems).is_none(), "{path}");
        let msg = problems.as_slice()[0].to_string();
        assert_eq!(msg, format!("{path} = \"magic\": {allowed}"));
    }
}
