//! The p-multigrid's transfer between two orders q < p on the same cells, applied cell by
//! cell instead of stored as a sparse matrix (and its transpose).
//!
//! The prolongation P is Lagrange interpolation: an order-p node takes the order-q field at
//! its reference position in one cell that holds it (its owner), rotated into the nodes' free
//! directions: y_n = Q_n Σ_j φ_j(ξ_n) Q_vⱼᵀ x_vⱼ. The restriction is exactly Pᵀ: each cell
//! hands its owned nodes' residuals back to its order-q nodes with the same weights. Cells
//! are visited in the coloured runs of the order-q mesh ([`crate::cell_runs`]), so both
//! directions are deterministic; nothing per cell is stored but its node lists.

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::{ReferenceElement, Shape};

use crate::cell_runs::{CellRuns, ReducedNodes, SharedSum};
use crate::condensation::Constraints;
use crate::ElasticError;

/// Interpolation weights below this are zeros of the basis at the node (round-off).
const ZERO_WEIGHT: f64 = 1e-14;

/// P and Pᵀ between a mesh of order p and one of order q on the same cells (all of one
/// shape).
pub(crate) struct CellTransfer {
    /// The order-q mesh's cells in coloured runs.
    runs: CellRuns,
    /// Nodes per order-p cell.
    fine_n: usize,
    /// The order-p nodes of the cell at each run position.
    fine_cells: Vec<u32>,
    /// The order-p local nodes each cell owns: `owned[owned_start[i]..owned_start[i + 1]]`
    /// for the cell at position i.
    owned_start: Vec<usize>,
    owned: Vec<u16>,
    /// For each order-p local node a: the order-q local nodes j with φ_j(ξ_a) ≠ 0 and φ_j(ξ_a).
    weights: Vec<Vec<(u16, f64)>>,
    fine: ReducedNodes,
    coarse: ReducedNodes,
    fine_sums: SharedSum,
    coarse_sums: SharedSum,
}

impl CellTransfer {
    /// The transfer between `fine` (order p, under `fine_constraints`) and `coarse` (order
    /// q, the same cells, under `coarse_constraints`); every cell of one shape.
    pub fn new(
        fine: &HighOrderMesh,
        fine_constraints: &Constraints,
        coarse: &HighOrderMesh,
        coarse_constraints: &Constraints,
    ) -> Result<Self, ElasticError> {
        // (Without cells any shape will do: there is nothing to transfer.)
        let shape = coarse.cells.first().map_or(Shape::Tet, |c| c.kind);
        let weights = interpolation_weights(shape, fine, coarse)?;
        let coarse_n = shape.num_nodes(coarse.order);
        let fine_n = weights.len();
        let runs = CellRuns::new(coarse, coarse_n);
        let mut fine_cells = Vec::with_capacity(runs.order.len() * fine_n);
        let mut owner_seen = vec![false; fine.nodes.len()];
        let (mut owned_start, mut owned) = (vec![0], Vec::new());
        for &c in &runs.order {
            let nodes = &fine.cells[c as usize].nodes;
            if nodes.len() != fine_n || coarse.cells[c as usize].nodes.len() != coarse_n {
                return Err(ElasticError::WrongNodeCount {
                    cell: c as usize,
                    found: nodes.len(),
                    expected: fine_n,
                });
            }
            fine_cells.extend_from_slice(nodes);
            for (a, &node) in nodes.iter().enumerate() {
                if !std::mem::replace(&mut owner_seen[node as usize], true) {
                    owned.push(a as u16);
                }
            }
            owned_start.push(owned.len());
        }
        Ok(CellTransfer {
            runs,
            fine_n,
            fine_cells,
            owned_start,
            owned,
            weights,
            fine: ReducedNodes::new(fine_constraints),
            coarse: ReducedNodes::new(coarse_constraints),
            fine_sums: SharedSum::default(),
            coarse_sums: SharedSum::default(),
        })
    }

    /// Number of order-q unknowns.
    pub fn coarse_len(&self) -> usize {
        self.coarse.len()
    }

    /// y = P x: order-q unknowns `x` to order-p unknowns `y`.
    pub fn prolong(&self, x: &[f64], y: &mut [f64]) {
        let dim = self.fine.dim;
        self.fine_sums.collect(y, |sums| {
            self.runs
                .for_each_run(Vec::new, |values: &mut Vec<[f64; 3]>, run| {
                    let nodes = self.runs.nodes_of_run(run);
                    values.clear();
                    values.extend(nodes.iter().map(|&v| self.coarse.expand(v as usize, x)));
                    for position in self.runs.cells_of_run(run) {
                        let local = self.runs.local(position);
                        for &a in self.owned_of(position) {
                            let mut u = [0.0; 3];
                            for &(j, w) in &self.weights[a as usize] {
                                let v = values[local[j as usize] as usize];
                                (0..dim).for_each(|d| u[d] += w * v[d]);
                            }
                            let node = self.fine_cells[position * self.fine_n + a as usize];
                            self.fine.restrict(node as usize, u, |i, v| sums.add(i, v));
                        }
                    }
                });
        });
    }

    /// z = Pᵀ r: order-p residuals `r` to order-q ones `z`.
    pub fn restrict(&self, r: &[f64], z: &mut [f64]) {
        let dim = self.fine.dim;
        self.coarse_sums.collect(z, |sums| {
            self.runs
                .for_each_run(Vec::new, |values: &mut Vec<[f64; 3]>, run| {
                    let nodes = self.runs.nodes_of_run(run);
                    values.clear();
                    values.resize(nodes.len(), [0.0; 3]);
                    for position in self.runs.cells_of_run(run) {
                        let local = self.runs.local(position);
                        for &a in self.owned_of(position) {
                            let node = self.fine_cells[position * self.fine_n + a as usize];
                            let u = self.fine.expand(node as usize, r);
                            for &(j, w) in &self.weights[a as usize] {
                                let v = &mut values[local[j as usize] as usize];
                                (0..dim).for_each(|d| v[d] += w * u[d]);
                            }
                        }
                    }
                    for (&node, &v) in nodes.iter().zip(values.iter()) {
                        self.coarse
                            .restrict(node as usize, v, |i, v| sums.add(i, v));
                    }
                });
        });
    }

    /// The order-p local nodes owned by the cell at `position`.
    fn owned_of(&self, position: usize) -> &[u16] {
        &self.owned[self.owned_start[position]..self.owned_start[position + 1]]
    }
}

/// For each order-p reference node of `shape` (the family and order of `fine`): the
/// order-q basis functions of `coarse` that do not vanish there, as (index, value).
pub(crate) fn interpolation_weights(
    shape: Shape,
    fine: &HighOrderMesh,
    coarse: &HighOrderMesh,
) -> Result<Vec<Vec<(u16, f64)>>, ElasticError> {
    let fine_reference = ReferenceElement::shared(shape, fine.order, fine.family)?;
    let coarse_reference = ReferenceElement::shared(shape, coarse.order, coarse.family)?;
    let basis = coarse_reference.basis();
    let mut values = vec![0.0; basis.len()];
    Ok(fine_reference
        .nodes()
        .points()
        .iter()
        .map(|&xi| {
            basis.eval(xi, &mut values);
            values
                .iter()
                .enumerate()
                .filter(|(_, w)| w.abs() > ZERO_WEIGHT)
                .map(|(j, &w)| (j as u16, w))
                .collect()
        })
        .collect())
}

#[cfg(test)]
#[path = "tests/transfer.rs"]
mod tests;
