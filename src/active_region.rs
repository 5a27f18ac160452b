//! The active region of the elastic solve (the paper's strategy, DESIGN.md §6): the
//! displacement imposed on curved boundaries decays within a few element layers, so only
//! the cells near the moved boundary nodes enter the solve, the others keep their straight
//! high-order nodes.
//!
//! The region is grown, not guessed: cells are ranked by rings of vertex neighbours from
//! the cells that hold a moved node (ring 0), the solve runs on rings 0..=L with the
//! region's outer nodes held fixed, and L doubles until the displacement on the outermost
//! ring is at most `cutoff` × the size of its elements — then holding the rest fixed
//! perturbs their shape by at most that relative amount — or the region would hold more
//! than half the cells, when one solve on all of them is cheaper.

use hocurve_elastic::{BoundaryConditions, ElasticSolution};
use hocurve_mesh::{HighOrderElement, HighOrderMesh};

use crate::pipeline::CurveError;

/// Which cells the elastic solve covers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolveRegion {
    /// Every cell.
    Whole,
    /// The cells near the moved boundary nodes, grown until the displacement reaching the
    /// region's outermost ring of cells is at most `cutoff` times their size.
    Active {
        /// Largest displacement on the outermost ring, relative to its element sizes.
        cutoff: f64,
    },
}

impl SolveRegion {
    /// The automatic region with a cutoff of 1e-3: the cells held fixed change shape by
    /// at most about 0.1 %, far below what the scaled Jacobian is reported to.
    pub const ACTIVE: SolveRegion = SolveRegion::Active { cutoff: 1e-3 };
}

impl std::str::FromStr for SolveRegion {
    type Err = String;
    /// "whole" or "active" (as on the command line).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "whole" => Ok(SolveRegion::Whole),
            "active" => Ok(SolveRegion::ACTIVE),
            _ => Err(format!(
                "unknown solve region \"{s}\" (expected whole or active)"
            )),
        }
    }
}

/// Rings 0..=`FIRST_RINGS` make the first region tried.
const FIRST_RINGS: usize = 2;

/// The displacement of every node from a solve on part of the mesh.
#[derive(Debug, Clone)]
pub(crate) struct RegionSolution {
    /// Displacement of every node of the whole mesh (zero outside the region).
    pub displacement: Vec<[f64; 3]>,
    /// The last solve (on the accepted region).
    pub solution: ElasticSolution,
    /// Cells in the accepted region.
    pub cells: usize,
    /// Solves run (one per region tried).
    pub solves: usize,
}

/// The ring of every cell around the cells that hold a moved node (`usize::MAX`: not
/// reachable from one), rings being vertex neighbours.
fn cell_rings(mesh: &HighOrderMesh, moved: &[bool]) -> Vec<usize> {
    let vertices = mesh.layout().num_vertices();
    let mut cells_of_vertex: Vec<Vec<u32>> = vec![Vec::new(); vertices];
    for (c, cell) in mesh.cells.iter().enumerate() {
        for &v in &cell.nodes[..cell.kind.num_vertices()] {
            if let Some(list) = cells_of_vertex.get_mut(v as usize) {
                list.push(c as u32);
            }
        }
    }
    let mut ring = vec![usize::MAX; mesh.cells.len()];
    let mut front: Vec<usize> = (0..mesh.cells.len())
        .filter(|&c| mesh.cells[c].nodes.iter().any(|&n| moved[n as usize]))
        .collect();
    for &c in &front {
        ring[c] = 0;
    }
    let mut r = 0;
    while !front.is_empty() {
        r += 1;
        let mut next = Vec::new();
        for &c in &front {
            let cell = &mesh.cells[c];
            for &v in &cell.nodes[..cell.kind.num_vertices()] {
                for &d in cells_of_vertex
                    .get(v as usize)
                    .map_or(&[][..], Vec::as_slice)
                {
                    if ring[d as usize] == usize::MAX {
                        ring[d as usize] = r;
                        next.push(d as usize);
                    }
                }
            }
        }
        next.sort_unstable();
        front = next;
    }
    ring
}

/// Largest vertex-to-vertex distance of a cell: its size.
fn cell_size(mesh: &HighOrderMesh, cell: &HighOrderElement) -> f64 {
    let corners = &cell.nodes[..cell.kind.num_vertices()];
    let mut size = 0.0f64;
    for (i, &a) in corners.iter().enumerate() {
        for &b in &corners[i + 1..] {
            let (x, y) = (mesh.nodes[a as usize], mesh.nodes[b as usize]);
            let d2: f64 = (0..3).map(|k| (x[k] - y[k]) * (x[k] - y[k])).sum();
            size = size.max(d2.sqrt());
        }
    }
    size
}

/// The solve on every cell, after `solves` on smaller regions.
pub(crate) fn solve_whole_mesh(
    mesh: &HighOrderMesh,
    bc: &BoundaryConditions,
    stiffening: Option<&[f64]>,
    solves: usize,
    solve: &mut impl FnMut(
        &HighOrderMesh,
        &BoundaryConditions,
        Option<&[f64]>,
    ) -> Result<ElasticSolution, CurveError>,
) -> Result<RegionSolution, CurveError> {
    let solution = solve(mesh, bc, stiffening)?;
    Ok(RegionSolution {
        displacement: solution.displacement.clone(),
        solution,
        cells: mesh.cells.len(),
        solves: solves + 1,
    })
}

/// Solves for the displacement with `solve` (mesh, boundary conditions, per-cell
/// stiffening) on the smallest region of rings around the moved nodes of `bc` that
/// meets `cutoff` (see the module documentation), holding the region's outer nodes fixed.
pub(crate) fn solve_in_active_region(
    mesh: &HighOrderMesh,
    bc: &BoundaryConditions,
    stiffening: Option<&[f64]>,
    cutoff: f64,
    mut solve: impl FnMut(
        &HighOrderMesh,
        &BoundaryConditions,
        Option<&[f64]>,
    ) -> Result<ElasticSolution, CurveError>,
) -> Result<RegionSolution, CurveError> {
    let n = mesh.nodes.len();
    let mut moved = vec![false; n];
    for (&node, u) in &bc.prescribed {
        if let Some(m) = moved.get_mut(node as usize) {
            *m = u.iter().any(|&x| x != 0.0);
        }
    }
    let ring = cell_rings(mesh, &moved);
    let deepest = ring.iter().filter(|&&r| r != usize::MAX).max().copied();
    let Some(deepest) = deepest else {
        // Nothing moves (or only slides): the whole solve is as cheap as any.
        return solve_whole_mesh(mesh, bc, stiffening, 0, &mut solve);
    };
    let mut rings = FIRST_RINGS;
    let mut solves = 0;
    loop {
        let region: Vec<usize> = (0..mesh.cells.len())
            .filter(|&c| ring[c] <= rings)
            .collect();
        // A region of more than half the cells (which may still have to grow) costs more
        // than one solve on them all.
        if rings >= deepest || 2 * region.len() > mesh.cells.len() {
            return solve_whole_mesh(mesh, bc, stiffening, solves, &mut solve);
        }
        let mut fixed = vec![false; n];
        for (c, cell) in mesh.cells.iter().enumerate() {
            if ring[c] > rings {
                for &m in &cell.nodes {
                    fixed[m as usize] = true;
                }
            }
        }
        let cells: Vec<HighOrderElement> = region.iter().map(|&c| mesh.cells[c].clone()).collect();
        let (sub, source) = HighOrderMesh::from_cells_with_source_nodes(
            mesh.dim,
            mesh.order,
            mesh.family,
            &mesh.nodes,
            &cells,
            &[],
        )?;
        let mut sub_bc = BoundaryConditions::default();
        for (s, &m) in source.iter().enumerate() {
            let s = s as u32;
            if let Some(&u) = bc.prescribed.get(&m) {
                sub_bc.prescribed.insert(s, u);
            } else if fixed[m as usize] {
                sub_bc.prescribed.insert(s, [0.0; 3]);
            } else if let Some(&normal) = bc.sliding.get(&m) {
                sub_bc.sliding.insert(s, normal);
            }
        }
        let sub_stiffening: Option<Vec<f64>> =
            stiffening.map(|k| region.iter().map(|&c| k[c]).collect());
        let solution = solve(&sub, &sub_bc, sub_stiffening.as_deref())?;
        solves += 1;
        // The displacement reaching the outermost ring, relative to its cells' sizes.
        let mut reach = 0.0f64;
        for (i, &c) in region.iter().enumerate() {
            if ring[c] != rings {
                continue;
            }
            let size = cell_size(mesh, &mesh.cells[c]);
            for &s in &sub.cells[i].nodes {
                let u = solution.displacement[s as usize];
                let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                reach = reach.max(length / size);
            }
        }
        if reach <= cutoff {
            let mut displacement = vec![[0.0; 3]; n];
            for (s, &m) in source.iter().enumerate() {
                displacement[m as usize] = solution.displacement[s];
            }
            return Ok(RegionSolution {
                displacement,
                solution,
                cells: region.len(),
                solves,
            });
        }
        rings *= 2;
    }
}

#[cfg(test)]
#[path = "tests/active_region.rs"]
mod tests;
