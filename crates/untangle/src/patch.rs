//! Patches around the elements to repair, their free nodes, and the repair itself.

use std::collections::BTreeMap;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::Shape;
use hocurve_quality::{BernsteinSpace, JacobianSampler, Sampling};
use rayon::prelude::*;

use crate::energy::{inverse, CellTerm, DistortionEnergy, Slot};
use crate::optimise::minimise;
use crate::{NodeConstraint, UntangleError};

/// Bernstein lattices larger than this are not sampled (high-order hexahedra: 3375 points
/// at p = 5); the quadrature points and the element's nodes are, which still include the
/// vertices.
const MAX_LATTICE_POINTS: usize = 1000;

/// How far a repair reaches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UntangleOptions {
    /// Rings of cells (sharing a vertex) around each element to repair whose nodes may move.
    pub rings: usize,
    /// Conjugate-gradient iterations per patch, at most.
    pub max_iterations: usize,
}

impl Default for UntangleOptions {
    fn default() -> Self {
        UntangleOptions {
            rings: 1,
            max_iterations: 2000,
        }
    }
}

/// What a repair did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UntangleReport {
    /// Independent patches optimised.
    pub patches: usize,
    /// Nodes free to move in them.
    pub free_nodes: usize,
    /// Smallest det T = det(J W⁻¹) at the sample points of the patches' cells afterwards
    /// (W: the straight-sided Jacobian; > 0 at every sample point is necessary, not
    /// sufficient, for validity: certify afterwards). +∞ when there was nothing to move.
    pub min_ratio: f64,
    /// Conjugate-gradient and Newton iterations, summed over the patches.
    pub iterations: usize,
}

/// Moves the nodes around `elements` (indices into `mesh.cells`) to untangle them and
/// improve their shape, keeping `fixed` nodes (sorted; the boundary nodes) in place;
/// `straight` holds the straight-sided position of every node, whose Jacobians are the
/// shapes aimed at. Only cells within `options.rings` vertex-neighbour rings of `elements`
/// change.
pub fn untangle(
    mesh: &mut HighOrderMesh,
    straight: &[[f64; 3]],
    elements: &[usize],
    fixed: &[u32],
    options: &UntangleOptions,
) -> Result<UntangleReport, UntangleError> {
    untangle_sliding(mesh, straight, elements, fixed, &BTreeMap::new(), options)
}

/// [`untangle`] with boundary nodes that slide: a node of `sliding` (not in `fixed`) moves
/// only as its [`NodeConstraint`] allows — within its plane or along its line, exactly, as
/// the elastic solve's sliding conditions let it.
pub fn untangle_sliding(
    mesh: &mut HighOrderMesh,
    straight: &[[f64; 3]],
    elements: &[usize],
    fixed: &[u32],
    sliding: &BTreeMap<u32, NodeConstraint>,
    options: &UntangleOptions,
) -> Result<UntangleReport, UntangleError> {
    if straight.len() != mesh.nodes.len() {
        return Err(UntangleError::StraightNodes {
            expected: mesh.nodes.len(),
            found: straight.len(),
        });
    }
    let count = mesh.cells.len();
    if let Some(&element) = elements.iter().find(|&&e| e >= count) {
        return Err(UntangleError::NoSuchElement { element, count });
    }
    let mut report = UntangleReport {
        min_ratio: f64::INFINITY,
        ..UntangleReport::default()
    };
    if elements.is_empty() {
        return Ok(report);
    }
    let in_patch = patch_cells(mesh, elements, options.rings);
    let free = free_nodes(mesh, &in_patch, fixed);
    let components = components(mesh, &in_patch, &free);
    let samplers = samplers(mesh, &components)?;
    let shape_index: BTreeMap<Shape, usize> = samplers
        .iter()
        .enumerate()
        .map(|(i, s)| (s.shape(), i))
        .collect();
    let samplers_ref = &samplers;
    let mesh_ref = &*mesh;
    let results: Vec<PatchResult> = components
        .par_iter()
        .map(|cells| {
            let (energy, variables, length) =
                patch_energy(mesh_ref, straight, cells, &free, samplers_ref, &shape_index);
            let mut x: Vec<[f64; 3]> = variables
                .iter()
                .map(|&n| mesh_ref.nodes[n as usize])
                .collect();
            let constraints: Vec<Option<NodeConstraint>> =
                variables.iter().map(|n| sliding.get(n).copied()).collect();
            let outcome = minimise(
                &energy,
                &mut x,
                length,
                options.max_iterations,
                &constraints,
            );
            (variables, x, outcome.min_ratio, outcome.iterations)
        })
        .collect();
    for (variables, x, min_ratio, iterations) in results {
        for (&n, p) in variables.iter().zip(&x) {
            mesh.nodes[n as usize] = *p;
        }
        report.patches += 1;
        report.free_nodes += variables.len();
        report.min_ratio = report.min_ratio.min(min_ratio);
        report.iterations += iterations;
    }
    Ok(report)
}

/// One optimised patch: its free nodes, their new positions, the smallest det T after,
/// the iterations.
type PatchResult = (Vec<u32>, Vec<[f64; 3]>, f64, usize);

/// `elements` and `rings` layers of cells sharing a vertex with them, as a mask.
pub(crate) fn patch_cells(mesh: &HighOrderMesh, elements: &[usize], rings: usize) -> Vec<bool> {
    let vertices = mesh.layout().num_vertices();
    let mut vertex_cells: Vec<Vec<u32>> = vec![Vec::new(); vertices];
    if rings > 0 {
        for (c, cell) in mesh.cells.iter().enumerate() {
            for &v in &cell.nodes[..cell.kind.num_vertices()] {
                if let Some(list) = vertex_cells.get_mut(v as usize) {
                    list.push(c as u32);
                }
            }
        }
    }
    let mut in_patch = vec![false; mesh.cells.len()];
    let mut front: Vec<usize> = elements.to_vec();
    for &e in elements {
        in_patch[e] = true;
    }
    for _ in 0..rings {
        let mut next = Vec::new();
        for &e in &front {
            let cell = &mesh.cells[e];
            for &v in &cell.nodes[..cell.kind.num_vertices()] {
                for &c in vertex_cells.get(v as usize).map_or(&[][..], |l| l) {
                    if !in_patch[c as usize] {
                        in_patch[c as usize] = true;
                        next.push(c as usize);
                    }
                }
            }
        }
        front = next;
    }
    in_patch
}

/// Per node: free to move (not fixed, and every cell using it is in the patch).
pub(crate) fn free_nodes(mesh: &HighOrderMesh, in_patch: &[bool], fixed: &[u32]) -> Vec<bool> {
    let mut outside = vec![false; mesh.nodes.len()];
    let mut inside = vec![false; mesh.nodes.len()];
    for (cell, &p) in mesh.cells.iter().zip(in_patch) {
        let mark = if p { &mut inside } else { &mut outside };
        for &n in &cell.nodes {
            mark[n as usize] = true;
        }
    }
    for &n in fixed {
        if let Some(o) = outside.get_mut(n as usize) {
            *o = true;
        }
    }
    inside
        .iter()
        .zip(&outside)
        .map(|(&i, &o)| i && !o)
        .collect()
}

/// The cells with a free node, grouped into sets that share free nodes (each sorted, the
/// sets ordered by their first cell).
pub(crate) fn components(
    mesh: &HighOrderMesh,
    in_patch: &[bool],
    free: &[bool],
) -> Vec<Vec<usize>> {
    let cells: Vec<usize> = (0..mesh.cells.len())
        .filter(|&c| in_patch[c] && mesh.cells[c].nodes.iter().any(|&n| free[n as usize]))
        .collect();
    let mut parent: Vec<usize> = (0..cells.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut owner: BTreeMap<u32, usize> = BTreeMap::new();
    for (k, &c) in cells.iter().enumerate() {
        for &n in &mesh.cells[c].nodes {
            if !free[n as usize] {
                continue;
            }
            match owner.get(&n) {
                Some(&other) => {
                    let (a, b) = (root(&mut parent, k), root(&mut parent, other));
                    parent[a.max(b)] = a.min(b);
                }
                None => {
                    owner.insert(n, k);
                }
            }
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for k in 0..cells.len() {
        let r = root(&mut parent, k);
        groups.entry(r).or_default().push(cells[k]);
    }
    groups.into_values().collect()
}

/// One sampler per shape among the cells to optimise: det J at the Bernstein lattice of
/// det J (the points whose values fix the polynomial det J, vertices and edges included,
/// where inversions start), or, where that lattice is too large, at the degree-2p
/// quadrature points and the nodes.
pub(crate) fn samplers(
    mesh: &HighOrderMesh,
    components: &[Vec<usize>],
) -> Result<Vec<JacobianSampler>, UntangleError> {
    let mut shapes: Vec<Shape> = Vec::new();
    for &c in components.iter().flatten() {
        let shape = mesh.cells[c].kind;
        if !shapes.contains(&shape) {
            shapes.push(shape);
        }
    }
    shapes.sort();
    shapes
        .into_iter()
        .map(|shape| {
            // Only the lattice points: no conversion matrix (33 MB and seconds at p = 8).
            let lattice = BernsteinSpace::lattice_only(shape, mesh.order)?;
            Ok(if lattice.len() <= MAX_LATTICE_POINTS {
                JacobianSampler::at_points(shape, mesh.order, mesh.family, lattice.points())?
            } else {
                JacobianSampler::new(shape, mesh.order, mesh.family, Sampling::Both)?
            })
        })
        .collect()
}

/// The energy of one set of cells, its free nodes (sorted) and a typical edge length.
pub(crate) fn patch_energy<'a>(
    mesh: &HighOrderMesh,
    straight: &[[f64; 3]],
    cells: &[usize],
    free: &[bool],
    samplers: &'a [JacobianSampler],
    shape_index: &BTreeMap<Shape, usize>,
) -> (DistortionEnergy<'a>, Vec<u32>, f64) {
    let dim = mesh.dim;
    let mut variables: Vec<u32> = cells
        .iter()
        .flat_map(|&c| mesh.cells[c].nodes.iter().copied())
        .filter(|&n| free[n as usize])
        .collect();
    variables.sort_unstable();
    variables.dedup();
    let mut length_sum = 0.0;
    let mut terms = Vec::with_capacity(cells.len());
    for &c in cells {
        let cell = &mesh.cells[c];
        let Some(&s) = shape_index.get(&cell.kind) else {
            continue; // unreachable: every shape has a sampler
        };
        let sampler = &samplers[s];
        let nodes = cell
            .nodes
            .iter()
            .map(|&n| match variables.binary_search(&n) {
                Ok(v) => Slot::Free(v as u32),
                Err(_) => Slot::Fixed(mesh.nodes[n as usize]),
            })
            .collect();
        let ideal_inverse = (0..sampler.points().len())
            .map(|q| {
                let mut w = [[0.0; 3]; 3];
                for (&n, g) in cell.nodes.iter().zip(sampler.point_gradients(q)) {
                    let x = straight[n as usize];
                    for d in 0..dim {
                        for k in 0..dim {
                            w[d][k] += x[d] * g[k];
                        }
                    }
                }
                inverse(&w, dim)
            })
            .collect();
        let (a, b) = (
            straight[cell.nodes[0] as usize],
            straight[cell.nodes[1] as usize],
        );
        length_sum += ((0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>()).sqrt();
        terms.push(CellTerm {
            sampler: s,
            nodes,
            ideal_inverse,
        });
    }
    let length = length_sum / cells.len().max(1) as f64;
    (
        DistortionEnergy {
            dim,
            samplers,
            cells: terms,
        },
        variables,
        length,
    )
}
