//! What is wrong with a curved mesh, in words a user can act on: the elements not
//! certified valid by their Gmsh element tags with a position and their bound, the steps
//! that were tried on them, and boundary nodes off the geometry.

use hocurve_mesh::LinearMesh;

use crate::pipeline::{CurveReport, CurvedMesh};

/// Largest distance of a written curved-boundary node from the geometry, relative to the
/// model size, that a mesh may have to be called "on the geometry".
pub const GEOMETRY_DISTANCE_LIMIT: f64 = 1e-10;

/// The elements of a curved mesh that are not certified valid, each named by its input
/// Gmsh element tag with its vertex centroid and certified bound, and what was tried.
pub struct Uncertified {
    /// One description per element.
    pub elements: Vec<String>,
    /// The steps run before giving up ("the elastic solve, then ...").
    pub tried: String,
}

impl Uncertified {
    /// The elements of `curved` not certified valid; `linear` is the input it was curved
    /// from (its cell tags name the elements).
    pub fn of(input: &LinearMesh, curved: &CurvedMesh) -> Self {
        // Cells are those of the mesh that was curved (the input, or the input with split
        // edges: the halves of a split cell keep its tag, appended ones get new tags, which
        // the input does not have: those are named by the input element they are part of).
        let linear = curved.split_input.as_ref().unwrap_or(input);
        let quality = &curved.quality;
        let elements = crate::repair::not_certified(quality)
            .into_iter()
            .map(|c| {
                let vertices = linear.cells.get(c).map_or(&[][..], |e| &e.vertices[..]);
                let mut centre = [0.0; 3];
                for &v in vertices {
                    for d in 0..3 {
                        centre[d] += linear.vertices[v as usize][d] / vertices.len() as f64;
                    }
                }
                let bound = quality
                    .validity
                    .as_ref()
                    .map(|v| format!(", Ĩ ≥ {:.3}", v[c].scaled_jacobian_lower_bound))
                    .unwrap_or_default();
                let cause = if curved.report.doubly_curved_cells.contains(&c) {
                    " (two of its faces lie on one curved surface and meet along an edge: curved, they open to 180° there, det J = 0; split this cell in the input, or mesh finer there so that no cell has two faces on one curved surface, e.g. Gmsh's Mesh.MeshSizeFromCurvature)"
                } else {
                    ""
                };
                let name = match (c >= input.cells.len())
                    .then(|| split_from(input, linear, c))
                {
                    None => format!("input element tag {}", linear.cell_tag(c)),
                    // Its own tag is in neither file (the written file numbers its
                    // elements 1, 2, …): the input element it is part of is.
                    Some(Some(parent)) => format!(
                        "a part of input element tag {} (split)",
                        input.cell_tag(parent)
                    ),
                    Some(None) => "an element made by splitting".to_string(),
                };
                format!(
                    "{name} at ({:.4}, {:.4}, {:.4}){bound}{cause}",
                    centre[0], centre[1], centre[2]
                )
            })
            .collect();
        let r = &curved.report;
        let mut tried = if r.solver == "none" {
            "placing the boundary nodes".to_string()
        } else if r.corrections_undone > 0 {
            format!(
                "the elastic solve (with {} minimum-angle correction(s) undone)",
                r.corrections_undone
            )
        } else {
            "the elastic solve".to_string()
        };
        if r.uncertified_after_solve > 0 && !r.repair_steps().is_empty() {
            tried += &format!(", then {}", r.repair_steps());
        }
        Uncertified { elements, tried }
    }

    /// No element to name.
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }
}

impl std::fmt::Display for Uncertified {
    /// The count, what was tried, and the first eight elements.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let shown: Vec<&str> = self.elements.iter().take(8).map(String::as_str).collect();
        write!(
            f,
            "{} element(s) not certified valid after {}: {}{}",
            self.elements.len(),
            self.tried,
            shown.join("; "),
            if self.elements.len() > shown.len() {
                "; …"
            } else {
                ""
            }
        )
    }
}

/// The input cell that cell `c` of `split` (the input with edges split, cells appended)
/// was cut from: of the input cells sharing the most vertices with it (by node tag), the
/// one its vertex centroid lies deepest inside (a half of a split tetrahedron shares a face
/// with its parent and with the neighbour across that face; its centroid is inside the
/// parent). None when it shares no vertex with any.
fn split_from(input: &LinearMesh, split: &LinearMesh, c: usize) -> Option<usize> {
    let cell = split.cells.get(c)?;
    let tags: Vec<u64> = cell
        .vertices
        .iter()
        .map(|&v| split.vertex_tag(v as usize))
        .collect();
    let centroid = |mesh: &LinearMesh, vertices: &[u32]| {
        let mut x = [0.0; 3];
        for &v in vertices {
            for d in 0..3 {
                x[d] += mesh.vertices[v as usize][d] / vertices.len() as f64;
            }
        }
        x
    };
    let centre = centroid(split, &cell.vertices);
    input
        .cells
        .iter()
        .enumerate()
        .filter_map(|(k, e)| {
            let shared = e
                .vertices
                .iter()
                .filter(|&&v| tags.contains(&input.vertex_tag(v as usize)))
                .count();
            (shared > 0).then(|| {
                let corners: Vec<[f64; 3]> = e
                    .vertices
                    .iter()
                    .map(|&v| input.vertices[v as usize])
                    .collect();
                let depth = simplex_depth(&corners, centre).unwrap_or_else(|| {
                    // Not a simplex: nearer centroids are deeper.
                    let y = centroid(input, &e.vertices);
                    -(0..3)
                        .map(|d| (y[d] - centre[d]).powi(2))
                        .sum::<f64>()
                        .sqrt()
                });
                (shared, depth, k)
            })
        })
        .max_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)))
        .map(|(_, _, k)| k)
}

/// The least barycentric coordinate of `x` in the triangle (in its plane, z ignored: 2D
/// meshes lie in z = const) or tetrahedron `corners` (positive inside); None for other
/// shapes or degenerate ones.
fn simplex_depth(corners: &[[f64; 3]], x: [f64; 3]) -> Option<f64> {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    match corners {
        [a, b, c] => {
            let (u, v, w) = (sub(*b, *a), sub(*c, *a), sub(x, *a));
            let det = u[0] * v[1] - u[1] * v[0];
            (det != 0.0).then(|| {
                let l1 = (w[0] * v[1] - w[1] * v[0]) / det;
                let l2 = (u[0] * w[1] - u[1] * w[0]) / det;
                (1.0 - l1 - l2).min(l1).min(l2)
            })
        }
        [a, b, c, d] => {
            let m = [sub(*b, *a), sub(*c, *a), sub(*d, *a)];
            let w = sub(x, *a);
            let det3 = |p: [f64; 3], q: [f64; 3], r: [f64; 3]| {
                p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0])
                    + p[2] * (q[0] * r[1] - q[1] * r[0])
            };
            let det = det3(m[0], m[1], m[2]);
            (det != 0.0).then(|| {
                // Cramer's rule for x − a = Σ λ_i (corner_i − a).
                let l1 = det3(w, m[1], m[2]) / det;
                let l2 = det3(m[0], w, m[2]) / det;
                let l3 = det3(m[0], m[1], w) / det;
                (1.0 - l1 - l2 - l3).min(l1).min(l2).min(l3)
            })
        }
        _ => None,
    }
}

/// Why the written boundary nodes of `curved` are not on the geometry (farther than
/// [`GEOMETRY_DISTANCE_LIMIT`] × `model_size` beyond the separation of the faces they lie
/// on, where the geometry file says its faces meet only to its uncertainty), or None when
/// they are.
pub fn off_geometry(curved: &CurvedMesh, model_size: f64) -> Option<String> {
    let r = &curved.report;
    let beyond = r.distance_beyond_seams;
    (beyond > GEOMETRY_DISTANCE_LIMIT * model_size).then(|| {
        let seams = match r.geometry_uncertainty {
            Some(u) if r.max_seam_gap > u => format!(
                " (on edges where the geometry's faces are up to {:.1e} apart, more than the {u:.1e} to which the file says they meet: no point is on both; if the model is known to be that loose, --geometry-gap {:.1e} takes its faces to meet to that)",
                r.max_seam_gap,
                // Rounded up, so that the suggestion covers the gap measured.
                r.max_seam_gap * 1.05
            ),
            _ if r.max_seam_gap > 0.0 => format!(
                " beyond the {:.1e} by which the faces they lie on are apart",
                r.max_seam_gap
            ),
            _ => String::new(),
        };
        format!(
            "written boundary nodes lie up to {beyond:.3e} from the geometry{seams}, more than {GEOMETRY_DISTANCE_LIMIT:e} of the model size {model_size:.3e}"
        )
    })
}

/// What a user should know about a run that succeeded: input nodes left out.
pub fn warnings(report: &CurveReport) -> Vec<String> {
    let unused = &report.unused_node_tags;
    if unused.is_empty() {
        return Vec::new();
    }
    let shown: Vec<String> = unused.iter().take(8).map(u64::to_string).collect();
    vec![format!(
        "{} node(s) belong to no cell and are left out of the output (node tags {}{})",
        unused.len(),
        shown.join(", "),
        if unused.len() > shown.len() {
            ", …"
        } else {
            ""
        }
    )]
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_mesh::{Element, Shape};

    /// Two tetrahedra sharing the face 0 1 2 and two more on the upper one's other faces,
    /// tagged like a file's: after the edge 0–1 is split, each appended half is named with
    /// the input tetrahedron it was cut from, although it shares a face with a neighbour
    /// of that one too.
    #[test]
    fn an_appended_half_is_named_by_the_input_cell_it_was_cut_from() {
        let tet = |vertices: [u32; 4]| Element {
            kind: Shape::Tet,
            vertices: vertices.to_vec(),
            entity: 1,
        };
        let input = LinearMesh {
            dim: 3,
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, -1.0],
                [-1.0, 0.2, 0.2],
                [1.0, 1.0, 1.0],
            ],
            cells: vec![
                tet([0, 1, 2, 3]),
                tet([0, 2, 1, 4]),
                tet([0, 2, 3, 5]),
                tet([1, 2, 3, 6]),
            ],
            vertex_tags: vec![11, 12, 13, 14, 15, 16, 17],
            cell_tags: vec![201, 202, 203, 204],
            ..Default::default()
        };
        let (split, count) = input.split_edges(&[[0, 1]]);
        assert_eq!((count, split.cells.len()), (1, 6));
        for c in 4..6 {
            let above = split.cells[c]
                .vertices
                .iter()
                .any(|&v| split.vertices[v as usize][2] > 0.0);
            let parent = split_from(&input, &split, c).unwrap();
            assert_eq!(parent, if above { 0 } else { 1 }, "cell {c}");
            assert!(split.cell_tag(c) > 204);
        }
    }
}
