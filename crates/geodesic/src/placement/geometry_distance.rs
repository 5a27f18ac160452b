//! Distance of nodes from the entities they lie on: measured, and removed by projecting the
//! nodes onto their entities.

use std::collections::BTreeMap;

use hocurve_nurbs::GeometryModel;
use rayon::prelude::*;

use crate::GeodesicError;

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
/// in [`BoundaryTargets::entities`](super::BoundaryTargets::entities)) onto its entities: the closest point for one entity,
/// alternating projections for a node on several (a feature curve or corner). Used for the
/// nodes that are written, when they are interpolated from another node family: the
/// interpolant of on-surface nodes leaves the surface between them (by 1e-3 of the size on
/// a coarse sphere at p = 3). Returns the largest distance then left, measured afresh.
pub fn project_nodes_onto_geometry(
    geometry: &GeometryModel,
    entities: &BTreeMap<u32, Vec<usize>>,
    nodes: &mut [[f64; 3]],
) -> Result<f64, GeodesicError> {
    let work: Vec<(u32, &Vec<usize>)> = entities.iter().map(|(&n, e)| (n, e)).collect();
    if let Some((&n, _)) = entities.iter().find(|(&n, _)| n as usize >= nodes.len()) {
        return Err(GeodesicError::Mismatch(format!(
            "node {n} of the boundary is not among the {} nodes",
            nodes.len()
        )));
    }
    let moved: Vec<([f64; 3], f64)> = work
        .par_iter()
        .map(|&(n, es)| {
            let y = crate::association::snap_onto(geometry, es, nodes[n as usize]);
            (y, distance_to_all(geometry, y, es))
        })
        .collect();
    let mut largest: f64 = 0.0;
    for ((n, _), (y, d)) in work.iter().zip(moved) {
        nodes[*n as usize] = y;
        largest = largest.max(d);
    }
    Ok(largest)
}

/// The largest distance of the nodes listed in `entities` from their entities.
pub fn max_distance_from_geometry(
    geometry: &GeometryModel,
    entities: &BTreeMap<u32, Vec<usize>>,
    nodes: &[[f64; 3]],
) -> f64 {
    let work: Vec<([f64; 3], &Vec<usize>)> = entities
        .iter()
        .filter_map(|(&n, e)| nodes.get(n as usize).map(|x| (*x, e)))
        .collect();
    work.par_iter()
        .map(|(x, es)| distance_to_all(geometry, *x, es))
        .reduce(|| 0.0, f64::max)
}
