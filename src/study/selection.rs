//! Which cases of a study a run solves: every case, a shard `I/N` (cases I, I+N, I+2N, …), or a
//! list of case indices. Built and checked here once, for the CLI (`--shard`, `--cases`), Python
//! (`shard=`, `cases=`) and the Dask path alike: every front end gets the same refusal with the
//! same message.

use std::collections::HashSet;

use crate::job::JobError;

use super::{Case, Study};

/// A selection of cases (checked against a study by [`Study::select`]).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Selection {
    /// Every case.
    #[default]
    All,
    /// Shard `index` of `count` (`0 ≤ index < count`): every `count`-th case from `index`; its
    /// journal is `journal.shard-<index>-of-<count>.jsonl`.
    Shard {
        /// Shard index, from 0.
        index: usize,
        /// Number of shards.
        count: usize,
    },
    /// These case indices (positions in the study's case list), each once; each must lie in
    /// `[0, N)` for a study of N cases ([`Study::select`]).
    Cases(Vec<i128>),
}

fn shard_error(text: &str) -> JobError {
    JobError::option(
        "shard",
        text,
        "I/N with 0 ≤ I < N",
        format!("shard = {text}: expected I/N with 0 ≤ I < N"),
    )
}

fn cases_error(value: &str, allowed: &str, message: String) -> JobError {
    JobError::option("cases", value, allowed, message)
}

/// `0,5,7`: whole numbers (empty words skipped).
fn parse_cases(text: &str) -> Result<Vec<i128>, JobError> {
    let word = |w: &str| {
        w.parse::<i128>().map_err(|_| {
            cases_error(
                w,
                "whole numbers",
                format!("cases: {w}: not a case index (a whole number)"),
            )
        })
    };
    text.split(',')
        .map(str::trim)
        .filter(|w| !w.is_empty())
        .map(word)
        .collect()
}

/// `I/N`: two whole numbers.
fn parse_shard(text: &str) -> Result<(i128, i128), JobError> {
    let (i, n) = text.split_once('/').ok_or_else(|| shard_error(text))?;
    let number = |w: &str| w.trim().parse::<i128>().map_err(|_| shard_error(text));
    Ok((number(i)?, number(n)?))
}

impl Selection {
    /// A selection from the two optional forms a front end takes: a list of case indices and a
    /// shard `(I, N)`. Both given is refused (a shard of a list is not a study's shard: its
    /// journal would name cases it does not hold); negative numbers are refused with their
    /// value.
    pub fn new(cases: Option<Vec<i128>>, shard: Option<(i128, i128)>) -> Result<Selection, JobError> {
        match (cases, shard) {
            (Some(_), Some(_)) => Err(JobError::option(
                "cases",
                "cases and shard",
                "one of them",
                "cases and shard: give one of them (a list of case indices or a shard I/N), not both"
                    .to_string(),
            )),
            (None, None) => Ok(Selection::All),
            (None, Some((i, n))) => Selection::shard(i, n),
            (Some(list), None) => Selection::cases(list),
        }
    }

    /// Shard `i` of `n`: `0 ≤ i < n`.
    pub fn shard(i: i128, n: i128) -> Result<Selection, JobError> {
        if n < 1 || i < 0 || i >= n {
            return Err(shard_error(&format!("{i}/{n}")));
        }
        Ok(Selection::Shard {
            index: i as usize,
            count: n as usize,
        })
    }

    /// A list of case indices: none twice, not empty (their range is the study's:
    /// [`Study::select`]).
    pub fn cases(list: Vec<i128>) -> Result<Selection, JobError> {
        if list.is_empty() {
            return Err(cases_error(
                "[]",
                "at least one case index",
                "cases: an empty list; give at least one case index".to_string(),
            ));
        }
        let mut seen = HashSet::with_capacity(list.len());
        for &i in &list {
            if !seen.insert(i) {
                return Err(cases_error(
                    &i.to_string(),
                    "each case once",
                    format!("cases: {i} is given more than once; each case runs once"),
                ));
            }
        }
        Ok(Selection::Cases(list))
    }

    /// The command line's text forms: `--cases 0,5,7` and `--shard I/N` (a word that is not a
    /// whole number is refused with the same message as an out-of-range one).
    pub fn parse(cases: Option<&str>, shard: Option<&str>) -> Result<Selection, JobError> {
        let cases = cases.map(parse_cases).transpose()?;
        let shard = shard.map(parse_shard).transpose()?;
        Selection::new(cases, shard)
    }

    /// The shard `(I, N)` that names the journal (`None`: `journal.jsonl`).
    pub fn journal_shard(&self) -> Option<(usize, usize)> {
        match self {
            Selection::Shard { index, count } => Some((*index, *count)),
            _ => None,
        }
    }
}

impl Study {
    /// The cases of `selection`, in the study's case order for a shard and in the order given
    /// for a list; a case index beyond the study's cases is refused.
    pub fn select(&self, selection: &Selection) -> Result<Vec<Case>, JobError> {
        let all = self.cases();
        match selection {
            Selection::All => Ok(all),
            Selection::Shard { index, count } => {
                Ok(all.into_iter().filter(|c| c.index % count == *index).collect())
            }
            Selection::Cases(list) => list
                .iter()
                .map(|&i| {
                    let at = usize::try_from(i).ok().and_then(|i| all.get(i));
                    at.copied().ok_or_else(|| {
                        let n = all.len();
                        cases_error(
                            &i.to_string(),
                            &format!("[0, {n})"),
                            format!("cases: {i}: must lie in [0, {n}) (the study has {n} cases)"),
                        )
                    })
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_number_forms_give_one_selection_or_one_message() {
        assert_eq!(
            Selection::parse(None, Some("1/3")),
            Selection::new(None, Some((1, 3)))
        );
        assert_eq!(
            Selection::parse(Some("4,0"), None),
            Selection::new(Some(vec![4, 0]), None)
        );
        for (i, n) in [(3, 2), (0, 0), (-1, 2), (2, 2)] {
            let a = Selection::parse(None, Some(&format!("{i}/{n}"))).unwrap_err();
            let b = Selection::new(None, Some((i, n))).unwrap_err();
            assert_eq!(a, b);
            assert_eq!(a.message, format!("shard = {i}/{n}: expected I/N with 0 ≤ I < N"));
        }
        let e = Selection::parse(Some("1,1"), None).unwrap_err();
        assert_eq!(e.message, "cases: 1 is given more than once; each case runs once");
        assert!(Selection::parse(Some("1"), Some("0/2")).is_err());
        assert!(Selection::parse(None, Some("x/2")).unwrap_err().is_invalid());
    }
}
