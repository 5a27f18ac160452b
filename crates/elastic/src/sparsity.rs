//! Who couples with whom: the cells around each node, the node adjacency graph (the
//! block sparsity pattern of the stiffness matrix) and a colouring of the cells so that
//! cells of one colour share no node and can be assembled in parallel.

use hocurve_mesh::{HighOrderMesh, Jagged};
use rayon::prelude::*;

/// A compressed list of lists (the mesh crate's [`Jagged`]): the cells of each node, the
/// nodes each node couples with.
pub(crate) type Adjacency = Jagged<u32>;

/// The cells containing each node, in increasing cell order.
pub(crate) fn node_cells(mesh: &HighOrderMesh) -> Adjacency {
    let mut counts = vec![0usize; mesh.nodes.len() + 1];
    for cell in &mesh.cells {
        for &n in &cell.nodes {
            counts[n as usize + 1] += 1;
        }
    }
    for i in 0..mesh.nodes.len() {
        counts[i + 1] += counts[i];
    }
    let offsets = counts.clone();
    let mut next = counts;
    let mut items = vec![0u32; offsets[mesh.nodes.len()]];
    for (c, cell) in mesh.cells.iter().enumerate() {
        for &n in &cell.nodes {
            items[next[n as usize]] = c as u32;
            next[n as usize] += 1;
        }
    }
    Adjacency::from_parts(offsets, items)
}

/// For each node, the sorted nodes it shares a cell with (itself included, also when it is
/// in no cell, so that every row has a diagonal).
pub(crate) fn node_graph(mesh: &HighOrderMesh, cells_of_node: &Adjacency) -> Adjacency {
    let rows: Vec<Vec<u32>> = (0..mesh.nodes.len())
        .into_par_iter()
        .map(|n| {
            let mut row = vec![n as u32];
            for &c in cells_of_node.row(n) {
                row.extend_from_slice(&mesh.cells[c as usize].nodes);
            }
            row.sort_unstable();
            row.dedup();
            row
        })
        .collect();
    let mut offsets = Vec::with_capacity(rows.len() + 1);
    offsets.push(0);
    for row in &rows {
        offsets.push(offsets[offsets.len() - 1] + row.len());
    }
    Adjacency::from_parts(offsets, rows.concat())
}

/// Greedy colouring: each cell, in order, takes the lowest colour not used by an earlier
/// cell sharing a node with it. Returns the cells of each colour, in increasing order.
pub(crate) fn colour_cells(mesh: &HighOrderMesh, cells_of_node: &Adjacency) -> Vec<Vec<u32>> {
    colour_cells_by_masks(mesh).unwrap_or_else(|| colour_cells_by_neighbours(mesh, cells_of_node))
}

/// [`colour_cells`] with a mask per node of the colours of the cells coloured so far that
/// hold it: O(cells × nodes per cell). None if more than 128 colours are needed.
fn colour_cells_by_masks(mesh: &HighOrderMesh) -> Option<Vec<Vec<u32>>> {
    let mut used = vec![0u128; mesh.nodes.len()];
    let mut classes: Vec<Vec<u32>> = Vec::new();
    for (c, cell) in mesh.cells.iter().enumerate() {
        let taken = cell
            .nodes
            .iter()
            .fold(0u128, |mask, &n| mask | used[n as usize]);
        if taken == u128::MAX {
            return None;
        }
        let k = taken.trailing_ones() as usize;
        if k == classes.len() {
            classes.push(Vec::new());
        }
        classes[k].push(c as u32);
        cell.nodes.iter().for_each(|&n| used[n as usize] |= 1 << k);
    }
    Some(classes)
}

/// [`colour_cells`] by looking at every earlier cell around each node.
fn colour_cells_by_neighbours(mesh: &HighOrderMesh, cells_of_node: &Adjacency) -> Vec<Vec<u32>> {
    let mut colour = vec![u32::MAX; mesh.cells.len()];
    let mut taken: Vec<bool> = Vec::new();
    let mut classes: Vec<Vec<u32>> = Vec::new();
    for (c, cell) in mesh.cells.iter().enumerate() {
        for &n in &cell.nodes {
            for &other in cells_of_node.row(n as usize) {
                let k = colour[other as usize];
                if k != u32::MAX {
                    taken[k as usize] = true;
                }
            }
        }
        let k = taken.iter().position(|&t| !t).unwrap_or(taken.len());
        if k == taken.len() {
            taken.push(false);
            classes.push(Vec::new());
        }
        colour[c] = k as u32;
        classes[k].push(c as u32);
        taken.iter_mut().for_each(|t| *t = false);
    }
    classes
}

#[cfg(test)]
#[path = "tests/sparsity.rs"]
mod tests;
