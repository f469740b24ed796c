//! Reading a run's solver counters ([`Stats`]) back from `summary.json`. `Stats` names its
//! method by a `&'static str` (one of [`Method::ALL`]'s names), which serde cannot borrow from a
//! file: the counters are read by name here and the method through the name list. A counter
//! missing from the file (one an earlier version did not write) reads as 0 (`false`, `""`).

use serde::{Deserialize, Deserializer};

use crate::solve::trajectory::Stats;
use crate::solve::transient::Method;

/// The `stats` object of `summary.json` as [`Stats`]; a method name that is not one of
/// [`Method::ALL`] is an error naming it.
pub fn stats<'de, D: Deserializer<'de>>(d: D) -> Result<Stats, D::Error> {
    let map = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
    let count = |key: &str| -> Result<usize, D::Error> {
        match map.get(key) {
            None | Some(serde_json::Value::Null) => Ok(0),
            Some(v) => v
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| serde::de::Error::custom(format!("stats.{key}: {v} is not a count"))),
        }
    };
    let method = match map.get("method").and_then(|v| v.as_str()) {
        None => "",
        Some(name) => Method::ALL
            .into_iter()
            .map(Method::name)
            .find(|m| *m == name)
            .ok_or_else(|| serde::de::Error::custom(format!("stats.method: unknown method {name:?}")))?,
    };
    Ok(Stats {
        steps: count("steps")?,
        rejected: count("rejected")?,
        rhs_evals: count("rhs_evals")?,
        jac_evals: count("jac_evals")?,
        lu_factorisations: count("lu_factorisations")?,
        newton_iterations: count("newton_iterations")?,
        newton_failures: count("newton_failures")?,
        restarts: count("restarts")?,
        samples_prepared: count("samples_prepared")?,
        events: count("events")?,
        sparse: map.get("sparse").and_then(|v| v.as_bool()).unwrap_or(false),
        method,
    })
}
