//! A job's stand-alone `geartherm` command line, rendered from its typed options (never
//! assembled elsewhere), and the shell quoting it needs. The CLI's tests parse every rendered
//! line back into the same options.

use std::path::Path;

use crate::model::Override;

use super::bench::BenchOptions;
use super::losses::LossesOptions;
use super::map::MapOptions;
use super::rating::RatingOptions;
use super::run::RunOptions;
use super::steady::SteadyOptions;
use super::validate::ValidateOptions;

/// Options that render as the arguments of a `geartherm` subcommand.
pub trait ToArgs {
    /// The subcommand (`run`, `steady`, …).
    const COMMAND: &'static str;
    /// The arguments after the model file (every option explicit, so that parsing them gives
    /// back the same options whatever the defaults).
    fn to_args(&self) -> Vec<String>;
}

/// `geartherm <command> <model> [--set …] <args>`, quoted for a POSIX shell.
pub fn command_line<T: ToArgs>(model: &Path, overrides: &[Override], options: &T) -> String {
    let mut words = vec!["geartherm".to_string(), T::COMMAND.to_string()];
    words.push(model.display().to_string());
    for o in overrides {
        words.push(super::options::flag("set"));
        words.push(o.to_string());
    }
    words.extend(options.to_args());
    join(&words)
}

/// Words joined by spaces, each quoted where a shell would split or expand it.
pub fn join(words: &[String]) -> String {
    words.iter().map(|w| quote(w)).collect::<Vec<_>>().join(" ")
}

/// One word for a POSIX shell: as is when it holds only safe characters, else in single quotes.
pub fn quote(w: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "-_./:,+=@%".contains(c);
    if !w.is_empty() && w.chars().all(safe) {
        w.to_string()
    } else {
        format!("'{}'", w.replace('\'', "'\\''"))
    }
}

/// Split a line written by [`join`] back into its words (single quotes and `'\''` only: the
/// inverse of [`quote`], not a shell).
pub fn split(line: &str) -> Result<Vec<String>, String> {
    let mut words = Vec::new();
    let mut cur: Option<String> = None;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            ' ' => words.extend(cur.take()),
            '\'' => {
                let w = cur.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(x) => w.push(x),
                        None => return Err(format!("unterminated quote in `{line}`")),
                    }
                }
            }
            '\\' => match chars.next() {
                Some(x) => cur.get_or_insert_with(String::new).push(x),
                None => return Err(format!("trailing backslash in `{line}`")),
            },
            x => cur.get_or_insert_with(String::new).push(x),
        }
    }
    words.extend(cur);
    Ok(words)
}

fn num(x: f64) -> String {
    // Rust's shortest round-trip form: parsing it gives back the same f64.
    format!("{x}")
}

/// Option `name` with its value, spelled as a flag ([`super::options::flag`]).
fn flag(out: &mut Vec<String>, name: &str, value: String) {
    out.push(super::options::flag(name));
    out.push(value);
}

fn opt(out: &mut Vec<String>, name: &str, value: Option<f64>) {
    if let Some(v) = value {
        flag(out, name, num(v));
    }
}

fn list(values: &[f64]) -> String {
    values.iter().map(|v| num(*v)).collect::<Vec<_>>().join(",")
}

impl ToArgs for LossesOptions {
    const COMMAND: &'static str = "losses";
    fn to_args(&self) -> Vec<String> {
        let mut a = Vec::new();
        flag(&mut a, "gear", self.gear.clone());
        flag(&mut a, "speed_rpm", num(self.speed_rpm));
        flag(&mut a, "torque_nm", num(self.torque_nm));
        flag(&mut a, "oil_temp_c", num(self.oil_temp_c));
        a
    }
}

impl ToArgs for RunOptions {
    const COMMAND: &'static str = "run";
    fn to_args(&self) -> Vec<String> {
        let mut a = Vec::new();
        flag(&mut a, "cycle", self.cycle.clone());
        flag(&mut a, "solver", self.solver.clone());
        flag(&mut a, "rtol", num(self.rtol));
        flag(&mut a, "atol", num(self.atol));
        opt(&mut a, "initial_temp_c", self.initial_temp_c);
        opt(&mut a, "ambient_c", self.ambient_c);
        opt(&mut a, "frozen_viscosity_c", self.frozen_viscosity_c);
        flag(&mut a, "max_steps", self.max_steps.to_string());
        if self.summary_only {
            a.push(super::options::flag("summary_only"));
        }
        if self.evaluate_all {
            a.push(super::options::flag("evaluate_all"));
        }
        if self.spread {
            a.push(super::options::flag("spread"));
        }
        a
    }
}

impl ToArgs for SteadyOptions {
    const COMMAND: &'static str = "steady";
    fn to_args(&self) -> Vec<String> {
        let mut a = Vec::new();
        flag(&mut a, "gear", self.gear.clone());
        flag(&mut a, "speed_rpm", num(self.speed_rpm));
        flag(&mut a, "torque_nm", num(self.torque_nm));
        flag(&mut a, "vehicle_speed_kmh", num(self.vehicle_speed_kmh));
        opt(&mut a, "ambient_c", self.ambient_c);
        a
    }
}

impl ToArgs for MapOptions {
    const COMMAND: &'static str = "map";
    fn to_args(&self) -> Vec<String> {
        let mut a = Vec::new();
        flag(&mut a, "gear", self.gear.clone());
        flag(&mut a, "speed_rpm", list(&self.speed_rpm));
        flag(&mut a, "torque_nm", list(&self.torque_nm));
        flag(&mut a, "vehicle_speed_kmh", num(self.vehicle_speed_kmh));
        opt(&mut a, "ambient_c", self.ambient_c);
        a
    }
}

impl ToArgs for RatingOptions {
    const COMMAND: &'static str = "rating";
    fn to_args(&self) -> Vec<String> {
        let mut a = Vec::new();
        flag(&mut a, "gear", self.gear.clone());
        flag(&mut a, "speed_rpm", list(&self.speed_rpm));
        flag(&mut a, "oil_limit_c", num(self.oil_limit_c));
        flag(&mut a, "vehicle_speed_kmh", num(self.vehicle_speed_kmh));
        opt(&mut a, "ambient_c", self.ambient_c);
        flag(&mut a, "torque_min_nm", num(self.torque_min_nm));
        opt(&mut a, "torque_max_nm", self.torque_max_nm);
        a
    }
}

impl ToArgs for BenchOptions {
    const COMMAND: &'static str = "bench";
    fn to_args(&self) -> Vec<String> {
        let mut a = Vec::new();
        flag(&mut a, "cycle", self.cycle.clone());
        flag(&mut a, "repeats", self.repeats.to_string());
        flag(&mut a, "min_rtol", num(self.min_rtol));
        flag(&mut a, "solvers", self.solvers.join(","));
        flag(&mut a, "max_steps", self.max_steps.to_string());
        a
    }
}

/// `geartherm validate DIR` (no model file).
pub fn validate_line(o: &ValidateOptions) -> String {
    join(&["geartherm".into(), "validate".into(), o.dir.display().to_string()])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quote_and_split_are_inverse() {
        let words: Vec<String> = [
            "a b",
            "it's",
            "",
            "x=1",
            "thermal.links[\"h-a\"].h = 2",
            "--rtol",
            "0.000001",
        ]
        .map(String::from)
        .to_vec();
        assert_eq!(split(&join(&words)).unwrap(), words);
    }
}
