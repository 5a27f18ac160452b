//! The CAD edges between faces, from each face's boundary curves: the faces on either
//! side of an edge each hold a copy of its curve (an IGES face's 142 boundary, a STEP
//! face's `EDGE_CURVE`s — shared when the faces are sewn, separate copies when each face is
//! its own shell). Copies that coincide are one [`ModelEdge`] bounding those faces: the
//! curve the modeller gave a seam where faces meet tangentially, which has no
//! well-defined intersection to trace.

use crate::groups::Groups;
use crate::inversion::closest_point_on_curve;
use crate::model::ModelEdge;
use crate::vec3::distance;
use crate::NurbsCurve;

/// Each 3D face's model-space boundary curves, by entity index: its copies of the edges
/// that bound it, each with where it came from.
pub(crate) type FaceBoundaries = Vec<(usize, Vec<(String, NurbsCurve)>)>;

/// One face's copy of an edge: the face (entity index), where it came from, its curve and
/// its end points.
struct EdgeCopy<'a> {
    face: usize,
    origin: &'a str,
    curve: &'a NurbsCurve,
    ends: [[f64; 3]; 2],
}

/// The edges between faces from each face's boundary curves (`faces`: entity index, its
/// curves): copies with the same end points whose interior points lie on each other within
/// `tolerance` are one edge; an edge is kept when it bounds two faces or more (a periodic
/// face's seam bounds that face alone, twice). Faces ascending, the first copy's curve.
pub(crate) fn edges_between_faces(faces: &FaceBoundaries, tolerance: f64) -> Vec<ModelEdge> {
    let mut copies: Vec<EdgeCopy> = faces
        .iter()
        .flat_map(|(face, curves)| {
            curves.iter().map(move |(origin, curve)| {
                let (t0, t1) = curve.domain();
                let ends = [curve.point(t0), curve.point(t1)];
                EdgeCopy {
                    face: *face,
                    origin,
                    curve,
                    ends,
                }
            })
        })
        .collect();
    // Sorted by the lower end's x: copies of one edge are then within `tolerance` of each
    // other in that key, and only such neighbours are compared.
    let key = |c: &EdgeCopy| c.ends[0][0].min(c.ends[1][0]);
    copies.sort_by(|a, b| key(a).total_cmp(&key(b)));
    let n = copies.len();
    let mut groups = Groups::new(n);
    for i in 0..n {
        for j in i + 1..n {
            if key(&copies[j]) - key(&copies[i]) > tolerance {
                break;
            }
            if same_edge(&copies[i], &copies[j], tolerance) {
                groups.join(i, j);
            }
        }
    }
    let mut edges: Vec<ModelEdge> = groups
        .of(|_| true)
        .into_iter()
        .filter_map(|group| {
            let mut faces: Vec<usize> = group.iter().map(|&k| copies[k].face).collect();
            faces.sort_unstable();
            faces.dedup();
            let first = group.iter().copied().min_by_key(|&k| copies[k].face)?;
            (faces.len() >= 2).then(|| ModelEdge {
                origin: copies[first].origin.to_string(),
                curve: copies[first].curve.clone(),
                faces,
            })
        })
        .collect();
    // In the faces' order, whatever the sort by coordinates did.
    edges.sort_by(|a, b| a.faces.cmp(&b.faces).then(a.origin.cmp(&b.origin)));
    edges
}

/// Whether two copies are one edge: the same end points (either way round), and each one's
/// points at a quarter, half and three quarters of its parameter range on the other.
fn same_edge(a: &EdgeCopy, b: &EdgeCopy, tolerance: f64) -> bool {
    let near = |x: [f64; 3], y: [f64; 3]| distance(x, y) <= tolerance;
    let ends = (near(a.ends[0], b.ends[0]) && near(a.ends[1], b.ends[1]))
        || (near(a.ends[0], b.ends[1]) && near(a.ends[1], b.ends[0]));
    let inside = |p: &EdgeCopy, q: &EdgeCopy| {
        let (t0, t1) = p.curve.domain();
        [0.25, 0.5, 0.75].iter().all(|f| {
            let x = p.curve.point(t0 + (t1 - t0) * f);
            closest_point_on_curve(q.curve, x).distance <= tolerance
        })
    };
    ends && inside(a, b) && inside(b, a)
}

#[cfg(test)]
#[path = "tests/face_edges.rs"]
mod tests;
