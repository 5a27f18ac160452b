//! Target positions of every high-order node on a curved boundary (the paper's Sect. 3.1,
//! 4.1, 4.2): vertices snapped onto the geometry, edge nodes by arc length along the boundary
//! curve (2D, Eq. (4)), along the intersection curve of the surfaces that meet at a feature
//! edge (3D patch boundaries, [`crate::feature`]) or along the approximate geodesic (3D, Eq.
//! (5)) — with the minimum-angle correction of Fig. 4 ([`crate::correction`]) — and
//! face-interior nodes by the geodesic constructions of Eq. (6) (triangles) and Eq. (7)
//! (quadrilaterals); or, as the baseline the paper improves on, by closest-point projection of
//! the straight nodes.
//!
//! Every edge's nodes are computed once, from one carrier built in the edge's canonical
//! orientation (lower vertex id first), so the facets on either side of it see the very same
//! points.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::{NodeEntity, ReferenceNodes, Shape};
use hocurve_nurbs::inversion::{closest_point_on_curve, closest_point_on_surface};
use hocurve_nurbs::vec3::{add, distance, scale, sub};
use hocurve_nurbs::{EntityGeometry, GeometryModel};
use rayon::prelude::*;

use crate::association::snap_onto;
use crate::chart::SurfaceChart;
use crate::correction::{check_edge, CorrectedEdge, EdgeEnd, Neighbour};
use crate::curve_arc::CurveArc;
use crate::feature::FeatureCurve;
use crate::frame::end_tangent;
use crate::path::{GeodesicPath, DEFAULT_LENGTH_TOLERANCE};
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

/// Options of [`place_boundary_nodes_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementOptions {
    /// How the nodes are placed: the paper's geodesic method (default) or closest-point
    /// projection of the straight nodes.
    pub strategy: BoundaryNodeStrategy,
    /// The paper's minimum-angle correction (Sect. 4.1, Fig. 4): surface edges making an
    /// angle below this limit (degrees, in [0, 90)) with a neighbouring edge of a curved face
    /// are replaced by a Hermite-type polynomial curve whose end tangents restore the limit
    /// (see [`crate::correction`]). `None` or `Some(0.0)` turns it off; default `Some(10.0)`.
    /// Only used by [`BoundaryNodeStrategy::Geodesic`] in 3D at orders p ≥ 3 (at p = 2 small
    /// angles are counted but not corrected).
    pub min_angle_degrees: Option<f64>,
    /// Relative tolerance on the length of traced intersection curves (feature edges between
    /// two surfaces without a curve entity in the model): the bisection stops when the
    /// polyline's length changes by less than this. Default 1e-12.
    pub feature_length_tolerance: f64,
    /// Surface edges (global vertex pairs, lower id first) that keep their geodesic even
    /// when an angle there is below the limit: the curving pipeline's repair puts here the
    /// corrected edges of elements that came out invalid, so that a correction is kept only
    /// where it does not hurt.
    pub uncorrected_edges: BTreeSet<[u32; 2]>,
}

impl Default for PlacementOptions {
    fn default() -> Self {
        Self::new(BoundaryNodeStrategy::default())
    }
}

impl PlacementOptions {
    /// The defaults with the given strategy: minimum angle 10°, feature curves traced to a
    /// relative length change of 1e-12.
    pub fn new(strategy: BoundaryNodeStrategy) -> Self {
        Self {
            strategy,
            min_angle_degrees: Some(10.0),
            feature_length_tolerance: 1e-12,
            uncorrected_edges: BTreeSet::new(),
        }
    }

    /// The same options with the minimum-angle limit `degrees` (`None`: no correction).
    pub fn with_min_angle(mut self, degrees: Option<f64>) -> Self {
        self.min_angle_degrees = degrees;
        self
    }

    /// The angle limit in radians, `None` when the correction is off; an error for a limit
    /// outside [0, 90) degrees or a tolerance that is not a positive finite number.
    fn checked_limit(&self) -> Result<Option<f64>, GeodesicError> {
        let t = self.feature_length_tolerance;
        if !(t.is_finite() && t > 0.0) {
            return Err(GeodesicError::InvalidOption {
                option: "feature_length_tolerance",
                reason: format!("must be a finite number > 0, got {t}"),
            });
        }
        match self.min_angle_degrees {
            None => Ok(None),
            Some(a) if a.is_finite() && (0.0..90.0).contains(&a) => {
                Ok((a > 0.0).then(|| a.to_radians()))
            }
            Some(a) => Err(GeodesicError::InvalidOption {
                option: "min_angle_degrees",
                reason: format!("must be an angle in [0, 90) degrees, got {a}"),
            }),
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
    /// Surface edges with an angle below the minimum-angle limit (Fig. 4a), corrected or not.
    pub small_angle_edges: usize,
    /// Edges replaced by the Hermite-type curve of the minimum-angle correction (Fig. 4b).
    pub corrected_edges: usize,
    /// The vertex pairs (lower id first) of the corrected edges, sorted.
    pub corrected_edge_vertices: Vec<[u32; 2]>,
    /// Smallest angle (degrees) between a surface edge and a neighbouring edge of a curved
    /// face before the correction (`None` when not measured: 2D, projection, p = 1, no limit).
    pub min_edge_angle_degrees: Option<f64>,
    /// Feature edges (on two or more surfaces) placed by arc length along the model's own
    /// curve entity.
    pub feature_edges_on_curves: usize,
    /// Feature edges placed along a traced intersection curve.
    pub feature_edges_traced: usize,
}

/// How the interior nodes of one mesh edge are placed: by the fraction of the length from the
/// edge's first vertex.
pub(crate) enum EdgeCarrier<'a> {
    /// A boundary curve (2D) between two parameters, possibly across the seam of a closed curve.
    Curve(CurveArc<'a>),
    /// An approximate geodesic on a surface (an edge inside one surface patch).
    Surface {
        chart: SurfaceChart<'a>,
        path: GeodesicPath,
    },
    /// The intersection of two or more surfaces (a feature edge, on a patch boundary).
    Feature(FeatureCurve<'a>),
    /// A surface edge replaced by the minimum-angle correction.
    Corrected(CorrectedEdge<'a>),
}

/// Target positions of the nodes of every associated facet of `mesh` (a straight-sided
/// high-order mesh built from the linear mesh that `association` was made for), with the
/// default [`PlacementOptions`] for `strategy` (minimum-angle correction at 10°).
pub fn place_boundary_nodes(
    mesh: &HighOrderMesh,
    geometry: &GeometryModel,
    association: &BoundaryAssociation,
    strategy: BoundaryNodeStrategy,
) -> Result<BoundaryTargets, GeodesicError> {
    place_boundary_nodes_with(
        mesh,
        geometry,
        association,
        &PlacementOptions::new(strategy),
    )
}

/// Target positions of the nodes of every associated facet of `mesh` (a straight-sided
/// high-order mesh built from the linear mesh that `association` was made for), placed as
/// `options` say.
pub fn place_boundary_nodes_with(
    mesh: &HighOrderMesh,
    geometry: &GeometryModel,
    association: &BoundaryAssociation,
    options: &PlacementOptions,
) -> Result<BoundaryTargets, GeodesicError> {
    let limit = options.checked_limit()?;
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
    // of different entities lie on all of them. For each edge, the neighbouring edges at its
    // ends in the facets holding it: (vertex, the facet's next vertex beyond the edge).
    let mut node_entities: BTreeMap<u32, BTreeSet<usize>> = BTreeMap::new();
    let mut edge_entities: BTreeMap<[u32; 2], BTreeSet<usize>> = BTreeMap::new();
    let mut edge_neighbours: BTreeMap<[u32; 2], Vec<(u32, u32)>> = BTreeMap::new();
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
            let key = [a.min(b), a.max(b)];
            edge_entities.entry(key).or_default().insert(e);
            if shape != Shape::Line {
                // Facet edges run round the polygon: i's other neighbour precedes it, j's
                // follows it.
                let nv = shape.num_vertices();
                let list = edge_neighbours.entry(key).or_default();
                list.push((a, facet.nodes[(i + nv - 1) % nv]));
                list.push((b, facet.nodes[(j + 1) % nv]));
            }
        }
    }
    if order == 1 {
        out.max_geometry_distance = max_distance(geometry, &out.targets, &out.entities);
        return Ok(out);
    }

    if options.strategy == BoundaryNodeStrategy::Projection {
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
        .map(|(vertices, entities)| {
            edge_carrier(
                geometry,
                association,
                *vertices,
                entities,
                options.feature_length_tolerance,
            )
        })
        .collect();
    let mut carrier_of: BTreeMap<[u32; 2], EdgeCarrier> = BTreeMap::new();
    for ((vertices, _), c) in edges.iter().zip(carriers) {
        let c = c?;
        if let EdgeCarrier::Feature(f) = &c {
            if f.curve_entity().is_some() {
                out.feature_edges_on_curves += 1;
            } else {
                out.feature_edges_traced += 1;
            }
        }
        carrier_of.insert(*vertices, c);
    }

    // The minimum-angle correction (Fig. 4), from the uncorrected carriers.
    if let (Some(limit), 3) = (limit, mesh.dim) {
        let checks: Vec<([u32; 2], Option<crate::correction::AngleCheck>)> = carrier_of
            .par_iter()
            .map(|(key, _)| {
                let check = check_edge_angles(
                    association,
                    &carrier_of,
                    &edge_neighbours,
                    [key[0], key[1]],
                    order,
                    limit,
                )?;
                Ok((*key, check))
            })
            .collect::<Result<_, GeodesicError>>()?;
        let mut min_angle = f64::INFINITY;
        for (key, check) in checks {
            let Some(check) = check else { continue };
            min_angle = min_angle.min(check.min_angle);
            if check.min_angle < limit {
                out.small_angle_edges += 1;
            }
            let Some(curve) = check.curve else { continue };
            if options.uncorrected_edges.contains(&key) {
                continue;
            }
            let entity = edge_entities[&key].iter().copied().next();
            if let (Some(EdgeCarrier::Surface { chart, path }), Some(entity)) =
                (carrier_of.remove(&key), entity)
            {
                carrier_of.insert(
                    key,
                    EdgeCarrier::Corrected(CorrectedEdge {
                        geometry,
                        entity,
                        chart,
                        curve,
                        guide: path,
                    }),
                );
                out.corrected_edge_vertices.push(key);
            }
        }
        out.corrected_edges = out.corrected_edge_vertices.len();
        if min_angle.is_finite() {
            out.min_edge_angle_degrees = Some(min_angle.to_degrees());
        }
    }

    // Edge nodes, once per edge from its carrier, at the reference 1D distribution (the
    // mesh numbers edge e's interior nodes from its lower vertex in this order).
    let line_fractions: Vec<f64> = mesh
        .family
        .interior_nodes(Shape::Line, order)
        .iter()
        .map(|(x, _)| x[0])
        .collect();
    let edge_ids: HashMap<[u32; 2], usize> = mesh
        .topology
        .edges
        .iter()
        .enumerate()
        .filter(|(_, e)| carrier_of.contains_key(*e))
        .map(|(i, e)| (*e, i))
        .collect();
    let edge_work: Vec<(&[u32; 2], &EdgeCarrier)> = carrier_of.iter().collect();
    let edge_nodes: Vec<Vec<(u32, [f64; 3])>> = edge_work
        .par_iter()
        .map(|(key, carrier)| {
            let e = *edge_ids.get(*key).ok_or_else(|| {
                GeodesicError::Mismatch(format!(
                    "edge {key:?} of a curved facet is not a mesh edge"
                ))
            })?;
            let first = mesh.layout.edge_first_node(e, order);
            Ok(line_fractions
                .iter()
                .enumerate()
                .map(|(k, &f)| ((first + k) as u32, carrier.at(f).1))
                .collect())
        })
        .collect::<Result<_, GeodesicError>>()?;
    for list in edge_nodes {
        for (n, x) in list {
            out.targets.insert(n, x);
        }
    }

    // Face-interior nodes, facet by facet (from the same carriers).
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
    let Some(EdgeCarrier::Surface { chart, path }) = carriers.get(&key) else {
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
            smooth: !matches!(association.vertex_entities.get(&v), Some(e) if e.len() > 1),
        });
    }
    let ends: [EdgeEnd; 2] = ends
        .try_into()
        .map_err(|_| GeodesicError::Mismatch("an edge has two ends".into()))?;
    Ok(check_edge(chart, &ends, path.length(), order, limit))
}

/// The local vertex pairs of a facet's edges.
fn facet_edges(shape: Shape) -> Vec<[usize; 2]> {
    match shape {
        Shape::Line => vec![[0, 1]],
        s => s.edges().to_vec(),
    }
}

/// The carrier of the mesh edge from vertex `a` to vertex `b` lying on `entities`: the
/// boundary curve (2D), the geodesic on the one surface, or the intersection curve of
/// several surfaces (traced to the relative length tolerance `feature_tolerance`).
pub(crate) fn edge_carrier<'a>(
    geometry: &'a GeometryModel,
    association: &BoundaryAssociation,
    [a, b]: [u32; 2],
    entities: &[usize],
    feature_tolerance: f64,
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
        EntityGeometry::Surface(_) if entities.len() > 1 => Ok(EdgeCarrier::Feature(
            FeatureCurve::between(geometry, entities, xa, xb, feature_tolerance),
        )),
        EntityGeometry::Surface(surface) => {
            let chart = SurfaceChart::new(surface);
            let (pa, pb) = (
                closest_point_on_surface(surface, xa).param,
                closest_point_on_surface(surface, xb).param,
            );
            let path = GeodesicPath::between(&chart, pa, pb, DEFAULT_LENGTH_TOLERANCE);
            Ok(EdgeCarrier::Surface { chart, path })
        }
    }
}

impl EdgeCarrier<'_> {
    /// The point at `fraction` of the edge's length from its first vertex, with its surface
    /// parameter where the carrier is one surface (zero otherwise: users re-invert).
    pub(crate) fn at(&self, fraction: f64) -> ([f64; 2], [f64; 3]) {
        match self {
            EdgeCarrier::Curve(arc) => ([0.0; 2], arc.at(fraction)),
            EdgeCarrier::Surface { chart, path } => path.at_fraction(chart, fraction),
            EdgeCarrier::Feature(curve) => ([0.0; 2], curve.at(fraction)),
            EdgeCarrier::Corrected(edge) => edge.at(fraction),
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

/// Places the interior nodes of one facet on entity `entity` (its edge nodes are placed once
/// per edge, by [`place_boundary_nodes_with`]).
fn place_facet(
    geometry: &GeometryModel,
    carriers: &BTreeMap<[u32; 2], EdgeCarrier>,
    nodes: &[u32],
    shape: Shape,
    reference: &ReferenceNodes,
    entity: usize,
) -> Result<Vec<(u32, [f64; 3])>, GeodesicError> {
    // The point at `fraction` of the way from local vertex i to local vertex j.
    let along =
        |i: usize, j: usize, fraction: f64| -> Result<([f64; 2], [f64; 3]), GeodesicError> {
            let (a, b) = (nodes[i], nodes[j]);
            let key = [a.min(b), a.max(b)];
            let carrier = carriers
                .get(&key)
                .ok_or_else(|| GeodesicError::Mismatch(format!("no carrier for edge {key:?}")))?;
            let f = if a < b { fraction } else { 1.0 - fraction };
            Ok(carrier.at(f))
        };
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
            let x = add(from.1, scale(sub(to.1, from.1), fraction));
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
    let mean = scale(add(x_s.1, x_t.1), 0.5);
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
        .map(|(x, es)| distance_to_all(geometry, *x, es))
        .reduce(|| 0.0, f64::max)
}

/// The largest distance of `x` from any of `entities`.
fn distance_to_all(geometry: &GeometryModel, x: [f64; 3], entities: &[usize]) -> f64 {
    entities
        .iter()
        .map(|&e| geometry.entities[e].distance(x))
        .fold(0.0, f64::max)
}

/// Moves every node of `nodes` listed in `entities` (node id → the entities it lies on, as
/// in [`BoundaryTargets::entities`]) onto its entities: the closest point for one entity,
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

#[cfg(test)]
#[path = "tests/placement.rs"]
mod tests;
