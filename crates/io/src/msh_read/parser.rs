//! The MSH reader's state: the cursor in the file and what the sections have given so far,
//! which the section parsers fill and the two readers assemble their meshes from.

use std::collections::{BTreeMap, HashMap, HashSet};

use hocurve_mesh::{Element, PhysicalGroup, Shape};

use super::cursor::Cursor;
use super::failure::{fail, R};
use super::node_index::NodeIndex;
use crate::error::Location;

/// The MSH version of the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Version {
    /// MSH 2.0 to 2.2.
    V2,
    /// MSH 4.1.
    V41,
}

/// Identity of an element for merging the copies MSH 2 writes once per physical group.
pub(super) type DedupKey = (Shape, i32, [u32; 8]);

/// The [`DedupKey`] of an element.
pub(super) fn dedup_key(kind: Shape, entity: i32, vertices: &[u32]) -> DedupKey {
    let mut v = [u32::MAX; 8];
    for (slot, &x) in v.iter_mut().zip(vertices) {
        *slot = x;
    }
    (kind, entity, v)
}

/// Where an element was read and of which order (high-order reader).
#[derive(Debug, Clone, Copy)]
pub(super) struct ElementRecord {
    pub(super) tag: i128,
    pub(super) location: Location,
    pub(super) order: usize,
}

/// A reader of one MSH file: where it is, and what it has read so far.
pub(super) struct Parser<'a> {
    pub(super) input: Cursor<'a>,
    pub(super) version: Version,
    // What was read.
    pub(super) vertices: Vec<[f64; 3]>,
    pub(super) node_tags: Vec<u64>,
    pub(super) nodes: Option<NodeIndex>,
    pub(super) by_dim: [Vec<Element>; 4],
    pub(super) have_elements: bool,
    pub(super) names: Vec<PhysicalGroup>,
    pub(super) entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
    // MSH 2 bookkeeping: the first physical tag seen per (dim, entity), the last
    // (dim, entity, physical) triple, and the element set once duplicates are possible.
    pub(super) first_physical: HashMap<(usize, i32), i32>,
    pub(super) last_triple: Option<(usize, i32, i32)>,
    pub(super) dedup: Option<HashSet<DedupKey>>,
    /// Read complete elements of any order (not only first-order ones).
    pub(super) high_order: bool,
    /// High-order reader: tag, place and order of each element of `by_dim`.
    pub(super) element_records: [Vec<ElementRecord>; 4],
    /// The file's tag of each element of `by_dim` (for messages).
    pub(super) element_tags: [Vec<u64>; 4],
}

impl<'a> Parser<'a> {
    /// A reader of the file `b`, of first-order elements only or (`high_order`) of complete
    /// elements of any order.
    pub(super) fn new(b: &'a [u8], high_order: bool) -> Self {
        Parser {
            input: Cursor::new(b),
            version: Version::V41,
            vertices: Vec::new(),
            node_tags: Vec::new(),
            nodes: None,
            by_dim: Default::default(),
            have_elements: false,
            names: Vec::new(),
            entity_physicals: BTreeMap::new(),
            first_physical: HashMap::new(),
            last_triple: None,
            dedup: None,
            high_order,
            element_records: Default::default(),
            element_tags: Default::default(),
        }
    }

    /// After [`Parser::read_sections`]: the dimension of the cells, the first of `dims` that
    /// has elements; an error if the file has no `$Nodes` or `$Elements` section, or
    /// (`none`) no elements of any of `dims`.
    pub(super) fn cell_dimension(
        &self,
        dims: impl IntoIterator<Item = usize>,
        none: &str,
    ) -> R<usize> {
        if self.nodes.is_none() {
            return fail(Location::EndOfFile, "the file has no $Nodes section");
        }
        if !self.have_elements {
            return fail(Location::EndOfFile, "the file has no $Elements section");
        }
        match dims
            .into_iter()
            .find(|&d| self.by_dim.get(d).is_some_and(|l| !l.is_empty()))
        {
            Some(dim) => Ok(dim),
            None => fail(Location::EndOfFile, none),
        }
    }
}

/// The list of dimension `dim` taken out of `lists` (empty if there is none).
pub(super) fn take_dim<T>(lists: &mut [Vec<T>; 4], dim: usize) -> Vec<T> {
    lists.get_mut(dim).map(std::mem::take).unwrap_or_default()
}
