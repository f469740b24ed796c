//! Sampling plans: full grid, Latin hypercube (seeded, deterministic on every machine), explicit
//! list. A sample is one value per parameter; a range or scale parameter's value is a number (for
//! a scale: the factor), a `values` parameter's value is one of its values.

use super::spec::{ParamSpec, Plan, Sampling};
use super::ParamValue;

/// Largest number of samples a plan may produce (and of cases a study may have).
pub const MAX_SAMPLES: usize = 10_000_000;

/// Largest number of sampled values (samples × parameters) a plan may hold: each is a
/// `ParamValue` (`size_of` 24 bytes on a 64-bit target) in its sample's row, so this bounds the
/// values of a plan to about half a gigabyte besides the rows' own vectors and any texts.
pub const MAX_SAMPLED_VALUES: usize = 20_000_000;

/// Refuse `n` samples of `params` parameters beyond [`MAX_SAMPLED_VALUES`], before building.
fn check_values(n: usize, params: usize) -> Result<(), String> {
    match n.checked_mul(params) {
        Some(v) if v <= MAX_SAMPLED_VALUES => Ok(()),
        _ => Err(format!(
            "{n} samples × {params} parameters: more than {MAX_SAMPLED_VALUES} sampled values \
             (about 1 GB); use fewer samples or parameters"
        )),
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): a small, fast generator with a fixed, documented
/// sequence, so a seed gives the same plan on every platform and version.
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform integer in [0, n) (n > 0), by rejection (no modulo bias).
    pub fn below(&mut self, n: u64) -> u64 {
        let zone = u64::MAX - u64::MAX % n;
        loop {
            let r = self.next_u64();
            if r < zone {
                return r % n;
            }
        }
    }
}

/// The value range of a continuous parameter (range or scale).
fn interval(p: &ParamSpec) -> Option<[f64; 2]> {
    p.range.or(p.scale)
}

/// Check one parameter: exactly one of values / range / scale, finite bounds lo ≤ hi.
pub fn check_param(p: &ParamSpec) -> Result<(), String> {
    let given = [p.values.is_some(), p.range.is_some(), p.scale.is_some()];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(format!(
            "parameter {}: give exactly one of values, range, scale",
            p.path
        ));
    }
    if let Some(v) = &p.values {
        if v.is_empty() {
            return Err(format!("parameter {}: values is empty", p.path));
        }
        if v.iter()
            .any(|x| matches!(x, ParamValue::Number(f) if !f.is_finite()))
        {
            return Err(format!("parameter {}: values must be finite", p.path));
        }
    }
    if p.factors && p.values.is_none() {
        return Err(format!("parameter {}: factors = true needs values", p.path));
    }
    if let Some([lo, hi]) = interval(p) {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(format!(
                "parameter {}: [{lo}, {hi}] must be finite with lo ≤ hi",
                p.path
            ));
        }
    }
    match p.levels {
        Some(0) => Err(format!("parameter {}: levels must be ≥ 1", p.path)),
        Some(n) if n > MAX_SAMPLES => Err(format!(
            "parameter {}: levels = {n}: must lie in [1, {MAX_SAMPLES}]",
            p.path
        )),
        _ => Ok(()),
    }
}

/// How many levels a parameter has on a grid (without building them).
fn level_count(p: &ParamSpec) -> usize {
    p.values.as_ref().map_or(p.levels.unwrap_or(3), Vec::len)
}

fn levels(p: &ParamSpec) -> Vec<ParamValue> {
    if let Some(v) = &p.values {
        return v.clone();
    }
    let [lo, hi] = interval(p).unwrap_or([0.0, 0.0]);
    let n = p.levels.unwrap_or(3);
    (0..n)
        .map(|k| {
            let x = if n == 1 {
                0.5 * (lo + hi)
            } else {
                lo + (hi - lo) * k as f64 / (n - 1) as f64
            };
            ParamValue::Number(x)
        })
        .collect()
}

/// Full factorial over the parameters' levels, the first parameter varying slowest.
fn grid(params: &[ParamSpec]) -> Result<Vec<Vec<ParamValue>>, String> {
    // The size is checked from the level counts before any level or sample is built.
    let total = params
        .iter()
        .try_fold(1usize, |acc, p| {
            acc.checked_mul(level_count(p)).filter(|&t| t <= MAX_SAMPLES)
        })
        .ok_or_else(|| format!("the grid has more than {MAX_SAMPLES} cases"))?;
    check_values(total, params.len())?;
    let lv: Vec<Vec<ParamValue>> = params.iter().map(levels).collect();
    Ok((0..total)
        .map(|mut k| {
            let mut s = vec![ParamValue::Number(0.0); lv.len()];
            for (j, l) in lv.iter().enumerate().rev() {
                s[j] = l[k % l.len()].clone();
                k /= l.len();
            }
            s
        })
        .collect())
}

/// Latin hypercube (McKay, Beckman & Conover 1979): each parameter's [0, 1) is cut into `n`
/// strata, each stratum used once, in an independent random order per parameter, with a random
/// point inside the stratum. A `values` parameter takes value ⌊u·k⌋ of its k values, so every
/// value appears n/k times (±1).
fn lhs(params: &[ParamSpec], n: usize, seed: u64) -> Vec<Vec<ParamValue>> {
    let mut rng = SplitMix64::new(seed);
    let mut cols: Vec<Vec<ParamValue>> = Vec::with_capacity(params.len());
    for p in params {
        let mut perm: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = rng.below(i as u64 + 1) as usize;
            perm.swap(i, j);
        }
        let col = perm
            .iter()
            .map(|&stratum| {
                let u = (stratum as f64 + rng.unit()) / n as f64;
                match (&p.values, interval(p)) {
                    (Some(v), _) => v[((u * v.len() as f64) as usize).min(v.len() - 1)].clone(),
                    (None, Some([lo, hi])) => ParamValue::Number(lo + (hi - lo) * u),
                    (None, None) => ParamValue::Number(0.0),
                }
            })
            .collect();
        cols.push(col);
    }
    (0..n)
        .map(|i| cols.iter().map(|c| c[i].clone()).collect())
        .collect()
}

fn list(params: &[ParamSpec]) -> Result<Vec<Vec<ParamValue>>, String> {
    let mut n = None;
    for p in params {
        let v = p
            .values
            .as_ref()
            .ok_or_else(|| format!("parameter {}: the list plan needs values", p.path))?;
        match n {
            None => n = Some(v.len()),
            Some(m) if m != v.len() => {
                return Err(format!(
                    "parameter {}: {} values, the other parameters have {m} (the list plan pairs them)",
                    p.path,
                    v.len()
                ))
            }
            _ => {}
        }
    }
    let n = n.unwrap_or(0);
    Ok((0..n)
        .map(|k| {
            params
                .iter()
                .map(|p| {
                    p.values
                        .as_ref()
                        .map_or(ParamValue::Number(0.0), |v| v[k].clone())
                })
                .collect()
        })
        .collect())
}

/// The samples of a plan.
pub fn samples(params: &[ParamSpec], s: &Sampling) -> Result<Vec<Vec<ParamValue>>, String> {
    for p in params {
        check_param(p)?;
    }
    match s.plan {
        Plan::Grid => grid(params),
        Plan::List => list(params),
        Plan::Qmc | Plan::Saltelli => Err(
            "sampling.plan: the qmc and saltelli plans sample the [uncertainty] inputs; \
                                           the study file has no [uncertainty]"
                .into(),
        ),
        Plan::Lhs => {
            let n = s.cases.ok_or("sampling: the lhs plan needs `cases`")?;
            if n == 0 || n > MAX_SAMPLES {
                return Err(format!("sampling.cases = {n}: must lie in [1, {MAX_SAMPLES}]"));
            }
            check_values(n, params.len())?;
            Ok(lhs(params, n, s.seed))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(path: &str, lo: f64, hi: f64) -> ParamSpec {
        ParamSpec {
            path: path.into(),
            values: None,
            range: Some([lo, hi]),
            scale: None,
            levels: None,
            factors: false,
        }
    }

    fn values(path: &str, v: &[&str]) -> ParamSpec {
        ParamSpec {
            path: path.into(),
            values: Some(v.iter().map(|s| ParamValue::Text(s.to_string())).collect()),
            range: None,
            scale: None,
            levels: None,
            factors: false,
        }
    }

    #[test]
    fn grid_is_the_full_product() {
        let p = vec![range("a", 0.0, 1.0), values("b", &["x", "y"])];
        let s = samples(&p, &Sampling::default()).unwrap();
        assert_eq!(s.len(), 6);
        assert_eq!(s[0], vec![ParamValue::Number(0.0), ParamValue::Text("x".into())]);
        assert_eq!(s[1], vec![ParamValue::Number(0.0), ParamValue::Text("y".into())]);
        assert_eq!(s[5], vec![ParamValue::Number(1.0), ParamValue::Text("y".into())]);
    }

    #[test]
    fn a_huge_grid_is_refused_before_it_is_built() {
        // 1e9 levels would take about 30 GB as samples: refused from the count alone.
        let mut big = range("a", 0.0, 1.0);
        big.levels = Some(1_000_000_000);
        let e = samples(&[big], &Sampling::default()).unwrap_err();
        assert!(e.contains("levels = 1000000000"), "{e}");
        let mut a = range("a", 0.0, 1.0);
        a.levels = Some(5_000);
        let mut b = range("b", 0.0, 1.0);
        b.levels = Some(5_000);
        let e = samples(&[a, b], &Sampling::default()).unwrap_err();
        assert!(e.contains("more than 10000000 cases"), "{e}");
    }

    /// 10⁷ LHS samples of 64 parameters would hold 6.4·10⁸ values (about 35 GB): refused from
    /// the counts, before any value is drawn; so is a grid within the case limit whose
    /// parameters multiply its values beyond the limit.
    #[test]
    fn a_plan_with_too_many_values_is_refused_before_it_is_built() {
        let params: Vec<ParamSpec> = (0..64).map(|k| range(&format!("p{k}"), 0.0, 1.0)).collect();
        let lhs = Sampling {
            plan: Plan::Lhs,
            cases: Some(MAX_SAMPLES),
            seed: 1,
        };
        let e = samples(&params, &lhs).unwrap_err();
        assert!(e.contains("10000000 samples × 64 parameters"), "{e}");
        let mut big = range("a", 0.0, 1.0);
        big.levels = Some(MAX_SAMPLES);
        let mut grid = vec![big];
        grid.extend((0..2).map(|k| values(&format!("v{k}"), &["x"])));
        let e = samples(&grid, &Sampling::default()).unwrap_err();
        assert!(e.contains("× 3 parameters"), "{e}");
    }

    #[test]
    fn lhs_uses_every_stratum_once_and_is_reproducible() {
        let p = vec![
            range("a", 10.0, 20.0),
            values("b", &["x", "y", "z", "w"]),
            range("c", 0.0, 1.0),
        ];
        let s = Sampling {
            plan: Plan::Lhs,
            cases: Some(40),
            seed: 7,
        };
        let a = samples(&p, &s).unwrap();
        assert_eq!(a, samples(&p, &s).unwrap());
        let other = samples(&p, &Sampling { seed: 8, ..s.clone() }).unwrap();
        assert_ne!(a, other);
        for col in [0, 2] {
            let mut strata: Vec<usize> = a
                .iter()
                .map(|r| match r[col] {
                    ParamValue::Number(x) => {
                        let (lo, hi) = if col == 0 { (10.0, 20.0) } else { (0.0, 1.0) };
                        ((x - lo) / (hi - lo) * 40.0) as usize
                    }
                    _ => panic!(),
                })
                .collect();
            strata.sort();
            assert_eq!(strata, (0..40).collect::<Vec<_>>());
        }
        for v in ["x", "y", "z", "w"] {
            let k = a.iter().filter(|r| r[1] == ParamValue::Text(v.into())).count();
            assert_eq!(k, 10, "{v}");
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        let mut p = range("a", 2.0, 1.0);
        assert!(samples(&[p.clone()], &Sampling::default()).is_err());
        p.range = Some([0.0, 1.0]);
        p.scale = Some([0.0, 1.0]);
        assert!(samples(&[p], &Sampling::default()).is_err());
        let lhs = Sampling {
            plan: Plan::Lhs,
            cases: None,
            seed: 1,
        };
        assert!(samples(&[range("a", 0.0, 1.0)], &lhs).is_err());
        let l = Sampling {
            plan: Plan::List,
            ..Sampling::default()
        };
        assert!(samples(&[values("a", &["x"]), values("b", &["x", "y"])], &l).is_err());
    }
}
