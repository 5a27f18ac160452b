//! The carrier of each mesh edge (boundary curve, geodesic, feature curve or corrected
//! curve) and the points at fractions of its length.

use std::collections::{BTreeSet, HashMap};

use hocurve_nurbs::inversion::closest_point_on_curve;
use hocurve_nurbs::{EntityGeometry, GeometryModel};
use rayon::prelude::*;

use crate::chart::{GeometryCharts, SurfaceChart};
use crate::closed_form::ClosedFormGeodesic;
use crate::correction::CorrectedEdge;
use crate::curve_arc::CurveArc;
use crate::feature::{FeatureCurve, FeatureTraces};
use crate::frame::end_tangent;
use crate::path::{GeodesicPath, DEFAULT_LENGTH_TOLERANCE};
use crate::{BoundaryAssociation, GeodesicError};

/// How the interior nodes of one mesh edge are placed: by the fraction of the length from the
/// edge's first vertex.
pub(crate) enum EdgeCarrier<'a> {
    /// A boundary curve (2D) between two parameters, possibly across the seam of a closed curve.
    Curve(CurveArc<'a>),
    /// An approximate geodesic on a surface (an edge inside one surface patch); where the
    /// surface's geodesics have a closed form, its points come from that (`exact`, with the
    /// edge's end points) and the path serves the minimum-angle check only.
    Surface {
        entity: usize,
        chart: SurfaceChart<'a>,
        path: GeodesicPath,
        exact: Option<(ClosedFormGeodesic, [[f64; 3]; 2])>,
    },
    /// The intersection of two or more surfaces (a feature edge, on a patch boundary).
    Feature(FeatureCurve<'a>),
    /// A surface edge replaced by the minimum-angle correction.
    Corrected(CorrectedEdge<'a>),
}

/// Surface parameters of snapped vertices, by (vertex, entity): see [`vertex_parameters`].
pub(crate) type VertexParameters = HashMap<(u32, usize), [f64; 2]>;

/// The surface parameter of every vertex of `edges` (vertex pairs, each with its entities)
/// that lies on one surface, by point inversion on that surface's NURBS: once per vertex
/// rather than once per edge end (a vertex ends ~6 edges, and an inversion on a patch
/// starts with a grid search: 12 of the 35 ms of the 6 k sphere's boundary nodes at p = 4).
pub(crate) fn vertex_parameters(
    geometry: &GeometryModel,
    association: &BoundaryAssociation,
    edges: &[([u32; 2], Vec<usize>)],
) -> VertexParameters {
    let on_surface: BTreeSet<(u32, usize)> = edges
        .iter()
        .filter_map(|(vertices, entities)| match entities.as_slice() {
            [e] if matches!(
                geometry.entities.get(*e).map(|x| &x.geometry),
                Some(EntityGeometry::Surface(_))
            ) =>
            {
                Some(vertices.map(|v| (v, *e)))
            }
            _ => None,
        })
        .flatten()
        .collect();
    let work: Vec<(u32, usize)> = on_surface.into_iter().collect();
    work.par_iter()
        .filter_map(|&(v, e)| {
            let x = association.vertex_targets.get(&v)?;
            Some(((v, e), geometry.entities[e].closest_point(*x).param))
        })
        .collect()
}

/// The carrier of the mesh edge from vertex `a` to vertex `b` lying on `entities`: the
/// boundary curve (2D), the geodesic on the one surface, or the intersection curve of
/// several surfaces (traced to the relative length tolerance `feature_tolerance`, or taken
/// from `traces`). Vertex parameters on a surface come from `params` where it has them.
pub(crate) fn edge_carrier<'a>(
    charts: &GeometryCharts<'a>,
    association: &BoundaryAssociation,
    params: &VertexParameters,
    [a, b]: [u32; 2],
    entities: &[usize],
    feature_tolerance: f64,
    traces: &FeatureTraces<'a>,
) -> Result<EdgeCarrier<'a>, GeodesicError> {
    let vertex = |v: u32| {
        association.vertex_targets.get(&v).copied().ok_or_else(|| {
            GeodesicError::Mismatch(format!("vertex {v} of a curved facet was not snapped"))
        })
    };
    let (xa, xb) = (vertex(a)?, vertex(b)?);
    let first = *entities
        .first()
        .ok_or_else(|| GeodesicError::Mismatch(format!("edge {a}–{b} lies on no entity")))?;
    let geometry = charts.geometry;
    // Faces written once each with one surface (the faces of a hub's cone, each patch over
    // its own extent) meet nowhere in particular: an edge between them lies on that one
    // surface, on the face whose patch holds both its vertices best.
    let twins = one_surface(geometry, entities);
    let first = match twins {
        Some(group) => group
            .iter()
            .map(|&e| {
                let entity = &geometry.entities[e];
                let d = entity.patch_distance(xa).max(entity.patch_distance(xb));
                (d, e)
            })
            .min_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)))
            .map_or(first, |(_, e)| e),
        None => first,
    };
    let entity = geometry.entities.get(first).ok_or_else(|| {
        GeodesicError::Mismatch(format!("entity index {first} is not in the geometry"))
    })?;
    match &entity.geometry {
        EntityGeometry::Curve(curve) => {
            let (la, lb) = (
                closest_point_on_curve(curve, xa).param,
                closest_point_on_curve(curve, xb).param,
            );
            Ok(EdgeCarrier::Curve(CurveArc::new(curve, la, lb)))
        }
        EntityGeometry::Surface(_) if entities.len() > 1 && twins.is_none() => Ok(
            EdgeCarrier::Feature(traces.between(geometry, entities, xa, xb, feature_tolerance)),
        ),
        EntityGeometry::Surface(surface) => {
            let chart = charts
                .chart(first)
                .cloned()
                .unwrap_or_else(|| SurfaceChart::new(surface));
            let param = |v: u32, x: [f64; 3]| {
                params
                    .get(&(v, first))
                    .copied()
                    .unwrap_or_else(|| entity.closest_point(x).param)
            };
            let (pa, pb) = (param(a, xa), param(b, xb));
            let path = GeodesicPath::between(&chart, pa, pb, DEFAULT_LENGTH_TOLERANCE);
            let exact = entity
                .analytic
                .as_ref()
                .and_then(ClosedFormGeodesic::of)
                .map(|g| (g, [xa, xb]));
            Ok(EdgeCarrier::Surface {
                entity: first,
                chart,
                path,
                exact,
            })
        }
    }
}

/// `entities` (two or more) when they are all one surface ([`GeometryModel::same_surface`]).
fn one_surface<'e>(geometry: &GeometryModel, entities: &'e [usize]) -> Option<&'e [usize]> {
    let (&first, rest) = entities.split_first()?;
    let group = geometry.same_surface(first);
    (!rest.is_empty() && rest.iter().all(|e| group.binary_search(e).is_ok())).then_some(entities)
}

impl EdgeCarrier<'_> {
    /// The point at `fraction` of the edge's length from its first vertex, with its surface
    /// parameter where the carrier is one surface (`None` otherwise: users invert).
    pub(crate) fn at(&self, fraction: f64) -> (Option<[f64; 2]>, [f64; 3]) {
        match self {
            EdgeCarrier::Curve(arc) => (None, arc.at(fraction)),
            EdgeCarrier::Surface {
                exact: Some((geodesic, [a, b])),
                path,
                ..
            } => (
                Some(path.parameter_near(fraction)),
                geodesic.at_fraction(*a, *b, fraction),
            ),
            EdgeCarrier::Surface { chart, path, .. } => {
                let (uv, x) = path.at_fraction(chart, fraction);
                (Some(uv), x)
            }
            EdgeCarrier::Feature(curve) => (None, curve.at(fraction)),
            EdgeCarrier::Corrected(edge) => {
                let (uv, x) = edge.at(fraction);
                (Some(uv), x)
            }
        }
    }

    /// Unit tangent of the uncorrected carrier at its first vertex (`at_end = false`) or its
    /// last, pointing into the edge; `None` for 2D curves and corrected edges.
    pub(crate) fn end_tangent(&self, at_end: bool) -> Option<[f64; 3]> {
        match self {
            EdgeCarrier::Surface { path, .. } => path.end_tangent(at_end),
            EdgeCarrier::Feature(curve) => curve.end_tangent(at_end),
            EdgeCarrier::Curve(_) | EdgeCarrier::Corrected(_) => None,
        }
    }
}

impl GeodesicPath {
    /// Unit tangent at the start (`at_end = false`) or the end, pointing into the path.
    pub(crate) fn end_tangent(&self, at_end: bool) -> Option<[f64; 3]> {
        end_tangent(&self.points, at_end)
    }

    /// The same path run backwards.
    pub(crate) fn reversed(&self) -> Self {
        let total = self.length();
        Self {
            params: self.params.iter().rev().copied().collect(),
            points: self.points.iter().rev().copied().collect(),
            lengths: self.lengths.iter().rev().map(|l| total - l).collect(),
        }
    }
}
