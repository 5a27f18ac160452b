//! The `$Nodes` section (MSH 4.1 and 2): node tags and coordinates, in file order.

use super::blocks::{block_header, block_section_header};
use super::cursor::Cursor;
use super::failure::{fail, fewer_than_announced, R};
use super::parser::Parser;

impl Parser<'_> {
    /// `$Nodes` of MSH 4.1: blocks of node tags, then their coordinates (parametric
    /// coordinates are read past). `announced` is set to the header's node count.
    pub(super) fn nodes_v41(&mut self, announced: &mut Option<u64>) -> R<()> {
        let input = &mut self.input;
        let (header, nblocks, nnodes) = block_section_header(input, "Nodes", "node")?;
        *announced = Some(nnodes);
        let each = if input.is_binary() {
            input.size_t() + 24
        } else {
            8
        };
        let cap = input.capacity(nnodes, each);
        self.vertices.reserve(cap);
        self.node_tags.reserve(cap);
        let mut total = 0u64;
        for b in 1..=nblocks {
            let (block, edim, _) = block_header(input, "Nodes", "node", b, nblocks)?;
            let param = input.int(|| format!("the parametric flag of node block {b}"))?;
            let n = input.size(|| format!("the number of nodes in block {b}"))?;
            input.end_record(|| format!("the header of node block {b}"))?;
            let edim = match usize::try_from(edim) {
                Ok(d) if d <= 3 => d,
                _ => {
                    return fail(
                        block,
                        format!(
                            "expected an entity dimension 0 to 3 in node block {b}, found {edim}"
                        ),
                    )
                }
            };
            let extra = match param {
                0 => 0,
                1 => edim,
                _ => {
                    return fail(
                        block,
                        format!("expected parametric flag 0 or 1 in node block {b}, found {param}"),
                    )
                }
            };
            input.check_room(n, input.size_t() as u64 + 8 * (3 + extra as u64), || {
                format!("node block {b} of {n} nodes")
            })?;
            let first = self.node_tags.len();
            for k in 1..=n {
                let what = || format!("the tag of node {k} of {n} in block {b}");
                input.begin(what)?;
                let tag = input.size(what)?;
                input.end_record(what)?;
                self.node_tags.push(tag);
            }
            for k in 0..n {
                let tag = usize::try_from(k)
                    .ok()
                    .and_then(|k| self.node_tags.get(first + k))
                    .copied()
                    .unwrap_or(0);
                input.begin(|| format!("the coordinates of node {tag}"))?;
                let x = coordinates(input, tag)?;
                for _ in 0..extra {
                    input.float(|| format!("a parametric coordinate of node {tag}"))?;
                }
                input.end_record(|| format!("the coordinates of node {tag}"))?;
                self.vertices.push(x);
            }
            total = total.saturating_add(n);
        }
        if total != nnodes {
            return fail(
                header,
                format!("node count in $Nodes header is {nnodes} but the blocks hold {total}"),
            );
        }
        input.expect_end("Nodes", || {
            format!(" after the {nblocks} node blocks announced in the $Nodes header")
        })
    }

    /// `$Nodes` of MSH 2: one node a record, its number and coordinates. `announced` is set
    /// to the header's node count.
    pub(super) fn nodes_v2(&mut self, announced: &mut Option<u64>) -> R<()> {
        let input = &mut self.input;
        input.begin_text(|| "the number of nodes".into())?;
        let n = input.size(|| "the number of nodes".into())?;
        input.end_record(|| "the number of nodes".into())?;
        *announced = Some(n);
        input.check_room(n, 28, || format!("{n} nodes"))?;
        let cap = input.capacity(n, if input.is_binary() { 28 } else { 8 });
        self.vertices.reserve(cap);
        self.node_tags.reserve(cap);
        for i in 0..n {
            input.begin_announced(
                || fewer_than_announced("node", "Nodes", n, i),
                || format!("node {} of {n}", i + 1),
            )?;
            let tag = input.int(|| format!("the number of node {} of {n}", i + 1))?;
            let Ok(tag) = u64::try_from(tag) else {
                return fail(
                    input.value_loc(),
                    format!("expected a non-negative node number, found {tag}"),
                );
            };
            let x = coordinates(input, tag)?;
            input.end_record(|| format!("the coordinates of node {tag}"))?;
            self.node_tags.push(tag);
            self.vertices.push(x);
        }
        input.expect_end("Nodes", || {
            format!(" after the {n} nodes announced in the $Nodes header")
        })
    }
}

/// The x, y and z coordinates of node `tag`.
fn coordinates(input: &mut Cursor<'_>, tag: u64) -> R<[f64; 3]> {
    let x = input.float(|| format!("the x coordinate of node {tag}"))?;
    let y = input.float(|| format!("the y coordinate of node {tag}"))?;
    let z = input.float(|| format!("the z coordinate of node {tag}"))?;
    Ok([x, y, z])
}
