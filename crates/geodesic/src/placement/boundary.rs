//! Boundary placement, the driver: vertices snapped, edge nodes from one carrier per mesh
//! edge (after the minimum-angle correction), face-interior nodes facet by facet; or every
//! node by closest-point projection.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::sync::Arc;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::{NodeFamily, ReferenceElement, Shape};
use hocurve_nurbs::GeometryModel;
use rayon::prelude::*;

use crate::association::snap_onto;
use crate::correction::CorrectedEdge;
use crate::feature::FeatureTraces;
use crate::{BoundaryAssociation, GeodesicError};

use super::edge_carriers::{edge_carrier, vertex_parameters, EdgeCarrier};
use super::face_interior::place_facet;
use super::geometry_distance::max_distance;
use super::options::{BoundaryNodeStrategy, PlacementOptions};
use super::small_angle::check_edge_angles;
use crate::chart::GeometryCharts;

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
    /// curve: a curve entity, or the CAD edge between the surfaces.
    pub feature_edges_on_curves: usize,
    /// Feature edges placed along a traced intersection curve.
    pub feature_edges_traced: usize,
    /// The interior nodes of feature edges at the equispaced fractions of the written mesh,
    /// by the same node ids, when the mesh's own family is another (empty otherwise). The
    /// written mesh's other boundary nodes are the interpolant snapped back onto their
    /// entity; a point near a seam snapped onto two faces that meet only to the file's
    /// uncertainty slides to wherever they cross (3e-3 away along OpenCASCADE's fillet of a
    /// sphere on a plane), so a seam's nodes come from its traced curve.
    pub equispaced_feature_nodes: BTreeMap<u32, [f64; 3]>,
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
    place_boundary_nodes_reusing(
        mesh,
        geometry,
        association,
        options,
        &FeatureTraces::default(),
    )
}

/// [`place_boundary_nodes_with`], the feature curves taken from `traces` where they were
/// traced before (and kept there): for placing nodes on one model several times. The same
/// targets as without.
pub fn place_boundary_nodes_reusing<'a>(
    mesh: &HighOrderMesh,
    geometry: &'a GeometryModel,
    association: &BoundaryAssociation,
    options: &PlacementOptions,
    traces: &FeatureTraces<'a>,
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
        let shape = facet.kind;
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
    let charts = GeometryCharts::new(geometry);
    let params = vertex_parameters(geometry, association, &edges);
    let carriers: Vec<Result<EdgeCarrier, GeodesicError>> = edges
        .par_iter()
        .map(|(vertices, entities)| {
            edge_carrier(
                &charts,
                association,
                &params,
                *vertices,
                entities,
                options.feature_length_tolerance,
                traces,
            )
        })
        .collect();
    let mut carrier_of: BTreeMap<[u32; 2], EdgeCarrier> = BTreeMap::new();
    for ((vertices, _), c) in edges.iter().zip(carriers) {
        let c = c?;
        if let EdgeCarrier::Feature(f) = &c {
            if f.on_model_curve() {
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
            // (Only surface carriers are correctable: `check.curve` is for them alone.)
            match carrier_of.remove(&key) {
                Some(EdgeCarrier::Surface {
                    entity,
                    chart,
                    path,
                    ..
                }) => {
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
                Some(other) => {
                    carrier_of.insert(key, other);
                }
                None => {}
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
        .topology()
        .edges()
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
            let first = mesh.layout().edge_first_node(e, order);
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
    let equispaced: Vec<f64> = NodeFamily::Equispaced
        .interior_nodes(Shape::Line, order)
        .iter()
        .map(|(x, _)| x[0])
        .collect();
    if mesh.family != NodeFamily::Equispaced {
        // (At p = 2 every family's edge node is the midpoint: the nodes placed are the
        // ones written.)
        let same = equispaced == line_fractions;
        let targets = &out.targets;
        let feature_nodes: Vec<Vec<(u32, [f64; 3])>> = edge_work
            .par_iter()
            .filter(|(_, carrier)| matches!(carrier, EdgeCarrier::Feature(_)))
            .filter_map(|(key, carrier)| {
                // (Every carrier's edge was found above.)
                let first = mesh.layout().edge_first_node(*edge_ids.get(*key)?, order);
                equispaced
                    .iter()
                    .enumerate()
                    .map(|(k, &f)| {
                        let n = (first + k) as u32;
                        let x = if same {
                            targets.get(&n).copied()?
                        } else {
                            carrier.at(f).1
                        };
                        Some((n, x))
                    })
                    .collect()
            })
            .collect();
        out.equispaced_feature_nodes = feature_nodes.into_iter().flatten().collect();
    }

    // Face-interior nodes, facet by facet (from the same carriers).
    let reference: BTreeMap<Shape, Arc<ReferenceElement>> = curved
        .iter()
        .map(|&(k, _)| mesh.facets[k].kind)
        .collect::<BTreeSet<_>>()
        .into_iter()
        .map(|s| ReferenceElement::shared(s, order, mesh.family).map(|r| (s, r)))
        .collect::<Result<_, _>>()
        .map_err(|e| GeodesicError::Mismatch(e.to_string()))?;
    let placed: Vec<Vec<(u32, [f64; 3])>> = curved
        .par_iter()
        .map(|&(k, e)| {
            let facet = &mesh.facets[k];
            let shape = facet.kind;
            let refn = reference[&shape].nodes();
            place_facet(&charts, &carrier_of, facet.nodes.as_slice(), shape, refn, e)
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
