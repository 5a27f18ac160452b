//! Nodal data carried along when a mesh is resampled to another node family.

use std::collections::BTreeMap;

use hocurve_nodes::{NodeFamily, ReferenceElement, Shape};

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
        let mut done = vec![false; n];
        // Per shape, Φⱼ at every target node, row by row: the same for every cell.
        let mut tables: BTreeMap<Shape, (usize, Vec<f64>)> = BTreeMap::new();
        let mut u = vec![0.0; components];
        for cell in &self.cells {
            let shape = cell.kind;
            if let std::collections::btree_map::Entry::Vacant(slot) = tables.entry(shape) {
                let from = ReferenceElement::shared(shape, self.order, self.family)?;
                let to = ReferenceElement::shared(shape, self.order, family)?;
                let basis = from.basis();
                let width = basis.len();
                let targets = to.nodes().points();
                let mut table = vec![0.0; targets.len() * width];
                for (row, xi) in table.chunks_mut(width.max(1)).zip(targets) {
                    basis.eval(*xi, row);
                }
                slot.insert((width, table));
            }
            let (width, table) = &tables[&shape];
            for (k, phi) in table.chunks(*width.max(&1)).enumerate() {
                let Some(&id) = cell.nodes.get(k) else {
                    break;
                };
                let id = id as usize;
                if done[id] {
                    continue;
                }
                u.iter_mut().for_each(|x| *x = 0.0);
                for (p, &j) in phi.iter().zip(&cell.nodes) {
                    let at = j as usize * components;
                    for (x, v) in u.iter_mut().zip(&values[at..at + components]) {
                        *x += p * v;
                    }
                }
                out[id * components..(id + 1) * components].copy_from_slice(&u);
                done[id] = true;
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
#[path = "tests/resample.rs"]
mod tests;
