//! The `$Elements` section (MSH 4.1 and 2): each element's type, entity and nodes (through
//! the node map), kept by dimension with its tag and place in the file; the copies MSH 2
//! writes of an element once per physical group are merged.

use hocurve_mesh::Element;

use super::blocks::{block_header, block_section_header};
use super::element_types::{element_kind, high_order_kind, BlockKind};
use super::failure::{eof_fail, fail, fewer_than_announced, Fail, R};
use super::parser::{dedup_key, ElementRecord, Parser};
use crate::error::Location;

impl Parser<'_> {
    /// The element block kind of Gmsh type `t` for this reader.
    fn block_kind(&self, t: i64) -> Result<Option<BlockKind>, String> {
        if self.high_order {
            high_order_kind(t)
        } else {
            element_kind(t).map(|k| k.map(BlockKind::linear))
        }
    }

    /// Stores an element of dimension `dim` (and, for the high-order reader, its record:
    /// file tag, where it was read, order).
    fn push_element(
        &mut self,
        dim: usize,
        kind: BlockKind,
        vertices: Vec<u32>,
        entity: i32,
        tag: i128,
        location: Location,
    ) {
        let element = Element {
            kind: kind.kind,
            vertices,
            entity,
        };
        let record = ElementRecord {
            tag,
            location,
            order: kind.order,
        };
        if let Some(list) = self.by_dim.get_mut(dim) {
            list.push(element);
            if let Some(tags) = self.element_tags.get_mut(dim) {
                tags.push(u64::try_from(tag).unwrap_or(0));
            }
            if self.high_order {
                if let Some(records) = self.element_records.get_mut(dim) {
                    records.push(record);
                }
            }
        }
    }

    /// Reads the node tags of one element and maps them to vertex indices.
    fn element_nodes(
        &mut self,
        kind: Option<BlockKind>,
        elem: i128,
        int_tags: bool,
    ) -> R<Vec<u32>> {
        let (nn, name) = kind.map_or((1, "point"), |k| (k.nodes, k.kind.name()));
        if let Some(left) = self.input.tokens_left() {
            if left != nn {
                let message =
                    format!("expected {nn} node tags for a {name} (element {elem}), found {left}");
                return Err(if self.input.is_last_line() && left < nn {
                    eof_fail(message)
                } else {
                    Fail::at(self.input.rec_location(), message)
                });
            }
        }
        let mut v = Vec::with_capacity(nn);
        for j in 1..=nn {
            let what = || format!("node {j} of element {elem}");
            let tag = if int_tags {
                let t = self.input.int(what)?;
                match u64::try_from(t) {
                    Ok(t) => t,
                    Err(_) => {
                        return fail(
                            self.input.value_loc(),
                            format!("element {elem} references node {t} which is not in $Nodes"),
                        )
                    }
                }
            } else {
                self.input.size(what)?
            };
            match self.nodes.as_ref().and_then(|m| m.get(tag)) {
                Some(i) => v.push(i),
                None => {
                    return fail(
                        self.input.value_loc(),
                        format!("element {elem} references node {tag} which is not in $Nodes"),
                    )
                }
            }
        }
        Ok(v)
    }

    /// `$Elements` of MSH 4.1: blocks of elements of one type on one entity. `announced` is
    /// set to the header's element count, `read` counts the elements read.
    pub(super) fn elements_v41(&mut self, announced: &mut Option<u64>, read: &mut u64) -> R<()> {
        let (header, nblocks, nelems) =
            block_section_header(&mut self.input, "Elements", "element")?;
        *announced = Some(nelems);
        for b in 1..=nblocks {
            let input = &mut self.input;
            let (block, edim, entity) = block_header(input, "Elements", "element", b, nblocks)?;
            let etype = input.int(|| format!("the element type of element block {b}"))?;
            let n = input.size(|| format!("the number of elements in block {b}"))?;
            input.end_record(|| format!("the header of element block {b}"))?;
            let kind = self.block_kind(etype).or_else(|m| fail(block, m))?;
            let (nn, dim, name) =
                kind.map_or((1, 0, "point"), |k| (k.nodes, k.kind.dim(), k.kind.name()));
            if edim != dim as i64 {
                return fail(
                    block,
                    format!(
                        "element block {b} is on an entity of dimension {edim} but holds \
                         {name}s (dimension {dim})"
                    ),
                );
            }
            let each = self.input.size_t() as u64 * (1 + nn as u64);
            self.input
                .check_room(n, each, || format!("element block {b} of {n} elements"))?;
            for k in 1..=n {
                let input = &mut self.input;
                input.begin(|| format!("element {k} of {n} in block {b}"))?;
                let location = input.rec_location();
                let tag = input.size(|| format!("the tag of element {k} of {n} in block {b}"))?;
                let vertices = self.element_nodes(kind, i128::from(tag), false)?;
                self.input.end_record(|| format!("element {tag}"))?;
                *read += 1;
                if let Some(kind) = kind {
                    self.push_element(dim, kind, vertices, entity, i128::from(tag), location);
                }
            }
        }
        if *read != nelems {
            return fail(
                header,
                format!("element count in $Elements header is {nelems} but the blocks hold {read}"),
            );
        }
        self.input.expect_end("Elements", || {
            format!(" after the {nblocks} element blocks announced in the $Elements header")
        })
    }

    /// `$Elements` of MSH 2: one element a record in ASCII files, blocks of elements of one
    /// type in binary ones. `announced` is set to the header's element count, `read` counts
    /// the elements read.
    pub(super) fn elements_v2(&mut self, announced: &mut Option<u64>, read: &mut u64) -> R<()> {
        let input = &mut self.input;
        input.begin_text(|| "the number of elements".into())?;
        let n = input.size(|| "the number of elements".into())?;
        input.end_record(|| "the number of elements".into())?;
        *announced = Some(n);
        if input.is_binary() {
            while *read < n {
                // A binary record of its own: the header of a block of elements, then each
                // element.
                let input = &mut self.input;
                input.begin(|| "an element block header".into())?;
                let at = input.rec_location();
                let etype = input.int(|| "the element type of an element block header".into())?;
                let count = input.int(|| "the element count of an element block header".into())?;
                let ntags = input.int(|| "the tag count of an element block header".into())?;
                let kind = self.block_kind(etype).or_else(|m| fail(at, m))?;
                let left = n - *read;
                let count = match u64::try_from(count) {
                    Ok(c) if c >= 1 && c <= left => c,
                    _ => {
                        return fail(
                            at,
                            format!(
                                "element block header announces {count} elements, expected 1 to \
                                 {left} (the elements left of the {n} in the $Elements header)"
                            ),
                        )
                    }
                };
                let Ok(ntags) = u64::try_from(ntags) else {
                    return fail(
                        at,
                        format!("expected a non-negative tag count, found {ntags}"),
                    );
                };
                let nn = kind.map_or(1, |k| k.nodes) as u64;
                let each = 4u64.saturating_mul(1 + ntags.saturating_add(nn));
                self.input
                    .check_room(count, each, || format!("element block of {count} elements"))?;
                for _ in 0..count {
                    self.input.begin(|| "an element number".into())?;
                    let tag = self.input.int(|| "an element number".into())?;
                    self.element_v2(kind, tag, ntags)?;
                    *read += 1;
                }
            }
        } else {
            for i in 0..n {
                let input = &mut self.input;
                input.begin_announced(
                    || fewer_than_announced("element", "Elements", n, i),
                    || format!("element {} of {n}", i + 1),
                )?;
                let tag = input.int(|| format!("the number of element {} of {n}", i + 1))?;
                let etype = input.int(|| format!("the type of element {tag}"))?;
                let kind = self
                    .block_kind(etype)
                    .or_else(|m| fail(self.input.rec_location(), m))?;
                let ntags = self
                    .input
                    .int(|| format!("the number of tags of element {tag}"))?;
                let Ok(ntags) = u64::try_from(ntags) else {
                    return fail(
                        self.input.rec_location(),
                        format!(
                            "expected a non-negative tag count for element {tag}, found {ntags}"
                        ),
                    );
                };
                self.element_v2(kind, tag, ntags)?;
                self.input.end_record(|| format!("element {tag}"))?;
                *read += 1;
            }
        }
        self.input.expect_end("Elements", || {
            format!(" after the {n} elements announced in the $Elements header")
        })
    }

    /// The tags and nodes of one MSH 2 element (after its number, type and tag count).
    fn element_v2(&mut self, kind: Option<BlockKind>, tag: i64, ntags: u64) -> R<()> {
        let location = self.input.rec_location();
        let mut physical = 0;
        let mut entity = 0;
        for j in 0..ntags {
            let v = self
                .input
                .int32(|| format!("tag {} of element {tag}", j + 1))?;
            match j {
                0 => physical = v,
                1 => entity = v,
                _ => {}
            }
        }
        let vertices = self.element_nodes(kind, i128::from(tag), true)?;
        let dim = kind.map_or(0, |k| k.kind.dim());
        let triple = (dim, entity, physical);
        if self.last_triple != Some(triple) {
            self.last_triple = Some(triple);
            if physical != 0 {
                let e = self.entity_physicals.entry((dim, entity)).or_default();
                if let Err(p) = e.binary_search(&physical) {
                    e.insert(p, physical);
                }
            }
            if kind.is_some() {
                let first = *self.first_physical.entry((dim, entity)).or_insert(physical);
                if first != physical && self.dedup.is_none() {
                    // MSH 2 repeats an element once per physical group of its entity: from
                    // now on, remember every element and merge the copies.
                    let set = self
                        .by_dim
                        .iter()
                        .flatten()
                        .map(|e| dedup_key(e.kind, e.entity, &e.vertices))
                        .collect();
                    self.dedup = Some(set);
                }
            }
        }
        let Some(kind) = kind else {
            return Ok(());
        };
        if let Some(set) = &mut self.dedup {
            if !set.insert(dedup_key(kind.kind, entity, &vertices)) {
                return Ok(());
            }
        }
        self.push_element(dim, kind, vertices, entity, i128::from(tag), location);
        Ok(())
    }
}
