//! Distance of nodes from the entities they lie on: measured, and removed by projecting the
//! nodes onto their entities.
//!
//! Where a node lies on several entities that the modeller made separately (a fillet's
//! B-spline beside the exact sphere it rounds), the entities may meet only to the file's
//! stated uncertainty: OpenCASCADE's fillet of a sphere on a plane leaves its B-spline
//! 2.0e-6 from the sphere along their common edge (uncertainty 5e-6 in the STEP file), so
//! no point is on both. There the node is measured against what the model allows: its
//! distance beyond the entities' own separation s at that place (the spread of the node's
//! feet on them), max(0, d − min(s, δ)) for the file's uncertainty δ — points closer than
//! δ being one point by the file's own definition. (Where the faces meet elsewhere is no
//! measure: that fillet's B-spline, continued past its edge, crosses the sphere at a
//! grazing angle 3e-4 away.)

use std::collections::BTreeMap;

use hocurve_nurbs::GeometryModel;
use rayon::prelude::*;

use crate::GeodesicError;

/// How far nodes are from the entities they lie on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GeometryDistance {
    /// Largest distance of a node from any of its entities.
    pub max: f64,
    /// Largest distance beyond what the model's own seams explain (see the module doc):
    /// `max` where the entities meet.
    pub beyond_seams: f64,
    /// Largest separation of a node's entities where they should meet (0 where they all
    /// do); only up to the file's uncertainty is it honoured in `beyond_seams`.
    pub max_seam_gap: f64,
}

impl GeometryDistance {
    fn merge(self, other: Self) -> Self {
        Self {
            max: self.max.max(other.max),
            beyond_seams: self.beyond_seams.max(other.beyond_seams),
            max_seam_gap: self.max_seam_gap.max(other.max_seam_gap),
        }
    }
}

/// Below this distance relative to the model, a node is on its entities up to round-off and
/// their separation is not measured.
const ROUND_OFF: f64 = 1e-13;

/// How far `x` is from `entities`, and beyond their separation there (module doc). `size`
/// is the model's size.
pub(super) fn node_distance(
    geometry: &GeometryModel,
    x: [f64; 3],
    entities: &[usize],
    size: f64,
) -> GeometryDistance {
    let d = distance_to_all(geometry, x, entities);
    let plain = GeometryDistance {
        max: d,
        beyond_seams: d,
        max_seam_gap: 0.0,
    };
    let Some(uncertainty) = geometry.uncertainty else {
        return plain;
    };
    if entities.len() < 2 || d <= ROUND_OFF * size {
        return plain;
    }
    // The entities' separation at x: the spread of x's feet on them (a node on one face
    // and the gap away from the other, or half-way, is explained by the gap; a node off
    // both by e beyond it is e off).
    let feet: Vec<[f64; 3]> = entities
        .iter()
        .map(|&e| geometry.entities[e].nearest_point(x))
        .collect();
    let mut gap: f64 = 0.0;
    for (i, a) in feet.iter().enumerate() {
        for b in &feet[i + 1..] {
            gap = gap.max(hocurve_nurbs::vec3::distance(*a, *b));
        }
    }
    GeometryDistance {
        max: d,
        beyond_seams: (d - gap.min(uncertainty)).max(0.0),
        max_seam_gap: gap,
    }
}

/// Largest distance of a target from the entities it should lie on.
pub(super) fn max_distance(
    geometry: &GeometryModel,
    targets: &BTreeMap<u32, [f64; 3]>,
    entities: &BTreeMap<u32, Vec<usize>>,
) -> f64 {
    let work: Vec<([f64; 3], &Vec<usize>)> = targets
        .iter()
        .filter_map(|(n, x)| entities.get(n).map(|e| (*x, e)))
        .collect();
    work.par_iter()
        .map(|(x, es)| distance_to_all(geometry, *x, es))
        .reduce(|| 0.0, f64::max)
}

/// The largest distance of `x` from any of `entities`.
pub(super) fn distance_to_all(geometry: &GeometryModel, x: [f64; 3], entities: &[usize]) -> f64 {
    entities
        .iter()
        .map(|&e| geometry.entities[e].distance(x))
        .fold(0.0, f64::max)
}

/// Moves every node of `nodes` listed in `entities` (node id → the entities it lies on, as
/// in [`BoundaryTargets::entities`](super::BoundaryTargets::entities)) onto its entities: to
/// its position in `placed` when it has one (the nodes of feature edges, from their traced
/// curves: [`BoundaryTargets::equispaced_feature_nodes`](super::BoundaryTargets::equispaced_feature_nodes)), else the closest point for one entity,
/// alternating projections for a node on several (a corner). Used for the
/// nodes that are written, when they are interpolated from another node family: the
/// interpolant of on-surface nodes leaves the surface between them (by 1e-3 of the size on
/// a coarse sphere at p = 3). Returns the distances then left, measured afresh.
pub fn project_nodes_onto_geometry(
    geometry: &GeometryModel,
    entities: &BTreeMap<u32, Vec<usize>>,
    placed: &BTreeMap<u32, [f64; 3]>,
    nodes: &mut [[f64; 3]],
) -> Result<GeometryDistance, GeodesicError> {
    let work: Vec<(u32, &Vec<usize>)> = entities.iter().map(|(&n, e)| (n, e)).collect();
    if let Some(&n) = entities
        .keys()
        .chain(placed.keys())
        .find(|&&n| n as usize >= nodes.len())
    {
        return Err(GeodesicError::Mismatch(format!(
            "node {n} of the boundary is not among the {} nodes",
            nodes.len()
        )));
    }
    let size = geometry.size();
    let moved: Vec<([f64; 3], GeometryDistance)> = work
        .par_iter()
        .map(|&(n, es)| {
            let snapped = |x: [f64; 3]| {
                let y = crate::association::snap_onto(geometry, es, x);
                let y = onto_one_where_apart(geometry, es, y, size);
                (y, node_distance(geometry, y, es, size))
            };
            let Some(&p) = placed.get(&n) else {
                return snapped(nodes[n as usize]);
            };
            let p = onto_one_where_apart(geometry, es, p, size);
            let at_p = node_distance(geometry, p, es, size);
            if at_p.beyond_seams <= ROUND_OFF * size {
                return (p, at_p);
            }
            // Where the seam's trace did not settle on both faces, the snap from it may
            // do better (or slide along faces that stay close): the nearer of the two.
            let (s, at_s) = snapped(p);
            if at_s.beyond_seams < at_p.beyond_seams {
                (s, at_s)
            } else {
                (p, at_p)
            }
        })
        .collect();
    let mut largest = GeometryDistance::default();
    for ((n, _), (y, d)) in work.iter().zip(moved) {
        nodes[*n as usize] = y;
        largest = largest.merge(d);
    }
    Ok(largest)
}

/// `y` on several `entities` that do not meet there (the seam solvers leave it half-way,
/// within half the gap of each) projected onto the nearest of them: exactly on one face,
/// the gap from the others — what a reader measuring its distance to the nearest face
/// expects. Unchanged where they meet to round-off.
fn onto_one_where_apart(
    geometry: &GeometryModel,
    entities: &[usize],
    y: [f64; 3],
    size: f64,
) -> [f64; 3] {
    if entities.len() < 2 || distance_to_all(geometry, y, entities) <= ROUND_OFF * size {
        return y;
    }
    // (The lowest index of equally near ones.)
    let nearest = entities
        .iter()
        .map(|&e| (geometry.entities[e].distance(y), e))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    nearest.map_or(y, |(_, e)| geometry.entities[e].nearest_point(y))
}

/// The distances of the nodes listed in `entities` from their entities.
pub fn max_distance_from_geometry(
    geometry: &GeometryModel,
    entities: &BTreeMap<u32, Vec<usize>>,
    nodes: &[[f64; 3]],
) -> GeometryDistance {
    let size = geometry.size();
    let work: Vec<([f64; 3], &Vec<usize>)> = entities
        .iter()
        .filter_map(|(&n, e)| nodes.get(n as usize).map(|x| (*x, e)))
        .collect();
    work.par_iter()
        .map(|(x, es)| node_distance(geometry, *x, es, size))
        .reduce(GeometryDistance::default, GeometryDistance::merge)
}
