//! Grouping items by pairs found to be one (the same surface, copies of one edge): a
//! union–find whose groups list their members ascending.

use std::collections::BTreeMap;

/// Items 0..n joined into groups.
pub(crate) struct Groups {
    parent: Vec<usize>,
}

impl Groups {
    /// `n` items, each alone.
    pub(crate) fn new(n: usize) -> Self {
        Groups {
            parent: (0..n).collect(),
        }
    }

    /// The least item of `k`'s group so far (paths halved on the way).
    fn root(&mut self, mut k: usize) -> usize {
        while self.parent[k] != k {
            self.parent[k] = self.parent[self.parent[k]];
            k = self.parent[k];
        }
        k
    }

    /// Puts `a` and `b` in one group.
    pub(crate) fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        self.parent[a.max(b)] = a.min(b);
    }

    /// The groups of the items `members` keeps, each ascending, by their least item.
    pub(crate) fn of(mut self, members: impl Fn(usize) -> bool) -> Vec<Vec<usize>> {
        let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for k in 0..self.parent.len() {
            if members(k) {
                let r = self.root(k);
                groups.entry(r).or_default().push(k);
            }
        }
        groups.into_values().collect()
    }
}
