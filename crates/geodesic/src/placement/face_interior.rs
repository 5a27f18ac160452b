//! Face-interior nodes of one facet: the geodesic constructions of Eq. (6) (triangles) and
//! Eq. (7) (quadrilaterals), projected onto the surface.

use std::collections::BTreeMap;

use hocurve_nodes::{NodeEntity, ReferenceNodes, Shape};
use hocurve_nurbs::inversion::closest_point_on_curve;
use hocurve_nurbs::vec3::{add, distance, scale, sub};
use hocurve_nurbs::EntityGeometry;

use crate::chart::GeometryCharts;
use crate::closed_form::ClosedFormGeodesic;
use crate::path::{GeodesicPath, DEFAULT_LENGTH_TOLERANCE};
use crate::GeodesicError;

use super::edge_carriers::EdgeCarrier;

/// Places the interior nodes of one facet on entity `entity` (its edge nodes are placed once
/// per edge, by [`place_boundary_nodes_with`]).
pub(super) fn place_facet(
    geometry: &GeometryCharts,
    carriers: &BTreeMap<[u32; 2], EdgeCarrier>,
    nodes: &[u32],
    shape: Shape,
    reference: &ReferenceNodes,
    entity: usize,
) -> Result<Vec<(u32, [f64; 3])>, GeodesicError> {
    // The point at `fraction` of the way from local vertex i to local vertex j.
    let along = |i: usize, j: usize, fraction: f64| -> Result<EdgePoint, GeodesicError> {
        let (a, b) = (nodes[i], nodes[j]);
        let key = [a.min(b), a.max(b)];
        let carrier = carriers
            .get(&key)
            .ok_or_else(|| GeodesicError::Mismatch(format!("no carrier for edge {key:?}")))?;
        let f = if a < b { fraction } else { 1.0 - fraction };
        Ok(carrier.at(f))
    };
    // Eqs. (6), (7) reproduce an edge only where it is the geodesic between its vertices
    // on this facet's surface. Other edges — feature curves where two surfaces meet, edges
    // rebuilt by the minimum-angle correction — the constructions miss by `share` of their
    // distance from that geodesic (1/3 for a triangle: one of its three geodesics runs
    // between the edge's vertices; 1/2 for a quadrilateral): that miss, d(s), is added
    // back, blended to vanish on the other edges (see `edge_blend`), so that the face
    // meets its edges exactly (a plate's face bounded by a hole's rim otherwise lags the
    // rim's bulge by a third, and folds once the nodes are closer than that).
    let share = if shape == Shape::Quad { 0.5 } else { 1.0 / 3.0 };
    let geodesic_edge = |i: usize, j: usize| {
        let (a, b) = (nodes[i], nodes[j]);
        matches!(
            carriers.get(&[a.min(b), a.max(b)]),
            Some(EdgeCarrier::Surface { .. })
        )
    };
    let miss = |i: usize, j: usize, fraction: f64| -> Result<[f64; 3], GeodesicError> {
        let on_edge = along(i, j, fraction)?;
        let geodesic = geodesic_point(
            geometry,
            entity,
            along(i, j, 0.0)?,
            along(i, j, 1.0)?,
            fraction,
        );
        Ok(scale(sub(on_edge.1, geodesic.1), share))
    };
    let corner_count = if shape == Shape::Quad { 4 } else { 3 };
    let corrected: Vec<(usize, usize)> = (0..corner_count)
        .map(|i| (i, (i + 1) % corner_count))
        .filter(|&(i, j)| !geodesic_edge(i, j))
        .collect();
    let mut out = Vec::new();
    if shape == Shape::Line {
        return Ok(out);
    }
    for ((&n, xi), ent) in nodes
        .iter()
        .zip(reference.points())
        .zip(reference.entities())
    {
        match *ent {
            NodeEntity::Vertex(_) | NodeEntity::Edge { .. } => {}
            NodeEntity::Interior(_) | NodeEntity::Face { .. } => {
                let x = match shape {
                    Shape::Tri => triangle_node(geometry, entity, &along, &miss, &corrected, *xi)?,
                    Shape::Quad => {
                        quadrilateral_node(geometry, entity, &along, &miss, &corrected, *xi)?
                    }
                    other => {
                        return Err(GeodesicError::Mismatch(format!(
                            "a boundary facet cannot be a {}",
                            other.name()
                        )))
                    }
                };
                out.push((n, x));
            }
        }
    }
    Ok(out)
}

/// A point on the boundary with its surface parameter where one is known (edge carriers on
/// a single surface know it; curves and feature edges do not).
pub(super) type EdgePoint = (Option<[f64; 2]>, [f64; 3]);

/// Points at fractions along two boundary points' geodesic on `entity`.
pub(super) fn geodesic_point(
    geometry: &GeometryCharts,
    entity: usize,
    from: EdgePoint,
    to: EdgePoint,
    fraction: f64,
) -> EdgePoint {
    let entity_geometry = &geometry.geometry.entities[entity];
    if let Some(exact) = entity_geometry
        .analytic
        .as_ref()
        .and_then(ClosedFormGeodesic::of)
    {
        // Parameters are guesses here: closed-form surfaces project without them.
        return (from.0, exact.at_fraction(from.1, to.1, fraction));
    }
    match (&entity_geometry.geometry, geometry.chart(entity)) {
        (EntityGeometry::Surface(_), Some(chart)) => {
            // Parameters of edge points may come from another entity's chart on feature
            // edges; re-invert them where they do not reproduce the point: by Newton from the
            // other end's parameter when that one is valid (the ends are a mesh edge apart),
            // globally otherwise (a search over the whole surface, far costlier on a large
            // B-spline face).
            let tolerance = 1e-9 * chart.size();
            // A parameter outside the chart's range is not this chart's (a projection's
            // clamped guess from another patch can be).
            let inside = |uv: [f64; 2]| {
                (0..2).all(|d| {
                    chart
                        .bounded_range(d)
                        .is_none_or(|(a, b)| (a..=b).contains(&uv[d]))
                })
            };
            let valid = |(uv, x): EdgePoint| {
                uv.is_some_and(|uv| inside(uv) && distance(chart.point(uv), x) <= tolerance)
            };
            let invert = |x: [f64; 3], near: Option<[f64; 2]>| {
                near.map(|g| chart.project_near(x, g))
                    .filter(|(_, y)| distance(*y, x) <= tolerance)
                    .map_or_else(|| entity_geometry.closest_point(x).param, |(uv, _)| uv)
            };
            let (from_ok, to_ok) = (valid(from), valid(to));
            let a = match from.0 {
                Some(uv) if from_ok => uv,
                _ => invert(from.1, to.0.filter(|_| to_ok)),
            };
            let b = match to.0 {
                Some(uv) if to_ok => uv,
                _ => invert(to.1, Some(a)),
            };
            let path = GeodesicPath::between(chart, a, b, DEFAULT_LENGTH_TOLERANCE);
            let (uv, x) = path.at_fraction(chart, fraction);
            (Some(uv), x)
        }
        _ => {
            let x = add(from.1, scale(sub(to.1, from.1), fraction));
            (None, x)
        }
    }
}

type Along<'a> = dyn Fn(usize, usize, f64) -> Result<EdgePoint, GeodesicError> + 'a;
/// `miss(i, j, s)`: what the construction misses of the edge from local vertex i to j at
/// fraction s (zero at both vertices).
type Miss<'a> = dyn Fn(usize, usize, f64) -> Result<[f64; 3], GeodesicError> + 'a;

/// The paper's Eq. (6): a triangle's interior node from three geodesics of constant
/// barycentric coordinate, averaged — plus the blended misses of the `corrected` edges —
/// and projected onto the surface.
fn triangle_node(
    geometry: &GeometryCharts,
    entity: usize,
    along: &Along,
    miss: &Miss,
    corrected: &[(usize, usize)],
    xi: [f64; 3],
) -> Result<[f64; 3], GeodesicError> {
    let (alpha, beta, gamma) = (1.0 - xi[0] - xi[1], xi[0], xi[1]);
    // Line α = const from edge 1–2 to edge 1–3, divided as γ : β.
    let xa = geodesic_point(
        geometry,
        entity,
        along(0, 1, 1.0 - alpha)?,
        along(0, 2, 1.0 - alpha)?,
        gamma / (beta + gamma),
    );
    let xb = geodesic_point(
        geometry,
        entity,
        along(1, 0, 1.0 - beta)?,
        along(1, 2, 1.0 - beta)?,
        gamma / (gamma + alpha),
    );
    let xc = geodesic_point(
        geometry,
        entity,
        along(2, 0, 1.0 - gamma)?,
        along(2, 1, 1.0 - gamma)?,
        beta / (beta + alpha),
    );
    let mut x = scale(add(add(xa.1, xb.1), xc.1), 1.0 / 3.0);
    let lambda = [alpha, beta, gamma];
    for &(i, j) in corrected {
        if let Some((weight, fraction)) = edge_blend(lambda[i], lambda[j]) {
            x = add(x, scale(miss(i, j, fraction)?, weight));
        }
    }
    Ok(project(geometry, entity, x, xa.0))
}

/// The blend of an edge's miss d(s) into a triangle (edge from vertex a to b, barycentric
/// coordinates λ_a, λ_b): (λ_a + λ_b) d(λ_b / (λ_a + λ_b)) — d itself on the edge, zero on
/// the other two (where λ_a or λ_b vanishes, as d does at the vertices). `None` at the
/// opposite vertex.
fn edge_blend(lambda_a: f64, lambda_b: f64) -> Option<(f64, f64)> {
    let weight = lambda_a + lambda_b;
    (weight > 0.0).then(|| (weight, lambda_b / weight))
}

/// The paper's Eq. (7): a quadrilateral's interior node from the two geodesics of constant
/// ξ and η, averaged — plus the blended misses of the `corrected` edges, each scaled by the
/// distance from its opposite edge — and projected onto the surface.
fn quadrilateral_node(
    geometry: &GeometryCharts,
    entity: usize,
    along: &Along,
    miss: &Miss,
    corrected: &[(usize, usize)],
    xi: [f64; 3],
) -> Result<[f64; 3], GeodesicError> {
    let (s, t) = (xi[0], xi[1]);
    // Vertices 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1).
    let x_s = geodesic_point(geometry, entity, along(0, 1, s)?, along(3, 2, s)?, t);
    let x_t = geodesic_point(geometry, entity, along(0, 3, t)?, along(1, 2, t)?, s);
    let mut x = scale(add(x_s.1, x_t.1), 0.5);
    for &(i, j) in corrected {
        // Edge i → i + 1 (mod 4): its fraction at this node, and the node's distance from
        // the opposite edge in the reference square.
        let (weight, fraction) = match (i, j) {
            (0, 1) => (1.0 - t, s),
            (1, 2) => (s, t),
            (2, 3) => (t, 1.0 - s),
            _ => (1.0 - s, 1.0 - t),
        };
        x = add(x, scale(miss(i, j, fraction)?, weight));
    }
    Ok(project(geometry, entity, x, x_s.0))
}

/// Closest point of `entity` to `x` (Π_S in Eqs. (6), (7)), by Newton from `guess` on a
/// surface (globally without one), in closed form where the entity has one.
pub(super) fn project(
    geometry: &GeometryCharts,
    entity: usize,
    x: [f64; 3],
    guess: Option<[f64; 2]>,
) -> [f64; 3] {
    let e = &geometry.geometry.entities[entity];
    if let Some(shape) = &e.analytic {
        return shape.closest_point(x).point;
    }
    match (&e.geometry, geometry.chart(entity)) {
        (EntityGeometry::Curve(c), _) => closest_point_on_curve(c, x).point,
        (EntityGeometry::Surface(_), Some(chart)) => match guess {
            Some(guess) => chart.project_near(x, guess).1,
            None => e.closest_point(x).point,
        },
        (EntityGeometry::Surface(_), None) => e.closest_point(x).point,
    }
}
