//! The calibrated model file: the model's own text with values written in at their key paths
//! (comments and layout kept; a key the file did not write is added), and boundaries replaced
//! by the trace's temperature series.

use toml_edit::{Array, DocumentMut, Item, Table, TableLike, Value};

use crate::model::overrides::Step;
use crate::model::Override;
use crate::report::calibration::FittedParameter;

/// The table-like item at the end of `steps` (keys, each optionally followed by a selector
/// into an array of tables: `[N]` or `["name"]`), creating missing tables for keys.
fn table_at<'a>(t: &'a mut dyn TableLike, steps: &[Step]) -> Result<&'a mut dyn TableLike, String> {
    let Some((first, rest)) = steps.split_first() else {
        return Ok(t);
    };
    let Step::Key(k) = first else {
        return Err("a selector must follow a key".into());
    };
    if t.get(k).is_none() {
        t.insert(k, Item::Table(Table::new()));
    }
    let item = t.get_mut(k).ok_or_else(|| format!("no key `{k}`"))?;
    match rest.split_first() {
        Some((Step::Index(_) | Step::Named(_), after)) => {
            let Item::ArrayOfTables(a) = item else {
                return Err(format!("`{k}` is not an array of tables"));
            };
            let pos = match &rest[0] {
                Step::Index(n) => *n,
                Step::Named(name) => a
                    .iter()
                    .position(|e| e.get("name").and_then(Item::as_str) == Some(name.as_str()))
                    .ok_or_else(|| format!("`{k}` has no entry named \"{name}\""))?,
                Step::Key(_) => return Err("a selector must follow a key".into()),
            };
            let entry = a
                .get_mut(pos)
                .ok_or_else(|| format!("`{k}` has no entry [{pos}]"))?;
            table_at(entry, after)
        }
        _ => {
            let inner = item
                .as_table_like_mut()
                .ok_or_else(|| format!("`{k}` is not a table"))?;
            table_at(inner, rest)
        }
    }
}

fn to_edit(v: &toml::Value) -> Value {
    match v {
        toml::Value::Float(x) => Value::from(*x),
        toml::Value::Integer(i) => Value::from(*i),
        toml::Value::Boolean(b) => Value::from(*b),
        toml::Value::String(s) => Value::from(s.as_str()),
        toml::Value::Array(a) => Value::Array(a.iter().map(to_edit).collect()),
        other => Value::from(other.to_string()),
    }
}

/// Write `value` at the override's key path, keeping the comment after an existing value.
fn set(doc: &mut DocumentMut, ov: &Override) -> Result<(), String> {
    let (last, parents) = ov.path.0.split_last().ok_or("empty key path")?;
    let Step::Key(k) = last else {
        return Err(format!("{}: a key path must end on a key", ov.path));
    };
    let t = table_at(doc.as_table_mut(), parents).map_err(|e| format!("{}: {e}", ov.path))?;
    let mut v = to_edit(&ov.value);
    if let Some(old) = t.get(k).and_then(Item::as_value) {
        *v.decor_mut() = old.decor().clone();
    }
    t.insert(k, Item::Value(v));
    Ok(())
}

/// The model text with every override written in and each boundary of `series` (name, (time s,
/// °C) pairs) given as a `series` instead of its `temp_c`.
pub fn calibrated_text(
    text: &str,
    overrides: &[Override],
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<String, String> {
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e| format!("the model text does not parse: {e}"))?;
    for ov in overrides {
        set(&mut doc, ov)?;
    }
    for (name, points) in series {
        let path = [
            Step::Key("thermal".into()),
            Step::Key("boundaries".into()),
            Step::Named(name.clone()),
            Step::Key("temp_c".into()),
        ];
        let t = table_at(doc.as_table_mut(), &path[..3])?;
        t.remove("temp_c");
        let mut arr = Array::new();
        for &(time, temp) in points {
            let mut pair = Array::new();
            pair.push(time);
            pair.push(temp);
            arr.push(pair);
        }
        t.insert("series", Item::Value(Value::Array(arr)));
    }
    Ok(doc.to_string())
}

/// The fitted parameters' covariance as a comment block at the end of `calibrated.toml` (a
/// TOML table once the leading `# ` of its lines is removed; the model file has no section for
/// it): key paths, scales, values and the covariance in the fitted coordinates (ln p or p).
pub fn covariance_comment(params: &[FittedParameter], cov: &[Vec<Option<f64>>]) -> String {
    if params.is_empty() {
        return String::new();
    }
    let quote = |s: &str| format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""));
    let list = |v: Vec<String>| format!("[{}]", v.join(", "));
    let mut s = String::from(
        "\n# The fitted parameters' covariance in their fitted coordinates (ln p for scale \"log\", p for \
         \"linear\"),\n# nan where not identifiable: remove the leading \"# \" for a TOML table.\n\
         # [calibration]\n",
    );
    s.push_str(&format!(
        "# parameters = {}\n",
        list(params.iter().map(|p| quote(&p.key_path)).collect())
    ));
    s.push_str(&format!(
        "# scale = {}\n",
        list(params.iter().map(|p| quote(p.scale)).collect())
    ));
    s.push_str(&format!(
        "# value = {}\n",
        list(params.iter().map(|p| format!("{:?}", p.value)).collect())
    ));
    let rows: Vec<String> = cov
        .iter()
        .map(|r| {
            list(
                r.iter()
                    .map(|x| x.map_or("nan".into(), |v| format!("{v:?}")))
                    .collect(),
            )
        })
        .collect();
    s.push_str(&format!("# covariance = [{}]\n", rows.join(", ")));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[thermal]\ninitial_temp_c = 23.0 # cold\n\n[[thermal.nodes]]\nname = \"sump\"\n\
                        mass_kg = 7.6 # ATF\n\n[[thermal.boundaries]]\nname = \"ambient\"\ntemp_c = 23.0\n";

    #[test]
    fn writes_values_keeping_comments() {
        let ovs: Vec<Override> = [
            "thermal.nodes[\"sump\"].mass_kg = 9.5",
            "thermal.initial_temp_c = 30.0",
            "thermal.nodes[\"sump\"].initial_temp_c = 31.5",
            "losses.multiplier.churning = 1.5",
        ]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
        let series = vec![("ambient".to_string(), vec![(0.0, 20.0), (600.0, 21.5)])];
        let out = calibrated_text(TEXT, &ovs, &series).unwrap();
        assert!(out.contains("mass_kg = 9.5 # ATF"), "{out}");
        assert!(out.contains("initial_temp_c = 30.0 # cold"), "{out}");
        assert!(out.contains("initial_temp_c = 31.5"), "{out}");
        assert!(out.contains("series = [[0.0, 20.0], [600.0, 21.5]]"), "{out}");
        assert!(!out.contains("temp_c = 23.0\n"), "{out}");
        let doc: toml::Table = out.parse().unwrap();
        assert_eq!(doc["losses"]["multiplier"]["churning"].as_float(), Some(1.5));
        assert_eq!(doc["thermal"]["nodes"][0]["mass_kg"].as_float(), Some(9.5));
    }
}
