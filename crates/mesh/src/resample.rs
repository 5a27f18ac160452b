//! Nodal data carried along when a mesh is resampled to another node family.

use std::collections::BTreeMap;

use hocurve_nodes::{NodeFamily, ReferenceElement, Shape};
use rayon::prelude::*;

use crate::{HighOrderMesh, MeshError};

impl HighOrderMesh {
    /// Nodal values (`components` per node, interleaved, given at this mesh's nodes) at the
    /// nodes of [`HighOrderMesh::resampled`]`(family)`: each cell's interpolant
    /// u(ξ) = Σⱼ Φⱼ(ξ) uⱼ is evaluated at the new family's nodes, exactly as the coordinates
    /// are, so a field that is a polynomial of degree ≤ p on each cell is unchanged (up to
    /// rounding) and coordinates passed as data give bitwise the resampled nodes. A node
    /// shared by several cells is evaluated once, from the first cell that has it; nodes no
    /// cell uses keep their values.
    pub fn resampled_point_values(
        &self,
        family: NodeFamily,
        components: usize,
        values: &[f64],
    ) -> Result<Vec<f64>, MeshError> {
        let n = self.nodes.len();
        let expected = components.checked_mul(n);
        if components == 0 || expected != Some(values.len()) {
            return Err(MeshError::DataLength {
                components,
                nodes: n,
                expected: expected.unwrap_or(usize::MAX),
                found: values.len(),
            });
        }
        family.check_order(self.order)?;
        let mut out = values.to_vec();
        if family == self.family {
            return Ok(out);
        }
        // Per shape, Φⱼ at every target node, row by row: the same for every cell.
        let mut tables: BTreeMap<Shape, (usize, Vec<f64>)> = BTreeMap::new();
        for cell in &self.cells {
            let shape = cell.kind;
            if let std::collections::btree_map::Entry::Vacant(slot) = tables.entry(shape) {
                let from = ReferenceElement::shared(shape, self.order, self.family)?;
                let to = ReferenceElement::shared(shape, self.order, family)?;
                let basis = from.basis();
                let width = basis.len().max(1);
                let targets = to.nodes().points();
                let mut table = vec![0.0; targets.len() * width];
                for (row, xi) in table.chunks_mut(width).zip(targets) {
                    basis.eval(*xi, row);
                }
                slot.insert((width, table));
            }
        }
        // Each node from the first cell that has it (its owner); then the cells evaluate
        // their own nodes in parallel, each sum in the same order as a serial pass would.
        let mut owned = vec![false; n];
        let owners: Vec<Vec<(usize, usize)>> = self
            .cells
            .iter()
            .map(|cell| {
                let rows = tables[&cell.kind].1.len() / tables[&cell.kind].0;
                cell.nodes
                    .iter()
                    .take(rows)
                    .enumerate()
                    .filter(|&(_, &id)| !std::mem::replace(&mut owned[id as usize], true))
                    .map(|(k, &id)| (k, id as usize))
                    .collect()
            })
            .collect();
        let evaluated: Vec<Vec<f64>> = self
            .cells
            .par_iter()
            .zip(&owners)
            .map(|(cell, own)| {
                let (width, table) = &tables[&cell.kind];
                let mut u = vec![0.0; components * own.len()];
                for (&(k, _), u) in own.iter().zip(u.chunks_exact_mut(components)) {
                    let phi = &table[k * width..(k + 1) * width];
                    for (p, &j) in phi.iter().zip(&cell.nodes) {
                        let at = j as usize * components;
                        for (x, v) in u.iter_mut().zip(&values[at..at + components]) {
                            *x += p * v;
                        }
                    }
                }
                u
            })
            .collect();
        for (own, u) in owners.iter().zip(&evaluated) {
            for (&(_, id), u) in own.iter().zip(u.chunks_exact(components)) {
                out[id * components..(id + 1) * components].copy_from_slice(u);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
#[path = "tests/resample.rs"]
mod tests;
