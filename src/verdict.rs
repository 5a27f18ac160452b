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
    pub fn of(linear: &LinearMesh, curved: &CurvedMesh) -> Self {
        // Cells are those of the mesh that was curved (the input, or the input with split
        // edges: the halves of a split cell keep its tag, appended ones get new tags).
        let linear = curved.split_input.as_ref().unwrap_or(linear);
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
                    " (two of its faces lie on one curved surface and meet along an edge: curved, they open to 180° there, det J = 0; split this cell in the input)"
                } else {
                    ""
                };
                format!(
                    "input element tag {} at ({:.4}, {:.4}, {:.4}){bound}{cause}",
                    linear.cell_tag(c),
                    centre[0],
                    centre[1],
                    centre[2]
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
