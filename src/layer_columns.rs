//! Boundary-layer columns: the thin cells stacked on a curved wall move with the wall.
//!
//! Linear elasticity shears a boundary layer's thin cells inside out once the wall's
//! displacement is comparable to their height (DESIGN.md §13; the paper's Sect. 5 layers).
//! A *column* starts at a curved wall facet and climbs through the cells stacked on it —
//! hexahedra through their opposite face, prisms on their triangles through the other
//! triangle, quadrilaterals (2D) through their opposite edge — for as long as each cell is
//! thin (height below [`THIN_HEIGHT_FRACTION`] of its shortest wall-parallel edge). Every node
//! of a column's cells is given the wall's displacement at its *foot*: the point of the wall
//! facet with the same wall-parallel reference coordinates. Each wall-normal line of nodes
//! thus translates rigidly with the wall, so a thin cell becomes its curved wall facet swept
//! along its own straight height, which is valid at any stretch as long as the curved facet
//! is (its det J is the facet's area element times the unchanged height). The elastic solve
//! then takes the column tops as Dirichlet data and curves the coarser cells above them.
//!
//! Where two columns share a side their feet lie on the shared wall edge, so the prescribed
//! displacements agree: the displacement stays continuous. A column node on a sliding plane
//! keeps only the displacement's part in that plane (along the line of two planes), so that
//! it still slides; a node another condition fixes stays fixed.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_elastic::BoundaryConditions;
use hocurve_mesh::{HighOrderMesh, Shape, NO_CELL};
use hocurve_nodes::{LagrangeBasis, ReferenceNodes};
use hocurve_nurbs::vec3::{distance, dot};

use crate::pipeline::CurveError;

/// A cell enters a column while its height (the mean length of its wall-normal edges) is
/// below this fraction of its shortest wall-parallel edge: thin enough that elasticity would
/// shear it, where a cell of aspect near one is curved well by the solve.
pub const THIN_HEIGHT_FRACTION: f64 = 0.5;

/// The displacement the columns prescribe, and how many there are.
#[derive(Debug, Clone, Default)]
pub(crate) struct LayerColumns {
    /// Every node of a column's cells that is not on the wall: its foot's wall displacement.
    pub displacement: BTreeMap<u32, [f64; 3]>,
    /// Columns with at least one cell.
    pub columns: usize,
    /// Cells in columns.
    pub cells: usize,
}

impl LayerColumns {
    /// Adds the columns' displacements to `bc` as Dirichlet data: a sliding node keeps the
    /// part in its plane (on its line), a node already prescribed (fixed, or on the
    /// geometry) keeps its own value.
    pub fn prescribe(&self, bc: &mut BoundaryConditions) {
        for (&n, &u) in &self.displacement {
            if bc.prescribed.contains_key(&n) {
                continue;
            }
            let u = if let Some(normal) = bc.sliding.remove(&n) {
                let s = dot(u, normal) / dot(normal, normal);
                [0, 1, 2].map(|d| u[d] - s * normal[d])
            } else if let Some(line) = bc.along_line.remove(&n) {
                let s = dot(u, line) / dot(line, line);
                [0, 1, 2].map(|d| s * line[d])
            } else {
                u
            };
            bc.prescribed.insert(n, u);
        }
    }
}

/// The columns of `mesh` (straight-sided) standing on the facets whose every node has a
/// target in `targets` that differs from its straight position somewhere.
pub(crate) fn layer_columns(
    mesh: &HighOrderMesh,
    targets: &BTreeMap<u32, [f64; 3]>,
) -> Result<LayerColumns, CurveError> {
    layer_columns_by(mesh, |n| {
        let x = targets.get(&n)?;
        let x0 = mesh.nodes[n as usize];
        Some([x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]])
    })
}

/// The columns of `mesh` standing on the facets whose every node has a wall displacement
/// `displacement_of(node)`, some of it non-zero: the displacement of their nodes. Only the
/// vertices' positions are read (the stacking and thinness), so `mesh` may be curved.
pub(crate) fn layer_columns_by(
    mesh: &HighOrderMesh,
    displacement_of: impl Fn(u32) -> Option<[f64; 3]>,
) -> Result<LayerColumns, CurveError> {
    let topology = mesh.topology();
    let mut out = LayerColumns::default();
    let mut in_column = BTreeSet::new();
    // Reference nodes of the shapes that stack, the Lagrange bases of the facet shapes.
    let mut references: BTreeMap<Shape, ReferenceNodes> = BTreeMap::new();
    for shape in [Shape::Hex, Shape::Prism, Shape::Quad] {
        if mesh.cells.iter().any(|c| c.kind == shape) {
            let nodes = ReferenceNodes::try_new(shape, mesh.order, mesh.family)?;
            references.insert(shape, nodes);
        }
    }
    if references.is_empty() {
        return Ok(out);
    }
    let mut bases: BTreeMap<Shape, LagrangeBasis> = BTreeMap::new();
    for shape in [Shape::Line, Shape::Tri, Shape::Quad] {
        if mesh.facets.iter().any(|f| f.kind == shape) {
            let nodes = ReferenceNodes::try_new(shape, mesh.order, mesh.family)?;
            bases.insert(shape, LagrangeBasis::new(&nodes)?);
        }
    }
    for (i, facet) in mesh.facets.iter().enumerate() {
        let Some(wall) = facet
            .nodes
            .iter()
            .map(|&n| displacement_of(n))
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        if wall.iter().all(|u| *u == [0.0; 3]) {
            continue;
        }
        let f = mesh.facet_ids[i] as usize;
        let [mut cell, other] = topology.facet_cells(f);
        if other != NO_CELL {
            continue;
        }
        let k = facet.kind.num_vertices();
        let mut bottom: Vec<u32> = facet.nodes[..k].to_vec();
        let Some(basis) = bases.get(&facet.kind) else {
            continue;
        };
        let mut values = vec![0.0; basis.len()];
        let mut cells_here = 0;
        while cell != NO_CELL && in_column.insert(cell) {
            let c = cell as usize;
            let Some(stack) = Stacked::find(mesh, c, &bottom) else {
                break;
            };
            if !stack.is_thin(mesh, c) {
                break;
            }
            let shape = mesh.cells[c].kind;
            for (j, xi) in references[&shape].points().iter().enumerate() {
                let n = mesh.cells[c].nodes[j];
                if displacement_of(n).is_some() || out.displacement.contains_key(&n) {
                    continue;
                }
                let (w, _) = shape.vertex_shape_functions(*xi);
                let foot_weights: Vec<f64> = (0..k)
                    .map(|m| w[stack.bottom[m]] + w[stack.top[m]])
                    .collect();
                basis.eval(foot_reference(facet.kind, &foot_weights), &mut values);
                let mut u = [0.0; 3];
                for (phi, v) in values.iter().zip(&wall) {
                    for d in 0..3 {
                        u[d] += phi * v[d];
                    }
                }
                out.displacement.insert(n, u);
            }
            cells_here += 1;
            bottom = stack.top.iter().map(|&t| mesh.cells[c].nodes[t]).collect();
            let cell_facets = if mesh.dim == 3 {
                topology.cell_faces(c)
            } else {
                topology.cell_edges(c)
            };
            let [a, b] = topology.facet_cells(cell_facets[stack.opposite] as usize);
            cell = if a == cell { b } else { a };
        }
        if cells_here > 0 {
            out.columns += 1;
            out.cells += cells_here;
        }
    }
    Ok(out)
}

/// The reference coordinates of the point of a facet of shape `facet` with vertex weights
/// `w` (linear, barycentric or bilinear weights, in the facet's vertex order).
fn foot_reference(facet: Shape, w: &[f64]) -> [f64; 3] {
    match facet {
        Shape::Line => [w[1], 0.0, 0.0],
        Shape::Tri => [w[1], w[2], 0.0],
        // Bilinear weights: x = w1 + w2, y = w2 + w3 (vertices (0,0), (1,0), (1,1), (0,1)).
        _ => [w[1] + w[2], w[2] + w[3], 0.0],
    }
}

/// How one cell stands on its bottom facet: local vertices of the bottom (in the wall
/// facet's vertex order), the vertex above each, and the local facet opposite the bottom.
struct Stacked {
    bottom: Vec<usize>,
    top: Vec<usize>,
    opposite: usize,
}

impl Stacked {
    /// The stacking of cell `c` on the facet with global vertices `bottom`, if `c` is a
    /// hexahedron, a prism on a triangle or a quadrilateral (2D) with that facet.
    fn find(mesh: &HighOrderMesh, c: usize, bottom: &[u32]) -> Option<Stacked> {
        let cell = &mesh.cells[c];
        let shape = cell.kind;
        let stackable = match shape {
            Shape::Hex => bottom.len() == 4,
            Shape::Prism => bottom.len() == 3,
            Shape::Quad => bottom.len() == 2,
            _ => false,
        };
        if !stackable {
            return None;
        }
        let vertices = &cell.nodes[..shape.num_vertices()];
        let local: Vec<usize> = bottom
            .iter()
            .map(|g| vertices.iter().position(|v| v == g))
            .collect::<Option<_>>()?;
        let facets: Vec<Vec<usize>> = if mesh.dim == 3 {
            shape.faces().iter().map(|f| f.to_vec()).collect()
        } else {
            shape.edges().iter().map(|e| e.to_vec()).collect()
        };
        let opposite = facets
            .iter()
            .position(|f| f.len() == bottom.len() && f.iter().all(|v| !local.contains(v)))?;
        let top = local
            .iter()
            .map(|&b| {
                shape.edges().iter().find_map(|&[x, y]| {
                    let other = if x == b {
                        y
                    } else if y == b {
                        x
                    } else {
                        return None;
                    };
                    facets[opposite].contains(&other).then_some(other)
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Stacked {
            bottom: local,
            top,
            opposite,
        })
    }

    /// Whether the cell's height (mean length of its edges from bottom to top) is below
    /// [`THIN_HEIGHT_FRACTION`] of its bottom's shortest edge.
    fn is_thin(&self, mesh: &HighOrderMesh, c: usize) -> bool {
        let x = |l: usize| mesh.nodes[mesh.cells[c].nodes[l] as usize];
        let k = self.bottom.len();
        let height = (0..k)
            .map(|m| distance(x(self.bottom[m]), x(self.top[m])))
            .sum::<f64>()
            / k as f64;
        let sides = if k == 2 { 1 } else { k };
        let lateral = (0..sides)
            .map(|m| distance(x(self.bottom[m]), x(self.bottom[(m + 1) % k])))
            .fold(f64::INFINITY, f64::min);
        height < THIN_HEIGHT_FRACTION * lateral
    }
}
