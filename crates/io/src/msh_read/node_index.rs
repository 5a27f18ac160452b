//! The map from Gmsh node tags, which may be sparse and unordered, to 0-based vertex
//! indices in file order: the elements' node tags are read through it.

use std::collections::HashMap;

use super::failure::{fail, R};
use crate::error::Location;

/// Node tag → 0-based vertex index.
pub(super) enum NodeIndex {
    /// Indexed by tag (`u32::MAX` where no node has the tag), when tags are dense enough.
    Dense(Vec<u32>),
    /// Looked up, when tags are sparse.
    Sparse(HashMap<u64, u32>),
}

impl NodeIndex {
    /// The map from `tags`, the node tags of `$Nodes` in file order, to vertex indices; a
    /// tag given twice is an error at `section`.
    pub(super) fn new(tags: &[u64], section: Location) -> R<Self> {
        let n = tags.len();
        if u32::try_from(n).map_or(true, |n| n == u32::MAX) {
            return fail(section, format!("{n} nodes are more than hocurve supports"));
        }
        let max = tags.iter().copied().max().unwrap_or(0);
        let dup = |tag: u64| {
            fail(
                section,
                format!("node tag {tag} appears more than once in $Nodes"),
            )
        };
        let dense_len = usize::try_from(max)
            .ok()
            .and_then(|m| m.checked_add(1))
            .filter(|&len| len <= n.saturating_mul(2).saturating_add(1024));
        let index = if let Some(len) = dense_len {
            let mut v = vec![u32::MAX; len];
            for (i, &t) in tags.iter().enumerate() {
                // `t <= max < len`, and `i < n < u32::MAX`.
                if let Some(slot) = usize::try_from(t).ok().and_then(|t| v.get_mut(t)) {
                    if *slot != u32::MAX {
                        return dup(t);
                    }
                    *slot = i as u32;
                }
            }
            NodeIndex::Dense(v)
        } else {
            let mut m = HashMap::with_capacity(n);
            for (i, &t) in tags.iter().enumerate() {
                if m.insert(t, i as u32).is_some() {
                    return dup(t);
                }
            }
            NodeIndex::Sparse(m)
        };
        Ok(index)
    }

    /// The vertex index of node tag `tag`, if the file has that node.
    pub(super) fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeIndex::Dense(v) => usize::try_from(tag)
                .ok()
                .and_then(|t| v.get(t))
                .copied()
                .filter(|&i| i != u32::MAX),
            NodeIndex::Sparse(m) => m.get(&tag).copied(),
        }
    }
}
