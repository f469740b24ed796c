//! Priors on fitted parameters and the maximum a posteriori (MAP) fit.
//!
//! A prior is normal on the value, p ~ N(mean, sd²), or log-normal, ln p ~ N(ln median,
//! sd_ln²). The MAP fit minimises Σ_c Σ_t (r_ct/w_c)² + Σ_k ρ_k(θ)², ρ_k = (g(p_k) − μ_k)/s_k
//! (g the identity or ln), the negative log posterior of Gaussian data and prior up to a
//! constant (Gelman et al., Bayesian Data Analysis, 3rd ed., 2013, §4.1: the normal
//! approximation at the posterior mode). The data rows are scaled by each channel's noise w_c,
//! estimated from the fit without priors (docs/calibration.md, "Priors"). The posterior
//! covariance is (I_data + I_prior)⁻¹ with I_data the inverse of the data's covariance of the
//! estimate and I_prior = diag((∂ρ_k/∂θ_k)²).
//!
//! Given as `KEYPATH=normal:MEAN:SD` or `KEYPATH=lognormal:MEDIAN:SD_LN` (`--prior`), or in a
//! TOML file (`--priors FILE`) of `[[prior]]` tables with `key`, `distribution` and `mean`,
//! `sd` or `median`, `sd_ln`.

use nalgebra::{DMatrix, DVector};
use toml::Value;

use super::lm::Evaluation;
use super::params::{canonical, Parameter};
use crate::job::JobError;
use crate::model::overrides::KeyPath;

/// The distribution of a prior.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// p ~ N(location, width²).
    Normal,
    /// ln p ~ N(ln location, width²).
    Lognormal,
}

/// One prior as given.
#[derive(Debug, Clone, PartialEq)]
pub struct PriorSpec {
    /// Key path.
    pub path: KeyPath,
    /// Distribution.
    pub kind: Kind,
    /// Mean (normal) or median (log-normal).
    pub location: f64,
    /// Standard deviation of p (normal) or of ln p (log-normal).
    pub width: f64,
    /// The argument as written, for messages.
    pub text: String,
    /// The trace of a per-trace parameter (`KEYPATH@TRACE=…`, a fit over several traces): its
    /// index, its name or `*`.
    pub owner: Option<String>,
}

fn bad_prior(text: &str, why: &str) -> JobError {
    JobError::option(
        "prior",
        text,
        "KEYPATH=normal:MEAN:SD or KEYPATH=lognormal:MEDIAN:SD_LN, SD > 0",
        format!("prior = {text}: {why}"),
    )
}

/// Check location and width; `what(field)` names a field in the message.
fn check_numbers(kind: Kind, location: f64, width: f64, what: &dyn Fn(&str) -> String) -> Result<(), String> {
    let (loc_name, width_name) = match kind {
        Kind::Normal => ("mean", "sd"),
        Kind::Lognormal => ("median", "sd_ln"),
    };
    if !location.is_finite() || (kind == Kind::Lognormal && location <= 0.0) {
        let allowed = if kind == Kind::Lognormal {
            "a finite number > 0 (a log-normal prior is on a positive value)"
        } else {
            "a finite number"
        };
        return Err(format!("{} = {location}: must be {allowed}", what(loc_name)));
    }
    if !(width.is_finite() && width > 0.0) {
        return Err(format!(
            "{} = {width}: the prior's width must be a finite number > 0",
            what(width_name)
        ));
    }
    Ok(())
}

impl std::str::FromStr for PriorSpec {
    type Err = JobError;

    fn from_str(s: &str) -> Result<Self, JobError> {
        let text = s.trim();
        let (path, rest) = text
            .rsplit_once('=')
            .ok_or_else(|| bad_prior(text, "no '=' between key path and distribution"))?;
        let (path, owner) = super::params::split_owner(path.trim());
        let path: KeyPath = path
            .trim()
            .parse()
            .map_err(|e| bad_prior(text, &format!("bad key path: {e}")))?;
        let parts: Vec<&str> = rest.split(':').map(str::trim).collect();
        let kind = match parts.first().copied() {
            Some("normal") => Kind::Normal,
            Some("lognormal") | Some("log-normal") => Kind::Lognormal,
            _ => return Err(bad_prior(text, "the distribution must be normal or lognormal")),
        };
        if parts.len() != 3 {
            return Err(bad_prior(text, "needs two numbers after the distribution"));
        }
        let num = |x: &str| {
            x.parse::<f64>()
                .map_err(|_| bad_prior(text, &format!("{x} is not a number")))
        };
        let (location, width) = (num(parts[1])?, num(parts[2])?);
        let names = |f: &str| format!("{f} ({})", parts[0]);
        check_numbers(kind, location, width, &names).map_err(|e| bad_prior(text, &e))?;
        Ok(PriorSpec {
            path,
            kind,
            location,
            width,
            text: text.to_string(),
            owner: owner.map(|o| o.trim().to_string()),
        })
    }
}

impl std::fmt::Display for PriorSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let k = match self.kind {
            Kind::Normal => "normal",
            Kind::Lognormal => "lognormal",
        };
        let at = self.owner.as_ref().map_or(String::new(), |o| format!("@{o}"));
        write!(f, "{}{at}={k}:{}:{}", self.path, self.location, self.width)
    }
}

/// A number of a `[[prior]]` table, by its field name.
fn field(t: &toml::Table, key: &str, at: &str) -> Result<f64, String> {
    match t.get(key) {
        Some(Value::Float(x)) => Ok(*x),
        Some(Value::Integer(i)) => Ok(*i as f64),
        Some(v) => Err(format!("{at}.{key} = {v}: must be a number")),
        None => Err(format!("{at}.{key}: missing")),
    }
}

/// One `[[prior]]` table of a priors file as a `--prior` argument.
fn file_entry(t: &toml::Table, at: &str) -> Result<String, String> {
    let key = t
        .get("key")
        .and_then(Value::as_str)
        .ok_or_else(|| format!("{at}.key: missing (the fitted parameter's key path, a string)"))?;
    let kind = match t.get("distribution").and_then(Value::as_str) {
        Some("normal") => Kind::Normal,
        Some("lognormal") => Kind::Lognormal,
        other => {
            return Err(format!(
                "{at}.distribution = {}: must be \"normal\" or \"lognormal\"",
                other.unwrap_or("(missing)")
            ))
        }
    };
    let allowed: &[&str] = match kind {
        Kind::Normal => &["key", "distribution", "mean", "sd"],
        Kind::Lognormal => &["key", "distribution", "median", "sd_ln"],
    };
    if let Some(k) = t.keys().find(|k| !allowed.contains(&k.as_str())) {
        return Err(format!("{at}.{k}: unknown key (allowed: {})", allowed.join(", ")));
    }
    let (location, width) = match kind {
        Kind::Normal => (field(t, "mean", at)?, field(t, "sd", at)?),
        Kind::Lognormal => (field(t, "median", at)?, field(t, "sd_ln", at)?),
    };
    check_numbers(kind, location, width, &|f| format!("{at}.{f}"))?;
    super::params::split_owner(key)
        .0
        .parse::<KeyPath>()
        .map_err(|e| format!("{at}.key = {key:?}: bad key path: {e}"))?;
    let name = if kind == Kind::Normal {
        "normal"
    } else {
        "lognormal"
    };
    Ok(format!("{key}={name}:{location}:{width}"))
}

/// The priors of a priors file (`[[prior]]` tables) as `--prior` arguments; every problem is
/// invalid input naming the file and the key path (`prior[1].sd`).
pub fn from_file(text: &str, file: &str) -> Result<Vec<String>, JobError> {
    let bad = |m: String| JobError::invalid(format!("{file}: {m}"));
    let doc: toml::Table = text.parse().map_err(|e| bad(format!("not TOML: {e}")))?;
    if let Some(k) = doc.keys().find(|k| k.as_str() != "prior") {
        return Err(bad(format!(
            "{k}: unknown key (a priors file holds [[prior]] tables)"
        )));
    }
    let list = match doc.get("prior") {
        Some(Value::Array(a)) => a,
        _ => return Err(bad("no [[prior]] table".into())),
    };
    list.iter()
        .enumerate()
        .map(|(i, v)| {
            let at = format!("prior[{i}]");
            let t = v
                .as_table()
                .ok_or_else(|| bad(format!("{at}: must be a table")))?;
            file_entry(t, &at).map_err(bad)
        })
        .collect()
}

/// A prior resolved against the fitted parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    /// Index of the parameter.
    pub param: usize,
    /// The spec.
    pub spec: PriorSpec,
}

/// The priors of a calibration, resolved.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Priors {
    /// One per parameter at most.
    pub list: Vec<Prior>,
}

impl Priors {
    /// Resolve the specs against the fitted parameters (by their canonical key paths in `doc`):
    /// a prior on a key not fitted, two priors on one parameter, or a log-normal prior on a
    /// parameter whose range reaches zero is invalid input naming the key path.
    pub fn resolve(specs: &[PriorSpec], params: &[Parameter], doc: &toml::Table) -> Result<Priors, JobError> {
        let canon: Vec<KeyPath> = params.iter().map(|p| canonical(&p.path, doc)).collect();
        let mut out = Priors::default();
        for s in specs {
            if let Some(o) = &s.owner {
                return Err(bad_prior(
                    &s.text,
                    &format!("@{o} names a trace, but one trace is fitted: a prior of one trace's parameter needs several --trace"),
                ));
            }
            let c = canonical(&s.path, doc);
            let Some(k) = canon.iter().position(|x| *x == c) else {
                return Err(bad_prior(
                    &s.text,
                    &format!("{} is not a fitted parameter (add it to fit)", s.path),
                ));
            };
            out.add(s, k, &params[k])?;
        }
        Ok(out)
    }

    /// Add the prior `s` on parameter `k` (`p`): refused when `p` has a prior already, or for a
    /// log-normal prior on a range that reaches zero.
    pub fn add(&mut self, s: &PriorSpec, k: usize, p: &Parameter) -> Result<(), JobError> {
        if self.list.iter().any(|q| q.param == k) {
            return Err(bad_prior(&s.text, &format!("{} has two priors", p.name())));
        }
        if s.kind == Kind::Lognormal && p.lo <= 0.0 {
            return Err(bad_prior(
                &s.text,
                &format!(
                    "a log-normal prior needs a positive parameter; {} may take values in [{}, {}], which \
                     reaches zero or below",
                    p.name(),
                    p.lo,
                    p.hi
                ),
            ));
        }
        self.list.push(Prior {
            param: k,
            spec: s.clone(),
        });
        Ok(())
    }

    /// A prior's refusal (invalid input naming the argument).
    pub fn refuse(s: &PriorSpec, why: &str) -> JobError {
        bad_prior(&s.text, why)
    }

    /// No prior.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// ρ_k(θ) and ∂ρ_k/∂θ_k of prior `q`.
    fn residual(&self, q: &Prior, params: &[Parameter], theta: &[f64]) -> (f64, f64) {
        let p = &params[q.param];
        let th = theta[q.param];
        let v = p.value(th);
        let dv = if p.log { v } else { 1.0 };
        let s = &q.spec;
        match s.kind {
            Kind::Normal => ((v - s.location) / s.width, dv / s.width),
            Kind::Lognormal => ((v.ln() - s.location.ln()) / s.width, dv / (v * s.width)),
        }
    }

    /// The prior's standard deviation in the fitted coordinate at θ (linearised).
    pub fn sd_theta(&self, q: &Prior, params: &[Parameter], theta: &[f64]) -> f64 {
        1.0 / self.residual(q, params, theta).1.abs()
    }

    /// The prior information diag((∂ρ_k/∂θ_k)²) at θ.
    pub fn information(&self, params: &[Parameter], theta: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; params.len()];
        for q in &self.list {
            out[q.param] = self.residual(q, params, theta).1.powi(2);
        }
        out
    }

    /// Append the prior rows to an evaluation at θ.
    pub fn augment(&self, e: Evaluation, params: &[Parameter], theta: &[f64]) -> Evaluation {
        if self.list.is_empty() {
            return e;
        }
        let (m, np) = e.j.shape();
        let n = m + self.list.len();
        let mut r = DVector::zeros(n);
        r.rows_mut(0, m).copy_from(&e.r);
        let mut j = DMatrix::zeros(n, np);
        j.rows_mut(0, m).copy_from(&e.j);
        for (i, q) in self.list.iter().enumerate() {
            let (rho, d) = self.residual(q, params, theta);
            r[m + i] = rho;
            j[(m + i, q.param)] = d;
        }
        Evaluation { r, j }
    }

    /// The evaluation without the prior rows.
    pub fn strip(&self, e: Evaluation) -> Evaluation {
        let m = e.r.len() - self.list.len();
        Evaluation {
            r: e.r.rows(0, m).into_owned(),
            j: e.j.rows(0, m).into_owned(),
        }
    }

    /// Σ ρ_k² at θ.
    pub fn cost(&self, params: &[Parameter], theta: &[f64]) -> f64 {
        self.list
            .iter()
            .map(|q| self.residual(q, params, theta).0.powi(2))
            .sum()
    }
}

/// Each data row of `e` divided by its channel's noise scale (rows ordered row-major over
/// `weights.len()` channels).
pub fn weighted(mut e: Evaluation, weights: &[f64]) -> Evaluation {
    let nc = weights.len();
    for k in 0..e.r.len() {
        let w = weights[k % nc];
        e.r[k] /= w;
        for c in 0..e.j.ncols() {
            e.j[(k, c)] /= w;
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_refuse() {
        let s: PriorSpec = "losses.multiplier.churning=lognormal:1:0.5".parse().unwrap();
        assert_eq!(s.kind, Kind::Lognormal);
        assert_eq!((s.location, s.width), (1.0, 0.5));
        let s: PriorSpec = "thermal.links[\"a=b\"].h_w_per_m2k=normal:5:2".parse().unwrap();
        assert_eq!(s.path.to_string(), "thermal.links[\"a=b\"].h_w_per_m2k");
        for bad in [
            "x=normal:1:-1",
            "x=normal:1:0",
            "x=lognormal:-1:0.5",
            "x=cauchy:1:1",
            "x=normal:1",
            "x=normal:a:1",
        ] {
            let e = bad.parse::<PriorSpec>().unwrap_err();
            assert!(e.to_string().contains(bad), "{e}");
        }
        let e = "x=normal:1:-1".parse::<PriorSpec>().unwrap_err().to_string();
        assert!(e.contains("sd") && e.contains("> 0"), "{e}");
    }

    #[test]
    fn files_name_the_key_path() {
        let ok = "[[prior]]\nkey = 'losses.multiplier.churning'\ndistribution = 'lognormal'\nmedian = 1\nsd_ln = 0.5\n";
        assert_eq!(
            from_file(ok, "p.toml").unwrap(),
            vec!["losses.multiplier.churning=lognormal:1:0.5".to_string()]
        );
        let bad = format!("{ok}[[prior]]\nkey = 'a.b'\ndistribution = 'normal'\nmean = 1\nsd = -2\n");
        let e = from_file(&bad, "p.toml").unwrap_err().to_string();
        assert!(e.contains("p.toml: prior[1].sd = -2"), "{e}");
        // A trace's own parameter (a fit over several traces) keeps its @TRACE.
        let own = "[[prior]]\nkey = 'a.b@t1'\ndistribution = 'normal'\nmean = 1\nsd = 2\n";
        assert_eq!(
            from_file(own, "p.toml").unwrap(),
            vec!["a.b@t1=normal:1:2".to_string()]
        );
        let e = from_file(
            "[[prior]]\nkey='a'\ndistribution='normal'\nmean=1\nsd=1\nmedian=2\n",
            "p.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("prior[0].median: unknown key"), "{e}");
    }
}
