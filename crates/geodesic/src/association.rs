//! Association of the mesh's boundary facets with the geometry's curves and surfaces, and the
//! snapping of their vertices onto it (the paper's Sect. 3.1 assumes every boundary vertex
//! lies on the CAD; exported CAD and its mesh often differ by ~1e-6, so we move them).
//!
//! Two rules, tried in order for every declared facet:
//! 1. **By name**: a facet whose physical group is named like an entity goes to that entity
//!    (the JSON input's `name`s are chosen for this).
//! 2. **By proximity** (when [`AssociationRule::NameThenNearest`] is asked for, as for IGES,
//!    whose entities carry no mesh names): the entity of the facet's dimension nearest to all
//!    its vertices — the smallest maximum vertex distance — if that is within the tolerance
//!    and within [`PROXIMITY_EDGE_FRACTION`] of the facet's shortest edge. The second bound
//!    keeps out facets that merely *touch* a surface: in a boundary layer of first height h
//!    below the tolerance, a facet of an end plane spans the layer with two vertices on the
//!    wall's boundary edge and two at distance h = its own shortest edge (a facet lying on
//!    the surface is off it by the CAD–mesh mismatch, a tiny fraction of its edges).
//!    Among the entities that pass, the one nearest the facet's centre (its worst vertex
//!    distance when larger) wins — unless others score within [`SCORE_TIE`] of it, or
//!    within the model's round-off ([`GeometryModel::round_off`]) of it. Then the
//!    facet's mesh entity decides (a mesh generator meshes each CAD face as one entity): the
//!    entity within reach of every facet of it (of several, the one nearest all their
//!    vertices; of several as near to round-off, the smallest patch), if it is among the
//!    tied; else the one nearest the facet's vertices (to round-off; then the smallest
//!    patch). Round-off must not decide: where parts of an assembly touch, a facet on a
//!    plate under a nut measures 0 from the nut's face and 4e-14 from the plate's in one
//!    file, and the other way round in another file of the same model. The smallest patch
//!    among coincident faces is the one that fits the mesh entity (the nut's face for the
//!    nut's mesh surface; the plate's patch holds it too), in any file of the model. A facet
//!    on a sharply curved blade face of Ventilator.stp, beside the fillet it blends into, has
//!    its centre (a sagitta inside the blade) 3.7e-3 from the blade and 3.4e-3 from the
//!    fillet's torus, but its vertices within 1.1e-6 of the blade and up to 1.1e-3 from the
//!    torus. Decisive scores: a facet with every vertex on the rim where a plane meets a
//!    cylinder — three points of a coarsely split quarter-round, one of them the arc's middle
//!    — is on both by its vertices, but spans the plane (centre on it) and cuts through the
//!    cylinder (centre a sagitta inside it). Taking the cylinder would make the facet's
//!    chord a feature edge and lay it along the whole arc. The centre is measured to the
//!    entity's bounded NURBS patch, not its closed form: faces on one infinite cylinder or
//!    plane (coaxial holes through stacked parts of an assembly) are one surface to the
//!    closed form, but only one face's patch holds the facet — and its chart the facet's
//!    parameters.
//!
//! Facets left over stay straight and are counted. A vertex of an associated facet farther
//! than the tolerance from its entity is an error; a vertex within it is moved onto the
//! entity. A vertex shared by facets on two entities (a feature edge) is moved onto both by
//! alternating projections, which converge to the intersection where the two meet at an angle.

use std::collections::{BTreeMap, HashMap};
use std::hash::Hash;
use std::sync::{Arc, Mutex};

use hocurve_mesh::LinearMesh;
use hocurve_nurbs::vec3::distance;
use hocurve_nurbs::GeometryModel;
use rayon::prelude::*;

use crate::GeodesicError;

/// Diagonal of the bounding box of the mesh's vertices, which the default tolerance is
/// relative to (re-exported from [`hocurve_nurbs::vec3`], where it lives).
pub use hocurve_nurbs::vec3::bounding_box_diagonal;

/// How facets find their entity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AssociationRule {
    /// Only physical-group names equal to entity names.
    NameOnly,
    /// Names first, then the nearest entity within the tolerance.
    NameThenNearest,
}

/// The relative default tolerance: a fraction of the mesh's bounding-box diagonal.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-4;

/// The largest vertex distance, as a fraction of a facet's shortest edge, at which proximity
/// still puts the facet on an entity (see the module doc).
pub const PROXIMITY_EDGE_FRACTION: f64 = 0.1;

/// Entities whose proximity scores for a facet (the larger of its centre's distance and
/// its vertices') are within this factor of the least are not told apart by them: a
/// facet's centre is off its own curved face by its sagitta, and off a face that face
/// blends into by about as much (see the module doc).
pub const SCORE_TIE: f64 = 2.0;

/// A facet's tied candidates (first the one to take), and every entity within reach with
/// the facet's largest vertex distance from it, by entity index.
type Ranking = (Vec<usize>, Vec<(usize, f64)>);

/// Which entity each boundary facet lies on, and where its vertices go.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryAssociation {
    /// Entity index (into [`GeometryModel::entities`]) of each declared facet of the mesh,
    /// `None` for facets that stay straight.
    pub facet_entity: Vec<Option<usize>>,
    /// For every vertex on an associated facet: its position on the geometry.
    pub vertex_targets: BTreeMap<u32, [f64; 3]>,
    /// The entities each such vertex lies on (one, or several on a feature edge).
    pub vertex_entities: BTreeMap<u32, Vec<usize>>,
    /// The absolute tolerance used.
    pub tolerance: f64,
    /// Facets associated by name and by proximity.
    pub by_name: usize,
    /// Facets associated by proximity.
    pub by_proximity: usize,
    /// Facets left straight.
    pub unassociated: usize,
    /// Largest distance a vertex was moved to land on the geometry.
    pub max_vertex_move: f64,
}

impl BoundaryAssociation {
    /// Number of facets on each entity, by entity index.
    pub fn facets_per_entity(&self) -> BTreeMap<usize, usize> {
        let mut out = BTreeMap::new();
        for e in self.facet_entity.iter().flatten() {
            *out.entry(*e).or_insert(0) += 1;
        }
        out
    }
}

/// The distances from boundary vertices and from facet centres to the geometry's entities,
/// and the vertices snapped onto their entities, kept across the associations of one run:
/// the pipeline associates the boundary again after every split of the mesh (rims, doubly
/// curved corners, each refinement round), and a split leaves nearly every vertex and facet
/// where it was. Each distance is a point inversion on a patch, and a snap alternating
/// projections (on a B-spline model, all of the association's time: Ventilator.stp, 102 k
/// facets, 20 s; again with all kept, 2 s). Kept by the point's coordinates' bits for one
/// model, tolerance and entity dimension (another clears them): a kept distance is the
/// one computing it again would give, bit for bit. Beyond [`KEPT_DISTANCES`] distances no
/// more are kept.
#[derive(Debug, Default)]
pub struct ProximityCache {
    kept: Mutex<KeptDistances>,
}

/// At most this many vertex–entity distances are kept by a [`ProximityCache`] (16 bytes
/// each: 128 MB).
pub const KEPT_DISTANCES: usize = 1 << 23;

/// The rows kept, what they were computed for, and their entries in all.
#[derive(Debug, Default)]
struct KeptDistances {
    /// The model's address, the tolerance's bits, and whether the candidates are curves.
    context: Option<(usize, u64, bool)>,
    rows: HashMap<[u64; 3], Arc<DistanceRow>>,
    /// Facet centres' distances to entities' patches, by the centre's bits and the entity.
    centres: CentreDistances,
    /// Vertices snapped onto their entities, by the vertex's bits and the entities.
    snaps: Snaps,
    entries: usize,
}

/// Vertices snapped onto their entities ([`snap_onto`]), by the vertex's coordinates' bits
/// and the entities' indices (each within the tolerance of the vertex).
type Snaps = HashMap<SnapKey, [f64; 3]>;

/// A vertex's coordinates' bits and its entities.
type SnapKey = ([u64; 3], Vec<usize>);

/// Facet centres' distances to entities' bounded patches ([`GeometricEntity::patch_distance`]),
/// by the centre's coordinates' bits and the entity's index.
///
/// [`GeometricEntity::patch_distance`]: hocurve_nurbs::GeometricEntity::patch_distance
type CentreDistances = HashMap<CentreKey, f64>;

/// A facet centre's coordinates' bits and an entity's index.
type CentreKey = ([u64; 3], u32);

/// A vertex's distance to each candidate entity (by position in the candidate list, ascending)
/// whose patch is not provably beyond the tolerance; the others are infinitely far.
type DistanceRow = Vec<(u32, f64)>;

/// The distance to candidate `k` in `row` (infinite when left out).
fn distance_in(row: &DistanceRow, k: usize) -> f64 {
    row.binary_search_by_key(&(k as u32), |e| e.0)
        .map_or(f64::INFINITY, |i| row[i].1)
}

impl ProximityCache {
    /// Keeps what follows for `geometry`, `tolerance` and candidates of the dimension
    /// `wants_curve` says, clearing what was kept for others.
    fn enter(&self, geometry: &GeometryModel, tolerance: f64, wants_curve: bool) {
        let context = (
            geometry as *const GeometryModel as usize,
            tolerance.to_bits(),
            wants_curve,
        );
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        if kept.context != Some(context) {
            *kept = KeptDistances {
                context: Some(context),
                ..KeptDistances::default()
            };
        }
    }

    /// The rows kept.
    #[cfg(test)]
    pub(crate) fn kept_rows(&self) -> usize {
        self.kept.lock().map_or(0, |k| k.rows.len())
    }

    /// The centres' distances kept.
    #[cfg(test)]
    pub(crate) fn kept_centres(&self) -> usize {
        self.kept.lock().map_or(0, |k| k.centres.len())
    }

    /// The distance rows of the points `xs` to `candidates` of `geometry` (within the
    /// context of the last [`Self::enter`]), from the cache where kept, computed (in
    /// parallel) and kept otherwise.
    fn rows(
        &self,
        geometry: &GeometryModel,
        candidates: &[usize],
        tolerance: f64,
        xs: &[[f64; 3]],
    ) -> Vec<Arc<DistanceRow>> {
        let key = |x: &[f64; 3]| x.map(f64::to_bits);
        let mut found: Vec<Option<Arc<DistanceRow>>> = {
            let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
            xs.iter().map(|x| kept.rows.get(&key(x)).cloned()).collect()
        };
        // An entity without a closed form lies in the boxes of its knot spans' control
        // points (convex hull, positive weights): a vertex farther than the tolerance from
        // all of them cannot be on it, and its point inversion is skipped.
        let missing: Vec<usize> = (0..xs.len()).filter(|&i| found[i].is_none()).collect();
        let computed: Vec<Arc<DistanceRow>> = missing
            .par_iter()
            .map(|&i| {
                let x = xs[i];
                let row: DistanceRow = candidates
                    .iter()
                    .enumerate()
                    .filter_map(|(k, &e)| {
                        let entity = &geometry.entities[e];
                        if entity.analytic.is_none() && entity.patch_is_farther_than(x, tolerance) {
                            None
                        } else {
                            Some((k as u32, entity.distance(x)))
                        }
                    })
                    .collect();
                Arc::new(row)
            })
            .collect();
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        for (&i, row) in missing.iter().zip(computed) {
            if kept.entries + row.len() <= KEPT_DISTANCES {
                kept.entries += row.len();
                kept.rows.insert(key(&xs[i]), row.clone());
            }
            found[i] = Some(row);
        }
        found.into_iter().flatten().collect()
    }

    /// One of the maps kept (for the context of the last [`Self::enter`]: `which` picks
    /// it), taken out so that a parallel loop reads it without a lock; [`Self::put_back`]
    /// returns it with the new entries.
    fn take<K, V>(
        &self,
        which: impl FnOnce(&mut KeptDistances) -> &mut HashMap<K, V>,
    ) -> HashMap<K, V> {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        std::mem::take(which(&mut kept))
    }

    /// Returns the map taken by [`Self::take`] with `new` entries while there is room.
    fn put_back<K: Eq + Hash, V>(
        &self,
        which: impl FnOnce(&mut KeptDistances) -> &mut HashMap<K, V>,
        mut taken: HashMap<K, V>,
        new: Vec<(K, V)>,
    ) {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let room = KEPT_DISTANCES.saturating_sub(kept.entries);
        kept.entries += new.len().min(room);
        taken.extend(new.into_iter().take(room));
        *which(&mut kept) = taken;
    }
}

/// Associates the declared facets of `mesh` with entities of `geometry` (see the module doc).
/// `tolerance` is absolute; `None` takes [`DEFAULT_RELATIVE_TOLERANCE`] × the mesh's bounding-box
/// diagonal.
pub fn associate_boundary(
    mesh: &LinearMesh,
    geometry: &GeometryModel,
    rule: AssociationRule,
    tolerance: Option<f64>,
) -> Result<BoundaryAssociation, GeodesicError> {
    associate_boundary_reusing(mesh, geometry, rule, tolerance, &ProximityCache::default())
}

/// [`associate_boundary`], the vertices' distances to the entities taken from `cache` where
/// computed before (and kept there): for associating several meshes of one run, most of
/// whose vertices are the same. The same association as without.
pub fn associate_boundary_reusing(
    mesh: &LinearMesh,
    geometry: &GeometryModel,
    rule: AssociationRule,
    tolerance: Option<f64>,
    cache: &ProximityCache,
) -> Result<BoundaryAssociation, GeodesicError> {
    let tolerance =
        tolerance.unwrap_or(DEFAULT_RELATIVE_TOLERANCE * bounding_box_diagonal(&mesh.vertices));
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(GeodesicError::Tolerance(tolerance));
    }
    // Entities of the facets' dimension: curves bound 2D meshes, surfaces 3D ones.
    let wants_curve = mesh.dim == 2;
    cache.enter(geometry, tolerance, wants_curve);
    let candidates: Vec<usize> = (0..geometry.entities.len())
        .filter(|&i| geometry.entities[i].is_curve() == wants_curve)
        .collect();

    // Rule 1: names.
    let name_of_group: BTreeMap<i32, &str> = mesh
        .physical_groups
        .iter()
        .filter(|g| g.dim + 1 == mesh.dim)
        .map(|g| (g.tag, g.name.as_str()))
        .collect();
    let mut facet_entity: Vec<Option<usize>> = mesh
        .facets
        .iter()
        .map(|f| {
            mesh.physical_tags(mesh.dim - 1, f.entity)
                .iter()
                .filter_map(|t| name_of_group.get(t))
                .find_map(|name| geometry.index_of(name))
        })
        .collect();
    for (f, (facet, entity)) in mesh.facets.iter().zip(&facet_entity).enumerate() {
        if let Some(e) = *entity {
            if geometry.entities[e].is_curve() != wants_curve {
                return Err(GeodesicError::EntityDimension {
                    entity: geometry.entities[e].name.clone(),
                    mesh_dim: mesh.dim,
                    facet_vertices: facet.vertices.clone(),
                    facet_tag: mesh.facet_tag(f),
                });
            }
        }
    }
    let by_name = facet_entity.iter().flatten().count();
    let round_off = geometry.round_off();
    let sizes: Vec<f64> = geometry.entities.iter().map(|e| e.size()).collect();

    // Rule 2: proximity, with the vertex–entity distances computed once per vertex.
    let mut by_proximity = 0;
    if rule == AssociationRule::NameThenNearest && !candidates.is_empty() {
        let mut open_vertices: Vec<u32> = mesh
            .facets
            .iter()
            .zip(&facet_entity)
            .filter(|(_, e)| e.is_none())
            .flat_map(|(f, _)| f.vertices.iter().copied())
            .collect();
        open_vertices.sort_unstable();
        open_vertices.dedup();
        let positions: Vec<[f64; 3]> = open_vertices
            .iter()
            .map(|&v| mesh.vertices[v as usize])
            .collect();
        let distances = cache.rows(geometry, &candidates, tolerance, &positions);
        let row = |v: u32| -> &DistanceRow {
            // Present: every open facet's vertices were collected above.
            &distances[open_vertices.binary_search(&v).unwrap_or(0)]
        };
        // Facet by facet in parallel: each scores its candidates by a point inversion of
        // its centre (unless kept), independently of the others.
        let kept_centres = cache.take(|k| &mut k.centres);
        type Scored = (Ranking, Vec<(CentreKey, f64)>);
        let scored_facets: Vec<Scored> = mesh
            .facets
            .par_iter()
            .zip(facet_entity.par_iter())
            .map(|(facet, entity)| {
                if entity.is_some() {
                    return ((Vec::new(), Vec::new()), Vec::new());
                }
                let mut measured = Vec::new();
                let reach =
                    tolerance.min(PROXIMITY_EDGE_FRACTION * shortest_edge(mesh, &facet.vertices));
                let centre = centroid(mesh, &facet.vertices);
                let mut patch_distance = |e: usize| {
                    let key = (centre.map(f64::to_bits), e as u32);
                    if let Some(&d) = kept_centres.get(&key) {
                        return d;
                    }
                    let d = geometry.entities[e].patch_distance(centre);
                    measured.push((key, d));
                    d
                };
                // Every entity within reach, with the facet's largest vertex distance.
                let mut within: Vec<(usize, f64)> = candidates
                    .iter()
                    .enumerate()
                    .map(|(k, &e)| {
                        let worst = facet
                            .vertices
                            .iter()
                            .map(|&v| distance_in(row(v), k))
                            .fold(0.0, f64::max);
                        (e, worst)
                    })
                    .filter(|&(_, worst)| worst <= reach)
                    .collect();
                // Their scores, nearest vertices first: (score, worst, entity). Vertices on
                // the curve where two surfaces meet are on both; the facet's centre tells
                // which one the facet spans, and its distance to the entity's bounded patch
                // which of several faces on one infinite surface it is on (see the module
                // doc). A score is at least `worst` and the centre's patch distance: when
                // either provably exceeds `SCORE_TIE` times the least so far, the entity is
                // not tied (nor, by the order, any after it in the first case).
                within.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                let mut least = f64::INFINITY;
                let mut scored: Vec<(f64, f64, usize)> = Vec::new();
                for &(e, worst) in &within {
                    let tie = (SCORE_TIE * least).max(round_off);
                    if worst > tie {
                        break;
                    }
                    if least.is_finite() && geometry.entities[e].patch_is_farther_than(centre, tie)
                    {
                        continue;
                    }
                    let score = worst.max(patch_distance(e));
                    least = least.min(score);
                    scored.push((score, worst, e));
                }
                within.sort_unstable_by_key(|w| w.0);
                // Scores within `SCORE_TIE` of the least, or within round-off of it, do not
                // tell the entities apart: nearest vertices first, then the nearest centre,
                // each to round-off, then the smallest patch.
                let mut tied: Vec<(f64, f64, usize)> = scored
                    .into_iter()
                    .filter(|s| s.0 <= (SCORE_TIE * least).max(round_off))
                    .collect();
                let beyond_round_off = |d: f64| d.max(round_off);
                tied.sort_by(|a, b| {
                    beyond_round_off(a.1)
                        .total_cmp(&beyond_round_off(b.1))
                        .then(beyond_round_off(a.0).total_cmp(&beyond_round_off(b.0)))
                        .then(sizes[a.2].total_cmp(&sizes[b.2]))
                        .then(a.2.cmp(&b.2))
                });
                (
                    (
                        tied.into_iter().map(|(_, _, e)| e).collect::<Vec<usize>>(),
                        within,
                    ),
                    measured,
                )
            })
            .collect();
        let mut new_centres = Vec::new();
        let ranked: Vec<Ranking> = scored_facets
            .into_iter()
            .map(|(ranking, measured)| {
                new_centres.extend(measured);
                ranking
            })
            .collect();
        cache.put_back(|k| &mut k.centres, kept_centres, new_centres);
        // A facet between equally near entities goes with its mesh entity (a mesh generator
        // meshes each CAD face as one entity): to the entity within reach of every facet of
        // it — the nearest to all their vertices where several are (one face for all, so
        // that no feature edge runs between two faces that nearly coincide), distances below
        // round-off counting as round-off and totals within round-off of the least as
        // equal, then the smallest patch — when that is among its own.
        let mut common: BTreeMap<i32, Vec<(usize, f64)>> = BTreeMap::new();
        for (facet, (_, within)) in mesh.facets.iter().zip(&ranked) {
            if within.is_empty() {
                continue;
            }
            common
                .entry(facet.entity)
                .and_modify(|c| {
                    c.retain_mut(|(e, total)| match within.binary_search_by_key(e, |w| w.0) {
                        Ok(k) => {
                            *total += within[k].1.max(round_off);
                            true
                        }
                        Err(_) => false,
                    })
                })
                .or_insert_with(|| {
                    within
                        .iter()
                        .map(|&(e, worst)| (e, worst.max(round_off)))
                        .collect()
                });
        }
        let face_of: BTreeMap<i32, usize> = common
            .into_iter()
            .filter_map(|(tag, c)| {
                let least = c.iter().map(|w| w.1).fold(f64::INFINITY, f64::min);
                let nearest = c
                    .into_iter()
                    .filter(|w| w.1 <= least + round_off)
                    .min_by(|a, b| sizes[a.0].total_cmp(&sizes[b.0]).then(a.0.cmp(&b.0)))?;
                Some((tag, nearest.0))
            })
            .collect();
        let nearest: Vec<Option<usize>> = mesh
            .facets
            .iter()
            .zip(&ranked)
            .map(|(facet, (tied, _))| {
                let face = face_of.get(&facet.entity);
                tied.iter()
                    .find(|&e| face == Some(e))
                    .or(tied.first())
                    .copied()
            })
            .collect();
        for (entity, nearest) in facet_entity.iter_mut().zip(nearest) {
            if let Some(e) = nearest {
                *entity = Some(e);
                by_proximity += 1;
            }
        }
    }
    let unassociated = facet_entity.iter().filter(|e| e.is_none()).count();

    // Vertices: their entities, then their snapped positions.
    let mut vertex_entities: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for (facet, entity) in mesh.facets.iter().zip(&facet_entity) {
        if let Some(e) = *entity {
            for &v in &facet.vertices {
                let list = vertex_entities.entry(v).or_default();
                if !list.contains(&e) {
                    list.push(e);
                }
            }
        }
    }
    for list in vertex_entities.values_mut() {
        list.sort_unstable();
    }
    let work: Vec<(u32, Vec<usize>)> = vertex_entities
        .iter()
        .map(|(v, e)| (*v, e.clone()))
        .collect();
    // (A vertex snapped before, onto the same entities, was within the tolerance of each.)
    let kept_snaps = cache.take(|k| &mut k.snaps);
    type Snapped = Result<(u32, [f64; 3], f64, bool), GeodesicError>;
    let snapped: Vec<Snapped> = work
        .par_iter()
        .map(|(v, entities)| {
            let x = mesh.vertices[*v as usize];
            if let Some(&target) = kept_snaps.get(&(x.map(f64::to_bits), entities.clone())) {
                return Ok((*v, target, distance(target, x), false));
            }
            for &e in entities {
                let d = geometry.entities[e].distance(x);
                if d > tolerance {
                    return Err(GeodesicError::VertexOffGeometry {
                        vertex: *v,
                        tag: mesh.vertex_tag(*v as usize),
                        position: x,
                        entity: geometry.entities[e].name.clone(),
                        distance: d,
                        tolerance,
                    });
                }
            }
            let target = snap_onto(geometry, entities, x);
            Ok((*v, target, distance(target, x), true))
        })
        .collect();
    let mut vertex_targets = BTreeMap::new();
    let mut max_vertex_move: f64 = 0.0;
    let mut new_snaps = Vec::new();
    let mut failed = None;
    for (s, (_, entities)) in snapped.into_iter().zip(&work) {
        match s {
            Ok((v, target, moved, new)) => {
                vertex_targets.insert(v, target);
                max_vertex_move = max_vertex_move.max(moved);
                if new {
                    let x = mesh.vertices[v as usize];
                    new_snaps.push(((x.map(f64::to_bits), entities.clone()), target));
                }
            }
            Err(e) => {
                failed.get_or_insert(e);
            }
        }
    }
    cache.put_back(|k| &mut k.snaps, kept_snaps, new_snaps);
    if let Some(e) = failed {
        return Err(e);
    }
    Ok(BoundaryAssociation {
        facet_entity,
        vertex_targets,
        vertex_entities,
        tolerance,
        by_name,
        by_proximity,
        unassociated,
        max_vertex_move,
    })
}

/// The mean of a facet's vertices.
fn centroid(mesh: &LinearMesh, vertices: &[u32]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in vertices {
        let x = mesh.vertices[v as usize];
        for d in 0..3 {
            c[d] += x[d];
        }
    }
    c.map(|s| s / vertices.len().max(1) as f64)
}

/// The shortest side of a facet (a segment, or a polygon through its vertices in order).
fn shortest_edge(mesh: &LinearMesh, vertices: &[u32]) -> f64 {
    let k = vertices.len();
    let sides = if k == 2 { 1 } else { k };
    (0..sides)
        .map(|i| {
            distance(
                mesh.vertices[vertices[i] as usize],
                mesh.vertices[vertices[(i + 1) % k] as usize],
            )
        })
        .fold(f64::INFINITY, f64::min)
}

/// How far, in multiples of a point's distance from its entities, the seam solver may move it
/// (see [`snap_onto`]).
const SEAM_REACH: f64 = 1e4;

/// Faces closer than this (relative to the model size) at a point share it: a seam.
const ON_SEAM: f64 = 1e-10;

/// The point on all of `entities` nearest `x`: the projection for one entity; alternating
/// projections for several (they converge linearly, fast for transversal intersections),
/// then, where they creep (surfaces meeting tangentially), the seam solver of
/// [`crate::feature`] if it lands closer to all of them.
pub fn snap_onto(geometry: &GeometryModel, entities: &[usize], x: [f64; 3]) -> [f64; 3] {
    match entities {
        [] => x,
        [e] => geometry.entities[*e].nearest_point(x),
        _ => {
            let (y, params) = alternating_projections(geometry, entities, x);
            let size = geometry.size().max(f64::MIN_POSITIVE);
            // (Measured by local searches from the feet's parameters: a global inversion
            // per entity costs a grid search. Closed forms need no parameter.)
            let foot = |e: usize, y: [f64; 3], param: Option<[f64; 2]>| match param {
                Some(uv) => geometry.entities[e].nearest_point_near(y, uv).0,
                None => geometry.entities[e].nearest_point(y),
            };
            let off = |y: [f64; 3]| -> f64 {
                entities
                    .iter()
                    .zip(&params)
                    .map(|(&e, &uv)| distance(y, foot(e, y, uv)))
                    .fold(0.0, f64::max)
            };
            let left = off(y);
            if left <= 1e-13 * size {
                return y;
            }
            // Alternating projections creep where two surfaces meet tangentially; the seam
            // solver works on the NURBS charts, so it needs every face's parameter.
            let guess: Vec<[f64; 2]> = entities
                .iter()
                .zip(&params)
                .map(|(&e, uv)| uv.unwrap_or_else(|| geometry.entities[e].closest_point(y).param))
                .collect();
            // Where the faces touch over a wide band (one blending into the other, gap
            // ~1e-7 for millimetres along the seam), the offset is flat every way, the
            // direction across is noise, and the solver slides along the seam to wherever
            // the gap is least (Ventilator.stp: 1.85 mm, seven edge lengths, from a
            // vertex 1.5e-7 off one face, for a gap 1.3e-7 instead of 1.5e-7). A foot is
            // taken only within `SEAM_REACH` times the point's distance from them: faces that
            // touch tangentially with relative curvature κ have their seam √(2d/κ) from a
            // point d off one of them, within reach unless κd < 2/SEAM_REACH².
            // And where y is already within the file's stated uncertainty of every entity
            // (one point, by the file's own definition, as the written mesh is measured),
            // only a seam the faces really share (to round-off) is worth a move: a foot
            // merely within the band is where the gap happens to be least.
            let reach = SEAM_REACH * off(x);
            let within_band = geometry.uncertainty.is_some_and(|u| left <= u);
            match crate::feature::foot_on_seam_of(geometry, entities, x, &guess) {
                Some(z) if distance(x, z) <= reach => {
                    let gap = off(z);
                    if gap < left && (!within_band || gap <= ON_SEAM * size) {
                        z
                    } else {
                        y
                    }
                }
                _ => y,
            }
        }
    }
}

/// Alternating projections onto each of `entities`, until the point settles to round-off;
/// with each entity's parameter of the last foot (`None` for closed forms, projected
/// without one).
fn alternating_projections(
    geometry: &GeometryModel,
    entities: &[usize],
    x: [f64; 3],
) -> ([f64; 3], Vec<Option<[f64; 2]>>) {
    let size = geometry.size().max(f64::MIN_POSITIVE);
    let mut y = x;
    // Each entity's parameter of its last foot: after a global inversion for the first, the
    // feet move little, and a local search from there finds the next (where two faces meet
    // at a grazing angle, hundreds of steps).
    let mut params: Vec<Option<[f64; 2]>> = vec![None; entities.len()];
    for _ in 0..200 {
        let before = y;
        for (&e, param) in entities.iter().zip(params.iter_mut()) {
            let entity = &geometry.entities[e];
            y = match *param {
                _ if entity.analytic.is_some() => entity.nearest_point(y),
                Some(guess) => {
                    let (foot, at) = entity.nearest_point_near(y, guess);
                    *param = Some(at);
                    foot
                }
                None => {
                    let found = entity.closest_point(y);
                    *param = Some(found.param);
                    found.point
                }
            };
        }
        if distance(before, y) <= 1e-14 * size {
            break;
        }
    }
    (y, params)
}
