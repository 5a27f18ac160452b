//! The block structure MSH 4.1 gives `$Nodes` and `$Elements`: the section's header (blocks,
//! count, smallest and largest tag) and the start of each block's header (entity dimension
//! and tag).

use super::cursor::Cursor;
use super::failure::R;
use crate::error::Location;

/// The header of an MSH 4.1 `$Nodes` or `$Elements` section (`noun` "node" or "element"):
/// its location, the number of blocks and the number of nodes or elements; the smallest and
/// largest tag are read past.
pub(super) fn block_section_header(
    input: &mut Cursor<'_>,
    section: &str,
    noun: &str,
) -> R<(Location, u64, u64)> {
    input.begin(|| format!("the ${section} header (blocks, {noun}s, smallest and largest tag)"))?;
    let header = input.rec_location();
    let nblocks = input.size(|| format!("the number of {noun} blocks"))?;
    let count = input.size(|| format!("the number of {noun}s"))?;
    input.size(|| format!("the smallest {noun} tag"))?;
    input.size(|| format!("the largest {noun} tag"))?;
    input.end_record(|| format!("the ${section} header"))?;
    Ok((header, nblocks, count))
}

/// The start of the header of block `b` of the `nblocks` an MSH 4.1 `$Nodes` or `$Elements`
/// section announced (`noun` "node" or "element"): its location, the entity dimension and
/// the entity tag.
pub(super) fn block_header(
    input: &mut Cursor<'_>,
    section: &str,
    noun: &str,
    b: u64,
    nblocks: u64,
) -> R<(Location, i64, i32)> {
    input.begin_announced(
        || {
            format!(
                "${section} header announces {nblocks} entity blocks but the section holds {}",
                b - 1
            )
        },
        || format!("the header of {noun} block {b} of {nblocks}"),
    )?;
    let block = input.rec_location();
    let edim = input.int(|| format!("the entity dimension of {noun} block {b}"))?;
    let entity = input.int32(|| format!("the entity tag of {noun} block {b}"))?;
    Ok((block, edim, entity))
}
