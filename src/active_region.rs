//! The active region of the elastic solve (the paper's strategy, DESIGN.md §6): the
//! displacement imposed on curved boundaries decays away from them, so only the cells near
//! the moved boundary nodes enter the solve, the others keep their straight high-order
//! nodes.
//!
//! The region is grown, not guessed: cells are ranked by rings of vertex neighbours from
//! the cells that hold a moved node (ring 0), the solve runs on rings 0..=L with the
//! region's outer nodes held fixed, and L grows (each time by at least a quarter more
//! cells) until the displacement on the outermost ring is at most `cutoff` × the thickness
//! of its cells — then holding the rest fixed strains the last ring by about that relative
//! amount. When the region would hold more than half the cells, or the regions tried add
//! up to the whole mesh, or the last one missed the cutoff by more than twice, one solve
//! on all cells is cheaper and is what runs.

use hocurve_elastic::{BoundaryConditions, ElasticSolution};
use hocurve_mesh::{HighOrderElement, HighOrderMesh};
use hocurve_nodes::Shape;

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
    /// The automatic region with a cutoff of 1e-2: the displacement held back from the
    /// cells outside is at most 1 % of their thickness, so the cells of the region's last
    /// ring take a strain of at most about 1 % that the whole solve would have spread
    /// further, and their scaled Jacobian moves by about as much (they are far from the
    /// curved boundary, nearly straight; the mesh's worst cells are not among them).
    pub const ACTIVE: SolveRegion = SolveRegion::Active { cutoff: 1e-2 };
}

impl std::str::FromStr for SolveRegion {
    type Err = String;
    /// "whole" or "active" (as on the command line).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "whole" => Ok(SolveRegion::Whole),
            "active" => Ok(SolveRegion::ACTIVE),
            _ => match s.strip_prefix("active=").map(str::parse::<f64>) {
                Some(Ok(cutoff)) if cutoff.is_finite() && cutoff >= 0.0 => {
                    Ok(SolveRegion::Active { cutoff })
                }
                _ => Err(format!(
                    "unknown solve region \"{s}\" (expected whole, active or active=CUTOFF \
                     with CUTOFF a non-negative number)"
                )),
            },
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

/// The thickness of a cell, which bounds how far its nodes may move before it folds: its
/// shortest edge, and for a simplex its smallest altitude, d·|K| / (largest facet measure)
/// (a boundary-layer cell is as thick as its wall-normal height, not as its long edges).
fn cell_thickness(mesh: &HighOrderMesh, cell: &HighOrderElement) -> f64 {
    let corner = |i: usize| mesh.nodes[cell.nodes[i] as usize];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let shortest_edge = cell
        .kind
        .edges()
        .iter()
        .map(|&[a, b]| norm(sub(corner(a), corner(b))))
        .fold(f64::INFINITY, f64::min);
    let altitude = match cell.kind {
        Shape::Tri => {
            let twice_area = norm(cross(sub(corner(1), corner(0)), sub(corner(2), corner(0))));
            let longest = cell
                .kind
                .edges()
                .iter()
                .map(|&[a, b]| norm(sub(corner(a), corner(b))))
                .fold(0.0, f64::max);
            twice_area / longest
        }
        Shape::Tet => {
            let [e1, e2, e3] = [1, 2, 3].map(|i| sub(corner(i), corner(0)));
            let c = cross(e1, e2);
            let six_volume = (c[0] * e3[0] + c[1] * e3[1] + c[2] * e3[2]).abs();
            let largest_twice_area = cell
                .kind
                .faces()
                .iter()
                .map(|f| {
                    norm(cross(
                        sub(corner(f[1]), corner(f[0])),
                        sub(corner(f[2]), corner(f[0])),
                    ))
                })
                .fold(0.0, f64::max);
            six_volume / largest_twice_area
        }
        _ => f64::INFINITY,
    };
    shortest_edge.min(altitude)
}

/// The solve `solve(mesh, boundary conditions, per-cell stiffening, initial guess)` of
/// [`solve_in_active_region`] and [`solve_whole_mesh`].
pub(crate) trait RegionSolve:
    FnMut(
    &HighOrderMesh,
    &BoundaryConditions,
    Option<&[f64]>,
    Option<&[[f64; 3]]>,
) -> Result<ElasticSolution, CurveError>
{
}

impl<F> RegionSolve for F where
    F: FnMut(
        &HighOrderMesh,
        &BoundaryConditions,
        Option<&[f64]>,
        Option<&[[f64; 3]]>,
    ) -> Result<ElasticSolution, CurveError>
{
}

/// The solve on every cell, after `solves` on smaller regions, CG started from `initial`
/// (a displacement of every node) when given.
pub(crate) fn solve_whole_mesh(
    mesh: &HighOrderMesh,
    bc: &BoundaryConditions,
    stiffening: Option<&[f64]>,
    initial: Option<&[[f64; 3]]>,
    solves: usize,
    solve: &mut impl RegionSolve,
) -> Result<RegionSolution, CurveError> {
    let solution = solve(mesh, bc, stiffening, initial)?;
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
/// Each try starts CG from the last one's displacement (the first from `initial`, a
/// displacement of every node, when given).
pub(crate) fn solve_in_active_region(
    mesh: &HighOrderMesh,
    bc: &BoundaryConditions,
    stiffening: Option<&[f64]>,
    cutoff: f64,
    initial: Option<&[[f64; 3]]>,
    mut solve: impl RegionSolve,
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
        return solve_whole_mesh(mesh, bc, stiffening, initial, 0, &mut solve);
    };
    // Cells within each number of rings.
    let mut within = vec![0usize; deepest + 1];
    for &r in ring.iter().filter(|&&r| r != usize::MAX) {
        within[r] += 1;
    }
    for r in 1..within.len() {
        within[r] += within[r - 1];
    }
    let mut rings = FIRST_RINGS;
    let mut solves = 0;
    // The displacement of every node the next solve starts from.
    let mut start: Option<Vec<[f64; 3]>> = initial.map(<[_]>::to_vec);
    let mut cells_solved = 0;
    loop {
        let region: Vec<usize> = (0..mesh.cells.len())
            .filter(|&c| ring[c] <= rings)
            .collect();
        // A region of more than half the cells (which may still have to grow) costs more
        // than one solve on them all, and so do regions tried before adding up to it.
        if rings >= deepest
            || 2 * region.len() > mesh.cells.len()
            || cells_solved + region.len() > mesh.cells.len()
        {
            return solve_whole_mesh(mesh, bc, stiffening, start.as_deref(), solves, &mut solve);
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
            } else if let Some(&direction) = bc.along_line.get(&m) {
                sub_bc.along_line.insert(s, direction);
            } else if let Some(&normal) = bc.sliding.get(&m) {
                sub_bc.sliding.insert(s, normal);
            }
        }
        let sub_stiffening: Option<Vec<f64>> =
            stiffening.map(|k| region.iter().map(|&c| k[c]).collect());
        let sub_start: Option<Vec<[f64; 3]>> = start
            .as_ref()
            .map(|u| source.iter().map(|&m| u[m as usize]).collect());
        let solution = solve(
            &sub,
            &sub_bc,
            sub_stiffening.as_deref(),
            sub_start.as_deref(),
        )?;
        solves += 1;
        cells_solved += region.len();
        // The displacement reaching the outermost ring, relative to its cells' thickness.
        let mut reach = 0.0f64;
        for (i, &c) in region.iter().enumerate() {
            if ring[c] != rings {
                continue;
            }
            let size = cell_thickness(mesh, &mesh.cells[c]);
            for &s in &sub.cells[i].nodes {
                let u = solution.displacement[s as usize];
                let length = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                reach = reach.max(length / size);
            }
        }
        let mut displacement = vec![[0.0; 3]; n];
        for (s, &m) in source.iter().enumerate() {
            displacement[m as usize] = solution.displacement[s];
        }
        if reach <= cutoff {
            return Ok(RegionSolution {
                displacement,
                solution,
                cells: region.len(),
                solves,
            });
        }
        // Far from a closed boundary the displacement decays slowly, like 1/r² (about ×0.7
        // per ring on the sphere-in-box meshes, and not at all inside boundary layers): a
        // region missing the cutoff by more than twice would grow past half the mesh.
        if reach > 2.0 * cutoff {
            return solve_whole_mesh(
                mesh,
                bc,
                stiffening,
                Some(&displacement),
                solves,
                &mut solve,
            );
        }
        start = Some(displacement);
        // Grow by at least a quarter more cells.
        let target = region.len() + region.len().div_ceil(4);
        rings = (rings + 1..=deepest)
            .find(|&r| within[r] >= target)
            .unwrap_or(deepest);
    }
}

#[cfg(test)]
#[path = "tests/active_region.rs"]
mod tests;
