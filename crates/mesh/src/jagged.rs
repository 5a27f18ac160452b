//! A compact list of variable-length rows.

/// Rows of varying length stored in one vector (CSR-style), e.g. the edges of each cell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Jagged<T> {
    offsets: Vec<usize>,
    values: Vec<T>,
}

impl<T> Default for Jagged<T> {
    fn default() -> Self {
        Jagged {
            offsets: vec![0],
            values: Vec::new(),
        }
    }
}

impl<T> Jagged<T> {
    /// An empty list.
    pub fn new() -> Self {
        Self::default()
    }

    /// The rows `values[offsets[r]..offsets[r + 1]]`: `offsets` starts at 0, never
    /// decreases and ends at `values.len()` (built by code, not read from files).
    ///
    /// # Panics
    ///
    /// If the offsets do not describe `values` that way.
    pub fn from_parts(offsets: Vec<usize>, values: Vec<T>) -> Self {
        assert!(
            offsets.first() == Some(&0)
                && offsets.windows(2).all(|w| w[0] <= w[1])
                && offsets.last() == Some(&values.len()),
            "offsets that do not describe the values"
        );
        Jagged { offsets, values }
    }

    /// Appends a row.
    pub fn push_row(&mut self, row: impl IntoIterator<Item = T>) {
        self.values.extend(row);
        self.offsets.push(self.values.len());
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[T] {
        &self.values[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Iterates over the rows.
    pub fn rows(&self) -> impl Iterator<Item = &[T]> + '_ {
        (0..self.len()).map(move |i| self.row(i))
    }
}
