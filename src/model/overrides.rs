//! Overrides by key path: `lubrication.oil_level_mm = 55`, `oil.catalogue = "fva_3a"`,
//! `gears[2].face_width_mm = 26`, `thermal.links["housing-air"].area_m2 = 0.9`.
//!
//! An override is applied to the parsed TOML document *before* the typed deserialisation and the
//! validation, so an overridden value meets exactly the checks and messages a value written in the
//! file meets. The right-hand side is a TOML value (strings in quotes, arrays, inline tables).
//!
//! Path grammar: steps separated by `.`; a step is a bare key (`[A-Za-z0-9_-]+`) or a quoted key
//! (`"a key"`), followed by any number of selectors: `[N]` (array index, from 0) or `["name"]`
//! (the element of an array of tables whose `name` is that string).

use std::fmt;
use std::str::FromStr;

use toml::{Table, Value};

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step {
    /// A key of a table.
    Key(String),
    /// An array index.
    Index(usize),
    /// The element of an array of tables whose `name` equals this.
    Named(String),
}

/// A key path into the model document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPath(pub Vec<Step>);

fn is_bare(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-'
}

fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Step::Key(k) => {
                    if i > 0 {
                        f.write_str(".")?;
                    }
                    if !k.is_empty() && k.chars().all(is_bare) {
                        f.write_str(k)?;
                    } else {
                        f.write_str(&quote(k))?;
                    }
                }
                Step::Index(n) => write!(f, "[{n}]")?,
                Step::Named(n) => write!(f, "[{}]", quote(n))?,
            }
        }
        Ok(())
    }
}

/// Read a quoted string starting at `chars[*i] == '"'`; advances past the closing quote.
fn quoted(chars: &[char], i: &mut usize) -> Result<String, String> {
    let mut out = String::new();
    *i += 1;
    while *i < chars.len() {
        match chars[*i] {
            '"' => {
                *i += 1;
                return Ok(out);
            }
            '\\' if *i + 1 < chars.len() => {
                out.push(chars[*i + 1]);
                *i += 2;
            }
            c => {
                out.push(c);
                *i += 1;
            }
        }
    }
    Err("unterminated quoted key".into())
}

fn selector(chars: &[char], i: &mut usize) -> Result<Step, String> {
    *i += 1; // '['
    let step = if chars.get(*i) == Some(&'"') {
        Step::Named(quoted(chars, i)?)
    } else {
        let start = *i;
        while *i < chars.len() && chars[*i].is_ascii_digit() {
            *i += 1;
        }
        let digits: String = chars[start..*i].iter().collect();
        let n = digits
            .parse::<usize>()
            .map_err(|_| "expected an index [N] or a name [\"name\"] after '['".to_string())?;
        Step::Index(n)
    };
    if chars.get(*i) != Some(&']') {
        return Err("missing ']'".into());
    }
    *i += 1;
    Ok(step)
}

impl FromStr for KeyPath {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let chars: Vec<char> = s.trim().chars().collect();
        let mut steps = Vec::new();
        let mut i = 0;
        loop {
            // A key.
            let key = match chars.get(i) {
                Some('"') => quoted(&chars, &mut i)?,
                Some(c) if is_bare(*c) => {
                    let start = i;
                    while i < chars.len() && is_bare(chars[i]) {
                        i += 1;
                    }
                    chars[start..i].iter().collect()
                }
                Some(c) => return Err(format!("unexpected '{c}' at position {}", i + 1)),
                None => return Err("empty key".into()),
            };
            steps.push(Step::Key(key));
            while chars.get(i) == Some(&'[') {
                steps.push(selector(&chars, &mut i)?);
            }
            match chars.get(i) {
                None => break,
                Some('.') => i += 1,
                Some(c) => return Err(format!("unexpected '{c}' at position {}", i + 1)),
            }
        }
        Ok(KeyPath(steps))
    }
}

/// One override: a key path and a TOML value.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// Where.
    pub path: KeyPath,
    /// The new value.
    pub value: Value,
}

impl fmt::Display for Override {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}", self.path, self.value)
    }
}

/// Parse the right-hand side of an override as one TOML value.
pub fn parse_value(text: &str) -> Result<Value, String> {
    let doc: Table = format!("v = {}", text.trim())
        .parse()
        .map_err(|e: toml::de::Error| {
            format!(
                "`{}` is not a TOML value ({}); strings need quotes, e.g. oil.catalogue = \"fva_3a\"",
                text.trim(),
                e.message()
            )
        })?;
    match (doc.len(), doc.get("v")) {
        (1, Some(v)) => Ok(v.clone()),
        _ => Err(format!("`{}` is not a single TOML value", text.trim())),
    }
}

impl FromStr for Override {
    type Err = String;

    /// `path = value` (the first `=` outside quotes and brackets separates them).
    fn from_str(s: &str) -> Result<Self, String> {
        let (mut in_quotes, mut depth, mut split) = (false, 0i32, None);
        let mut prev = ' ';
        for (k, c) in s.char_indices() {
            match c {
                '"' if prev != '\\' => in_quotes = !in_quotes,
                '[' if !in_quotes => depth += 1,
                ']' if !in_quotes => depth -= 1,
                '=' if !in_quotes && depth == 0 => {
                    split = Some(k);
                    break;
                }
                _ => {}
            }
            prev = c;
        }
        let k = split.ok_or_else(|| format!("override `{s}`: expected PATH = VALUE"))?;
        let path: KeyPath = s[..k]
            .parse()
            .map_err(|e| format!("override `{s}`: bad key path `{}`: {e}", s[..k].trim()))?;
        let value = parse_value(&s[k + 1..]).map_err(|e| format!("override `{s}`: {e}"))?;
        Ok(Override { path, value })
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Table(_) => "a table",
        Value::Array(_) => "an array",
        _ => "a value",
    }
}

/// Walk `steps` inside `root`, creating missing tables for `Key` steps when `create`; returns the
/// value and the canonical path (names resolved to indices) walked so far.
fn walk<'a>(
    root: &'a mut Value,
    steps: &[Step],
    create: bool,
    canon: &mut Vec<Step>,
) -> Result<&'a mut Value, String> {
    let mut cur = root;
    for step in steps {
        let here = KeyPath(canon.clone()).to_string();
        let at = if here.is_empty() {
            "the model".to_string()
        } else {
            here
        };
        cur = match step {
            Step::Key(k) => {
                let found = kind(cur);
                let t = cur
                    .as_table_mut()
                    .ok_or_else(|| format!("{at} is {found}, not a table: no key `{k}`"))?;
                if !t.contains_key(k) {
                    if !create {
                        let keys: Vec<&str> = t.keys().map(String::as_str).collect();
                        return Err(format!("{at} has no key `{k}` (it has: {})", keys.join(", ")));
                    }
                    t.insert(k.clone(), Value::Table(Table::new()));
                }
                canon.push(step.clone());
                t.get_mut(k).expect("inserted above")
            }
            Step::Index(n) => {
                let found = kind(cur);
                let a = cur
                    .as_array_mut()
                    .ok_or_else(|| format!("{at} is {found}, not an array: no index [{n}]"))?;
                let len = a.len();
                canon.push(step.clone());
                a.get_mut(*n).ok_or_else(|| {
                    format!(
                        "{at}[{n}]: index out of range ({len} entries, indices 0..{})",
                        len.max(1) - 1
                    )
                })?
            }
            Step::Named(name) => {
                let found = kind(cur);
                let a = cur
                    .as_array_mut()
                    .ok_or_else(|| format!("{at} is {found}, not an array of tables"))?;
                let names: Vec<String> = a
                    .iter()
                    .filter_map(|e| e.get("name").and_then(Value::as_str).map(str::to_string))
                    .collect();
                let pos = a
                    .iter()
                    .position(|e| e.get("name").and_then(Value::as_str) == Some(name))
                    .ok_or_else(|| {
                        format!("{at} has no entry named \"{name}\" (names: {})", names.join(", "))
                    })?;
                canon.push(Step::Index(pos));
                &mut a[pos]
            }
        };
    }
    Ok(cur)
}

/// Apply one override to a parsed model document. Intermediate tables that are missing are
/// created (an optional section not written in the file); arrays and named entries must exist.
/// The last key may be new: whether the schema knows it is decided by the deserialisation, with
/// its usual message. Returns the canonical path (named entries as indices), the form validation
/// messages use.
pub fn apply(doc: &mut Table, ov: &Override) -> Result<String, String> {
    let steps = &ov.path.0;
    let (last, parents) = steps.split_last().ok_or("empty key path")?;
    let mut root = Value::Table(std::mem::take(doc));
    let mut canon = Vec::new();
    let result = (|| -> Result<String, String> {
        let parent = walk(&mut root, parents, true, &mut canon)?;
        match last {
            Step::Key(k) => {
                let at = KeyPath(canon.clone()).to_string();
                let found = kind(parent);
                let t = parent
                    .as_table_mut()
                    .ok_or_else(|| format!("{at} is {found}, not a table: no key `{k}`"))?;
                t.insert(k.clone(), ov.value.clone());
                canon.push(last.clone());
            }
            _ => {
                let slot = walk(parent, std::slice::from_ref(last), false, &mut canon)?;
                *slot = ov.value.clone();
            }
        }
        Ok(KeyPath(canon.clone()).to_string())
    })();
    if let Value::Table(t) = root {
        *doc = t;
    }
    result.map_err(|e| format!("override `{ov}`: {e}"))
}

/// The value at a key path of a parsed document (names resolved), or why there is none.
pub fn get(doc: &Table, path: &KeyPath) -> Result<Value, String> {
    let mut root = Value::Table(doc.clone());
    let v = walk(&mut root, &path.0, false, &mut Vec::new())?;
    Ok(v.clone())
}

/// Scale a number or (nested) array of numbers.
pub fn scaled(v: &Value, f: f64) -> Result<Value, String> {
    match v {
        Value::Integer(i) => Ok(Value::Float(*i as f64 * f)),
        Value::Float(x) => Ok(Value::Float(x * f)),
        Value::Array(a) => a
            .iter()
            .map(|x| scaled(x, f))
            .collect::<Result<Vec<_>, _>>()
            .map(Value::Array),
        other => Err(format!(
            "a scale parameter needs a number or an array of numbers, found {other}"
        )),
    }
}

/// Whether a problem at `problem_path` concerns the override at canonical path `canon`: the same
/// key, inside it, or one of its parents.
pub fn concerns(problem_path: &str, canon: &str) -> bool {
    let inside = |a: &str, b: &str| {
        a == b || (a.starts_with(b) && matches!(a.as_bytes().get(b.len()), Some(b'.') | Some(b'[')))
    };
    !problem_path.is_empty() && (inside(problem_path, canon) || inside(canon, problem_path))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Table {
        r#"
[lubrication]
oil_level_mm = 60.0
[[gears]]
name = "sun"
face_width_mm = 20.0
[[gears]]
name = "ring"
face_width_mm = 22.0
[thermal]
[[thermal.links]]
name = "housing-air"
area_m2 = 0.7
"#
        .parse()
        .unwrap()
    }

    #[test]
    fn parses_paths_with_indices_and_names() {
        let p: KeyPath = r#"thermal.links["housing-air"].area_m2"#.parse().unwrap();
        assert_eq!(
            p.0,
            vec![
                Step::Key("thermal".into()),
                Step::Key("links".into()),
                Step::Named("housing-air".into()),
                Step::Key("area_m2".into())
            ]
        );
        let p: KeyPath = "gears[2].face_width_mm".parse().unwrap();
        assert_eq!(p.0[1], Step::Index(2));
        assert_eq!(p.to_string(), "gears[2].face_width_mm");
    }

    #[test]
    fn rejects_malformed_paths() {
        for bad in ["", "a..b", "a[", "a[x]", "a[1", ".a", "a.", "a b", r#"a["x]"#] {
            assert!(bad.parse::<KeyPath>().is_err(), "{bad}");
        }
    }

    #[test]
    fn parses_overrides_with_toml_values() {
        let o: Override = r#"oil.catalogue = "fva_3a""#.parse().unwrap();
        assert_eq!(o.value.as_str(), Some("fva_3a"));
        let o: Override = "gears[2].face_width_mm=26".parse().unwrap();
        assert_eq!(o.value.as_integer(), Some(26));
        let o: Override = r#"thermal.links["a=b"].area_m2 = [1.0, 2.0]"#.parse().unwrap();
        assert_eq!(o.path.0[2], Step::Named("a=b".into()));
        assert!(o.value.is_array());
        let e = "oil.catalogue = fva_3a".parse::<Override>().unwrap_err();
        assert!(e.contains("strings need quotes"), "{e}");
        assert!("x = 1\ny = 2".parse::<Override>().is_err());
        assert!("x".parse::<Override>().is_err());
    }

    #[test]
    fn applies_by_index_and_by_name() {
        let mut d = doc();
        let c = apply(&mut d, &"gears[1].face_width_mm = 26".parse().unwrap()).unwrap();
        assert_eq!(c, "gears[1].face_width_mm");
        assert_eq!(d["gears"][1]["face_width_mm"].as_integer(), Some(26));
        let c = apply(&mut d, &r#"gears["sun"].face_width_mm = 18.5"#.parse().unwrap()).unwrap();
        assert_eq!(c, "gears[0].face_width_mm");
        assert_eq!(d["gears"][0]["face_width_mm"].as_float(), Some(18.5));
        let c = apply(
            &mut d,
            &r#"thermal.links["housing-air"].area_m2 = 0.9"#.parse().unwrap(),
        )
        .unwrap();
        assert_eq!(c, "thermal.links[0].area_m2");
        // A missing optional section is created.
        apply(&mut d, &"losses.sliding.mu = 0.05".parse().unwrap()).unwrap();
        assert_eq!(d["losses"]["sliding"]["mu"].as_float(), Some(0.05));
    }

    #[test]
    fn unknown_entries_are_rejected_with_what_exists() {
        let mut d = doc();
        let e = apply(&mut d, &"gears[5].face_width_mm = 1".parse().unwrap()).unwrap_err();
        assert!(e.contains("out of range") && e.contains("2 entries"), "{e}");
        let e = apply(&mut d, &r#"gears["planet"].face_width_mm = 1"#.parse().unwrap()).unwrap_err();
        assert!(
            e.contains("no entry named \"planet\"") && e.contains("sun, ring"),
            "{e}"
        );
        let e = apply(&mut d, &"lubrication.oil_level_mm.x = 1".parse().unwrap()).unwrap_err();
        assert!(e.contains("not a table"), "{e}");
        // Nothing was lost from the document on failure.
        assert_eq!(d, doc());
    }

    #[test]
    fn problem_paths_are_matched_to_overrides() {
        assert!(concerns("gears[1].face_width_mm", "gears[1].face_width_mm"));
        assert!(concerns("gears[1]", "gears[1].face_width_mm"));
        assert!(!concerns("gears[10].x", "gears[1].x"));
        assert!(!concerns("", "a"));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// Any path built from keys, indices and names prints and parses back to itself.
        #[test]
        fn path_round_trips(
            keys in proptest::collection::vec("[a-z_][a-z0-9_ -]{0,6}", 1..4),
            sel in proptest::collection::vec(proptest::option::of(0usize..50), 1..4),
            names in proptest::collection::vec("[ -~]{0,6}", 1..4),
        ) {
            let mut steps = Vec::new();
            for (i, k) in keys.iter().enumerate() {
                steps.push(Step::Key(k.clone()));
                match sel.get(i).copied().flatten() {
                    Some(n) if n % 2 == 0 => steps.push(Step::Index(n)),
                    Some(_) => steps.push(Step::Named(names[i % names.len()].clone())),
                    None => {}
                }
            }
            let p = KeyPath(steps);
            let back: KeyPath = p.to_string().parse().unwrap();
            proptest::prop_assert_eq!(back, p);
        }

        /// Arbitrary text never panics the parser.
        #[test]
        fn parser_never_panics(s in "[ -~]{0,40}") {
            let _ = s.parse::<Override>();
            let _ = s.parse::<KeyPath>();
        }
    }
}
