//! The minimum-angle check of one surface edge (Fig. 4), from its carrier and the carriers
//! of its neighbouring edges, for the small-angle correction.

use std::collections::BTreeMap;

use crate::correction::{check_edge, EdgeEnd, Neighbour};
use crate::{BoundaryAssociation, GeodesicError};

use super::edge_carriers::EdgeCarrier;

/// The minimum-angle check of the surface edge `[from, to]` (see [`crate::correction`]):
/// `None` for edges that are not inside one surface or where a tangent plane is missing.
/// The edge's own carrier is rebuilt in the given orientation only if it is not stored in it.
pub(crate) fn check_edge_angles(
    association: &BoundaryAssociation,
    carriers: &BTreeMap<[u32; 2], EdgeCarrier>,
    edge_neighbours: &BTreeMap<[u32; 2], Vec<(u32, u32)>>,
    [from, to]: [u32; 2],
    order: usize,
    limit: f64,
) -> Result<Option<crate::correction::AngleCheck>, GeodesicError> {
    let key = [from.min(to), from.max(to)];
    let Some(EdgeCarrier::Surface { chart, path, .. }) = carriers.get(&key) else {
        return Ok(None);
    };
    let reversed;
    let path = if from < to {
        path
    } else {
        reversed = path.reversed();
        &reversed
    };
    let vertex = |v: u32| {
        association.vertex_targets.get(&v).copied().ok_or_else(|| {
            GeodesicError::Mismatch(format!("vertex {v} of a curved facet was not snapped"))
        })
    };
    let neighbours = edge_neighbours.get(&key).map(Vec::as_slice).unwrap_or(&[]);
    let mut ends = Vec::with_capacity(2);
    for (v, at_end) in [(from, false), (to, true)] {
        let Some(tangent) = path.end_tangent(at_end) else {
            return Ok(None);
        };
        let mut list = Vec::new();
        for &(_, w) in neighbours.iter().filter(|(u, _)| *u == v) {
            let nkey = [v.min(w), v.max(w)];
            let Some(carrier) = carriers.get(&nkey) else {
                continue;
            };
            let Some(tangent) = carrier.end_tangent(v != nkey[0]) else {
                continue;
            };
            list.push(Neighbour {
                tangent,
                far_vertex: vertex(w)?,
                // At p = 2 a neighbour turns at one end only, maybe not this one.
                correctable: matches!(carrier, EdgeCarrier::Surface { .. }) && order >= 3,
            });
        }
        let n = path.params.len();
        ends.push(EdgeEnd {
            vertex: v,
            point: vertex(v)?,
            param: if at_end {
                path.params[n - 1]
            } else {
                path.params[0]
            },
            tangent,
            neighbours: list,
        });
    }
    let ends: [EdgeEnd; 2] = ends
        .try_into()
        .map_err(|_| GeodesicError::Mismatch("an edge has two ends".into()))?;
    Ok(check_edge(chart, &ends, path.length(), order, limit))
}
