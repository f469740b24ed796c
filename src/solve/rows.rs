//! Rows of equal width stored in one buffer: the per-output-row states and losses of a
//! trajectory, without one allocation per row.

use std::ops::Index;
use std::slice::ChunksExact;

/// Rows of `width` values each, contiguous.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rows {
    width: usize,
    data: Vec<f64>,
}

impl Rows {
    /// Empty, with room for `rows` rows of `width` values.
    pub fn with_capacity(width: usize, rows: usize) -> Self {
        Self {
            width,
            data: Vec::with_capacity(width * rows),
        }
    }

    /// Append a row (its length must be the width).
    pub fn push(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.width);
        self.data.extend_from_slice(row);
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.data.len().checked_div(self.width).unwrap_or(0)
    }

    /// True without rows.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The rows in order.
    pub fn iter(&self) -> ChunksExact<'_, f64> {
        self.data.chunks_exact(self.width.max(1))
    }

    /// Row `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&[f64]> {
        (k < self.len()).then(|| &self.data[k * self.width..(k + 1) * self.width])
    }

    /// The first row.
    pub fn first(&self) -> Option<&[f64]> {
        self.get(0)
    }

    /// The last row.
    pub fn last(&self) -> Option<&[f64]> {
        self.len().checked_sub(1).and_then(|k| self.get(k))
    }
}

impl Index<usize> for Rows {
    type Output = [f64];
    fn index(&self, k: usize) -> &[f64] {
        &self.data[k * self.width..(k + 1) * self.width]
    }
}

impl<'a> IntoIterator for &'a Rows {
    type Item = &'a [f64];
    type IntoIter = ChunksExact<'a, f64>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_index_iterate_and_end() {
        let mut r = Rows::with_capacity(3, 2);
        assert!(r.is_empty() && r.last().is_none() && r.iter().next().is_none());
        r.push(&[1.0, 2.0, 3.0]);
        r.push(&[4.0, 5.0, 6.0]);
        assert_eq!(r.len(), 2);
        assert_eq!(&r[1], &[4.0, 5.0, 6.0]);
        assert_eq!(r.first(), Some(&[1.0, 2.0, 3.0][..]));
        assert_eq!(r.last(), Some(&[4.0, 5.0, 6.0][..]));
        assert_eq!(r.get(2), None);
        let sums: Vec<f64> = r.iter().map(|row| row.iter().sum()).collect();
        assert_eq!(sums, vec![6.0, 15.0]);
        assert!(Rows::default().iter().next().is_none());
    }
}
