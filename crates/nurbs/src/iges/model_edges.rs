//! The CAD edges of a 3D IGES model. IGES 144 faces carry no shared topology, but each
//! face's boundary (its 142 curves on surface) gives the edges' model-space curves: the
//! faces on either side of an edge each hold a copy. Copies that coincide are one
//! [`ModelEdge`] bounding those faces, as STEP's `EDGE_CURVE`s are (see
//! [`crate::step`]): the curve the modeller gave a seam where faces meet tangentially,
//! which has no well-defined intersection to trace.

use super::converter::Converter;
use super::entities::EntityData;
use super::model::IgesEntity;
use crate::inversion::closest_point_on_curve;
use crate::model::{EntityGeometry, ModelEdge};
use crate::vec3::distance;
use crate::NurbsCurve;

/// One face's copy of an edge: the face (entity index), where it came from, its curve and
/// its end points.
struct EdgeCopy {
    face: usize,
    origin: String,
    curve: NurbsCurve,
    ends: [[f64; 3]; 2],
}

impl<'a> Converter<'a> {
    /// The model-space curves of face `e`'s boundary: for a 144 trimmed surface, the model
    /// curves of its outer and inner 142 entities, one per CAD edge (the members of a 102).
    /// Boundaries given only in parameter space, and any that do not convert, are left out
    /// (the seams along them are then traced, as for a model without edges).
    pub(super) fn face_edge_curves(&self, e: &'a IgesEntity) -> Vec<(String, NurbsCurve)> {
        let EntityData::TrimmedSurface { outer, inner, .. } = &e.kind else {
            return Vec::new();
        };
        let placed = self.own_transform(e);
        let mut out = Vec::new();
        for &de in outer.iter().chain(inner) {
            let Ok(boundary) = self.child(de, e) else {
                continue;
            };
            if let EntityData::CurveOnSurface {
                model_curve: None, ..
            } = boundary.kind
            {
                continue;
            }
            let Ok(curves) = self.curve_entities(boundary, &placed, "") else {
                continue;
            };
            for (k, c) in curves.into_iter().enumerate() {
                if let EntityGeometry::Curve(curve) = c.geometry {
                    let origin = format!(
                        "IGES boundary curve {} of entity 142 (DE {}, line {}) of entity 144 (DE {})",
                        k + 1,
                        boundary.de,
                        boundary.line,
                        e.de
                    );
                    out.push((origin, curve));
                }
            }
        }
        out
    }
}

/// The edges between faces from each face's boundary curves (`faces`: entity index, its
/// curves): copies with the same end points whose interior points lie on each other within
/// `tolerance` are one edge; an edge is kept when it bounds two faces or more (a periodic
/// face's seam bounds that face alone, twice). Faces ascending, the first copy's curve.
pub(super) fn edges_between_faces(
    faces: Vec<(usize, Vec<(String, NurbsCurve)>)>,
    tolerance: f64,
) -> Vec<ModelEdge> {
    let mut copies: Vec<EdgeCopy> = faces
        .into_iter()
        .flat_map(|(face, curves)| {
            curves.into_iter().map(move |(origin, curve)| {
                let (t0, t1) = curve.domain();
                let ends = [curve.point(t0), curve.point(t1)];
                EdgeCopy {
                    face,
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
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    for i in 0..n {
        for j in i + 1..n {
            if key(&copies[j]) - key(&copies[i]) > tolerance {
                break;
            }
            if same_edge(&copies[i], &copies[j], tolerance) {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for k in 0..n {
        let r = root(&mut parent, k);
        groups.entry(r).or_default().push(k);
    }
    let mut edges: Vec<ModelEdge> = groups
        .into_values()
        .filter_map(|group| {
            let mut faces: Vec<usize> = group.iter().map(|&k| copies[k].face).collect();
            faces.sort_unstable();
            faces.dedup();
            let first = group.iter().copied().min_by_key(|&k| copies[k].face)?;
            (faces.len() >= 2).then(|| ModelEdge {
                origin: copies[first].origin.clone(),
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
            closest_point_on_curve(&q.curve, x).distance <= tolerance
        })
    };
    ends && inside(a, b) && inside(b, a)
}

#[cfg(test)]
#[path = "tests/model_edges.rs"]
mod tests;
