//! Target positions of every high-order node on a curved boundary (the paper's Sect. 3.1,
//! 4.1, 4.2): vertices snapped onto the geometry, edge nodes by arc length along the boundary
//! curve (2D, Eq. (4)) or along the approximate geodesic (3D, Eq. (5)), and face-interior nodes
//! by the geodesic constructions of Eq. (6) (triangles) and Eq. (7) (quadrilaterals) — or, as
//! the baseline the paper improves on, by closest-point projection of the straight nodes.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::{NodeEntity, ReferenceNodes, Shape};
use hocurve_nurbs::arc_length::{arc_length, parameter_at_length_fraction};
use hocurve_nurbs::inversion::{closest_point_on_curve, closest_point_on_surface};
use hocurve_nurbs::{EntityGeometry, GeometryModel, NurbsCurve};
use rayon::prelude::*;

use crate::association::{snap_onto, snap_onto_with};
use crate::chart::SurfaceChart;
use crate::path::{distance, GeodesicPath, DEFAULT_LENGTH_TOLERANCE};
use crate::{BoundaryAssociation, GeodesicError};

/// How boundary nodes are placed on the geometry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BoundaryNodeStrategy {
    /// The paper's method: arc length along curves and geodesics, Eqs. (4)–(7).
    #[default]
    Geodesic,
    /// Closest-point projection of the straight-sided nodes (the baseline).
    Projection,
}

impl std::str::FromStr for BoundaryNodeStrategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "geodesic" => Ok(Self::Geodesic),
            "projection" => Ok(Self::Projection),
            _ => Err(format!(
                "unknown boundary-node strategy \"{s}\" (expected geodesic or projection)"
            )),
        }
    }
}

/// Where the nodes of the curved boundary go.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BoundaryTargets {
    /// Target position of every node on a curved facet, by global node id.
    pub targets: BTreeMap<u32, [f64; 3]>,
    /// The geometry entities each target lies on.
    pub entities: BTreeMap<u32, Vec<usize>>,
    /// Facets placed on the geometry.
    pub curved_facets: usize,
    /// Largest distance of a target from its entities (should be round-off).
    pub max_geometry_distance: f64,
}

/// How the interior nodes of one mesh edge are placed: by the fraction of the length from the
/// edge's lower-numbered vertex.
enum EdgeCarrier<'a> {
    /// A boundary curve (2D) between two parameters, possibly across the seam of a closed curve.
    Curve(CurveArc<'a>),
    /// An approximate geodesic on a surface; `also_on` lists further surfaces (a feature
    /// edge between two entities), onto which the points are then snapped.
    Surface {
        chart: SurfaceChart<'a>,
        path: GeodesicPath,
        also_on: Vec<usize>,
    },
}

/// A piece of a NURBS curve from `from` to `to`, the short way round if the curve is closed.
struct CurveArc<'a> {
    curve: &'a NurbsCurve,
    from: f64,
    to: f64,
    /// Crosses the seam of a closed curve.
    wraps: bool,
    length: f64,
}

impl<'a> CurveArc<'a> {
    fn new(curve: &'a NurbsCurve, from: f64, to: f64) -> Self {
        let direct = arc_length(curve, from, to);
        if curve.is_closed() {
            let (s0, s1) = curve.domain();
            let total = arc_length(curve, s0, s1);
            if total - direct < direct {
                return Self {
                    curve,
                    from,
                    to,
                    wraps: true,
                    length: total - direct,
                };
            }
        }
        Self {
            curve,
            from,
            to,
            wraps: false,
            length: direct,
        }
    }

    /// The point at `fraction` of the arc length from `from` (the paper's Eq. (4)).
    fn at(&self, fraction: f64) -> [f64; 3] {
        let c = self.curve;
        if !self.wraps {
            return c.point(parameter_at_length_fraction(
                c, self.from, self.to, fraction,
            ));
        }
        let (s0, s1) = c.domain();
        // Through the end of the domain (forwards) or through its start (backwards).
        let (seam_out, seam_in) = if self.from > self.to {
            (s1, s0)
        } else {
            (s0, s1)
        };
        let first = arc_length(c, self.from, seam_out);
        let target = fraction * self.length;
        if target <= first && first > 0.0 {
            c.point(parameter_at_length_fraction(
                c,
                self.from,
                seam_out,
                target / first,
            ))
        } else {
            let rest = (self.length - first).max(f64::MIN_POSITIVE);
            c.point(parameter_at_length_fraction(
                c,
                seam_in,
                self.to,
                (target - first) / rest,
            ))
        }
    }
}

/// Target positions of the nodes of every associated facet of `mesh` (a straight-sided
/// high-order mesh built from the linear mesh that `association` was made for).
pub fn place_boundary_nodes(
    mesh: &HighOrderMesh,
    geometry: &GeometryModel,
    association: &BoundaryAssociation,
    strategy: BoundaryNodeStrategy,
) -> Result<BoundaryTargets, GeodesicError> {
    if association.facet_entity.len() != mesh.facets.len() {
        return Err(GeodesicError::Mismatch(format!(
            "the association covers {} facets but the mesh has {}",
            association.facet_entity.len(),
            mesh.facets.len()
        )));
    }
    let order = mesh.order;
    let mut out = BoundaryTargets::default();
    let curved: Vec<(usize, usize)> = association
        .facet_entity
        .iter()
        .enumerate()
        .filter_map(|(k, e)| e.map(|e| (k, e)))
        .collect();
    out.curved_facets = curved.len();
    if curved.is_empty() {
        return Ok(out);
    }
    let entity_list = |ids: &BTreeSet<usize>| ids.iter().copied().collect::<Vec<_>>();

    // Vertices: snapped by the association.
    for (&v, &x) in &association.vertex_targets {
        out.targets.insert(v, x);
        if let Some(e) = association.vertex_entities.get(&v) {
            out.entities.insert(v, e.clone());
        }
    }

    // Every node of a curved facet lies on the facet's entity; nodes of edges between facets
    // of different entities lie on all of them.
    let mut node_entities: BTreeMap<u32, BTreeSet<usize>> = BTreeMap::new();
    let mut edge_entities: BTreeMap<[u32; 2], BTreeSet<usize>> = BTreeMap::new();
    for &(k, e) in &curved {
        let facet = &mesh.facets[k];
        for &n in &facet.nodes {
            node_entities.entry(n).or_default().insert(e);
        }
        let shape = facet
            .kind
            .shape()
            .map_err(|err| GeodesicError::Mismatch(err.to_string()))?;
        for [i, j] in facet_edges(shape) {
            let (a, b) = (facet.nodes[i], facet.nodes[j]);
            edge_entities
                .entry([a.min(b), a.max(b)])
                .or_default()
                .insert(e);
        }
    }
    if order == 1 {
        out.max_geometry_distance = max_distance(geometry, &out.targets, &out.entities);
        return Ok(out);
    }

    if strategy == BoundaryNodeStrategy::Projection {
        let work: Vec<(u32, Vec<usize>)> = node_entities
            .iter()
            .filter(|(n, _)| !association.vertex_targets.contains_key(n))
            .map(|(n, e)| (*n, entity_list(e)))
            .collect();
        let placed: Vec<(u32, [f64; 3], Vec<usize>)> = work
            .into_par_iter()
            .map(|(n, e)| {
                let x = snap_onto(geometry, &e, mesh.nodes[n as usize]);
                (n, x, e)
            })
            .collect();
        for (n, x, e) in placed {
            out.targets.insert(n, x);
            out.entities.insert(n, e);
        }
        out.max_geometry_distance = max_distance(geometry, &out.targets, &out.entities);
        return Ok(out);
    }

    // Edge carriers, one per mesh edge, from its lower vertex to its higher.
    let edges: Vec<([u32; 2], Vec<usize>)> = edge_entities
        .iter()
        .map(|(k, e)| (*k, entity_list(e)))
        .collect();
    let carriers: Vec<Result<EdgeCarrier, GeodesicError>> = edges
        .par_iter()
        .map(|(vertices, entities)| edge_carrier(geometry, association, *vertices, entities))
        .collect();
    let mut carrier_of: BTreeMap<[u32; 2], EdgeCarrier> = BTreeMap::new();
    for ((vertices, _), c) in edges.iter().zip(carriers) {
        carrier_of.insert(*vertices, c?);
    }

    // Edge nodes and face-interior nodes, facet by facet (edge nodes shared by two facets are
    // computed from the same carrier and fraction, so they agree bit for bit).
    let reference: BTreeMap<Shape, ReferenceNodes> = curved
        .iter()
        .filter_map(|&(k, _)| mesh.facets[k].kind.shape().ok())
        .collect::<BTreeSet<_>>()
        .into_iter()
        .map(|s| ReferenceNodes::try_new(s, order, mesh.family).map(|r| (s, r)))
        .collect::<Result<_, _>>()
        .map_err(|e| GeodesicError::Mismatch(e.to_string()))?;
    let placed: Vec<Vec<(u32, [f64; 3])>> = curved
        .par_iter()
        .map(|&(k, e)| {
            let facet = &mesh.facets[k];
            let shape = facet
                .kind
                .shape()
                .map_err(|err| GeodesicError::Mismatch(err.to_string()))?;
            let refn = &reference[&shape];
            place_facet(
                geometry,
                &carrier_of,
                facet.nodes.as_slice(),
                shape,
                refn,
                e,
            )
        })
        .collect::<Result<_, _>>()?;
    for list in placed {
        for (n, x) in list {
            out.targets.entry(n).or_insert(x);
        }
    }
    for (n, e) in node_entities {
        out.entities.entry(n).or_insert_with(|| entity_list(&e));
    }
    out.max_geometry_distance = max_distance(geometry, &out.targets, &out.entities);
    Ok(out)
}

/// The local vertex pairs of a facet's edges.
fn facet_edges(shape: Shape) -> Vec<[usize; 2]> {
    match shape {
        Shape::Line => vec![[0, 1]],
        s => s.edges().to_vec(),
    }
}

/// The carrier of the mesh edge `[a, b]` (a < b) lying on `entities`.
fn edge_carrier<'a>(
    geometry: &'a GeometryModel,
    association: &BoundaryAssociation,
    [a, b]: [u32; 2],
    entities: &[usize],
) -> Result<EdgeCarrier<'a>, GeodesicError> {
    let vertex = |v: u32| {
        association.vertex_targets.get(&v).copied().ok_or_else(|| {
            GeodesicError::Mismatch(format!("vertex {v} of a curved facet was not snapped"))
        })
    };
    let (xa, xb) = (vertex(a)?, vertex(b)?);
    let first = entities[0];
    match &geometry.entities[first].geometry {
        EntityGeometry::Curve(curve) => {
            let (la, lb) = (
                closest_point_on_curve(curve, xa).param,
                closest_point_on_curve(curve, xb).param,
            );
            Ok(EdgeCarrier::Curve(CurveArc::new(curve, la, lb)))
        }
        EntityGeometry::Surface(surface) => {
            let chart = SurfaceChart::new(surface);
            let (pa, pb) = (
                closest_point_on_surface(surface, xa).param,
                closest_point_on_surface(surface, xb).param,
            );
            let path = GeodesicPath::between(&chart, pa, pb, DEFAULT_LENGTH_TOLERANCE);
            Ok(EdgeCarrier::Surface {
                chart,
                path,
                also_on: entities[1..].to_vec(),
            })
        }
    }
}

impl EdgeCarrier<'_> {
    /// The point at `fraction` of the edge's length from its lower vertex, with its surface
    /// parameter where the carrier is a surface.
    fn at(&self, geometry: &GeometryModel, fraction: f64) -> ([f64; 2], [f64; 3]) {
        match self {
            EdgeCarrier::Curve(arc) => ([0.0; 2], arc.at(fraction)),
            EdgeCarrier::Surface {
                chart,
                path,
                also_on,
            } => {
                let (uv, x) = path.at_fraction(chart, fraction);
                if also_on.is_empty() {
                    (uv, x)
                } else {
                    (
                        uv,
                        snap_onto_with(geometry, also_on, x, |y| chart.project_near(y, uv).1),
                    )
                }
            }
        }
    }
}

/// Places the edge and interior nodes of one facet on entity `entity`.
fn place_facet(
    geometry: &GeometryModel,
    carriers: &BTreeMap<[u32; 2], EdgeCarrier>,
    nodes: &[u32],
    shape: Shape,
    reference: &ReferenceNodes,
    entity: usize,
) -> Result<Vec<(u32, [f64; 3])>, GeodesicError> {
    let vertices = shape.vertices();
    // The point at `fraction` of the way from local vertex i to local vertex j.
    let along =
        |i: usize, j: usize, fraction: f64| -> Result<([f64; 2], [f64; 3]), GeodesicError> {
            let (a, b) = (nodes[i], nodes[j]);
            let key = [a.min(b), a.max(b)];
            let carrier = carriers
                .get(&key)
                .ok_or_else(|| GeodesicError::Mismatch(format!("no carrier for edge {key:?}")))?;
            let f = if a < b { fraction } else { 1.0 - fraction };
            Ok(carrier.at(geometry, f))
        };
    let mut out = Vec::new();
    for ((&n, xi), ent) in nodes
        .iter()
        .zip(reference.points())
        .zip(reference.entities())
    {
        match *ent {
            NodeEntity::Vertex(_) => {}
            NodeEntity::Edge { edge, .. } => {
                let [i, j] = facet_edges(shape)[edge];
                out.push((
                    n,
                    along(i, j, reference_fraction(vertices[i], vertices[j], *xi))?.1,
                ));
            }
            NodeEntity::Interior(_) if shape == Shape::Line => {
                out.push((n, along(0, 1, xi[0])?.1));
            }
            NodeEntity::Interior(_) | NodeEntity::Face { .. } => {
                let x = match shape {
                    Shape::Tri => triangle_node(geometry, entity, &along, *xi)?,
                    Shape::Quad => quadrilateral_node(geometry, entity, &along, *xi)?,
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

/// Fraction of the way from reference vertex `a` to `b` of the reference point `xi` on that edge.
fn reference_fraction(a: [f64; 3], b: [f64; 3], xi: [f64; 3]) -> f64 {
    let l = distance(a, b);
    if l > 0.0 {
        distance(a, xi) / l
    } else {
        0.0
    }
}

/// Points at fractions along two boundary points' geodesic on `entity`.
fn geodesic_point(
    geometry: &GeometryModel,
    entity: usize,
    from: ([f64; 2], [f64; 3]),
    to: ([f64; 2], [f64; 3]),
    fraction: f64,
) -> ([f64; 2], [f64; 3]) {
    match &geometry.entities[entity].geometry {
        EntityGeometry::Surface(surface) => {
            let chart = SurfaceChart::new(surface);
            // Parameters of edge points may come from another entity's chart on feature
            // edges; re-invert them where they do not reproduce the point.
            let param_on = |(uv, x): ([f64; 2], [f64; 3])| {
                if distance(chart.point(uv), x) <= 1e-9 * surface.size() {
                    uv
                } else {
                    closest_point_on_surface(surface, x).param
                }
            };
            let path = GeodesicPath::between(
                &chart,
                param_on(from),
                param_on(to),
                DEFAULT_LENGTH_TOLERANCE,
            );
            path.at_fraction(&chart, fraction)
        }
        EntityGeometry::Curve(_) => {
            let x = [
                from.1[0] + fraction * (to.1[0] - from.1[0]),
                from.1[1] + fraction * (to.1[1] - from.1[1]),
                from.1[2] + fraction * (to.1[2] - from.1[2]),
            ];
            ([0.0; 2], x)
        }
    }
}

type Along<'a> = dyn Fn(usize, usize, f64) -> Result<([f64; 2], [f64; 3]), GeodesicError> + 'a;

/// The paper's Eq. (6): a triangle's interior node from three geodesics of constant
/// barycentric coordinate, averaged and projected onto the surface.
fn triangle_node(
    geometry: &GeometryModel,
    entity: usize,
    along: &Along,
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
    let mean = [
        (xa.1[0] + xb.1[0] + xc.1[0]) / 3.0,
        (xa.1[1] + xb.1[1] + xc.1[1]) / 3.0,
        (xa.1[2] + xb.1[2] + xc.1[2]) / 3.0,
    ];
    Ok(project(geometry, entity, mean, xa.0))
}

/// The paper's Eq. (7): a quadrilateral's interior node from the two geodesics of constant
/// ξ and η, averaged and projected onto the surface.
fn quadrilateral_node(
    geometry: &GeometryModel,
    entity: usize,
    along: &Along,
    xi: [f64; 3],
) -> Result<[f64; 3], GeodesicError> {
    let (s, t) = (xi[0], xi[1]);
    // Vertices 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1).
    let x_s = geodesic_point(geometry, entity, along(0, 1, s)?, along(3, 2, s)?, t);
    let x_t = geodesic_point(geometry, entity, along(0, 3, t)?, along(1, 2, t)?, s);
    let mean = [
        0.5 * (x_s.1[0] + x_t.1[0]),
        0.5 * (x_s.1[1] + x_t.1[1]),
        0.5 * (x_s.1[2] + x_t.1[2]),
    ];
    Ok(project(geometry, entity, mean, x_s.0))
}

/// Closest point of `entity` to `x` (Π_S in Eqs. (6), (7)), by Newton from `guess` on a
/// surface, in closed form where the entity has one.
fn project(geometry: &GeometryModel, entity: usize, x: [f64; 3], guess: [f64; 2]) -> [f64; 3] {
    let e = &geometry.entities[entity];
    if let Some(shape) = &e.analytic {
        return shape.closest_point(x).point;
    }
    match &e.geometry {
        EntityGeometry::Surface(s) => SurfaceChart::new(s).project_near(x, guess).1,
        EntityGeometry::Curve(c) => closest_point_on_curve(c, x).point,
    }
}

/// Largest distance of a target from the entities it should lie on.
fn max_distance(
    geometry: &GeometryModel,
    targets: &BTreeMap<u32, [f64; 3]>,
    entities: &BTreeMap<u32, Vec<usize>>,
) -> f64 {
    let work: Vec<([f64; 3], &Vec<usize>)> = targets
        .iter()
        .filter_map(|(n, x)| entities.get(n).map(|e| (*x, e)))
        .collect();
    work.par_iter()
        .map(|(x, es)| {
            es.iter()
                .map(|&e| geometry.entities[e].distance(*x))
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
}
