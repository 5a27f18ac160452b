//! Cells split before curving (beyond the paper): a cell with two facets (a quadrilateral
//! with two edges) on one curved entity meeting at a corner opens to a 180° angle there
//! once curved, with det J = 0 whatever the interior nodes do; so does a tetrahedron's
//! corner whose three edges lie on curved facets with one tangent plane there
//! ([`flat_corner_splits`]), whatever facets the cell itself has.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_mesh::LinearMesh;

/// The quadrilaterals to split, each with the corner whose two edges lie on one curved
/// entity (the first such corner; a triangle left with two such edges is then split by
/// [`edges_opposite_doubly_curved_corners`]).
pub(crate) fn quadrilateral_corners_on_one_entity(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> Vec<(usize, usize)> {
    let facet_entity = facet_entities(linear, association);
    let mut out = Vec::new();
    for (c, cell) in linear.cells.iter().enumerate() {
        if cell.kind != hocurve_mesh::Shape::Quad || cell.vertices.len() != 4 {
            continue;
        }
        let v = &cell.vertices;
        let entity = |k: usize| {
            facet_entity
                .get(&sorted(&[v[k % 4], v[(k + 1) % 4]]))
                .copied()
        };
        // Corner k joins edges k − 1 and k.
        if let Some(k) = (0..4).find(|&k| entity(k + 3).is_some() && entity(k + 3) == entity(k)) {
            out.push((c, k));
        }
    }
    out
}

/// Vertex ids sorted (a facet's key whatever its orientation).
pub(crate) fn sorted(v: &[u32]) -> Vec<u32> {
    let mut v = v.to_vec();
    v.sort_unstable();
    v
}

/// The curved entity of each associated declared facet, keyed by its sorted vertices.
pub(crate) fn facet_entities(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> std::collections::HashMap<Vec<u32>, usize> {
    linear
        .facets
        .iter()
        .zip(&association.facet_entity)
        .filter_map(|(f, e)| e.map(|e| (sorted(&f.vertices), e)))
        .collect()
}

/// The hexahedra and prisms with two faces on one curved entity that share an edge: curved,
/// the dihedral angle there opens to 180° (det J = 0), and such cells cannot be split
/// conformingly like simplices and quadrilaterals. Indices into `linear.cells`.
pub(crate) fn cells_with_doubly_curved_edges(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> Vec<usize> {
    let facet_entity = facet_entities(linear, association);
    let mut out = Vec::new();
    for (c, cell) in linear.cells.iter().enumerate() {
        let shape = match cell.kind {
            hocurve_mesh::Shape::Hex => hocurve_nodes::Shape::Hex,
            hocurve_mesh::Shape::Prism => hocurve_nodes::Shape::Prism,
            _ => continue,
        };
        let faces: Vec<(Vec<u32>, Option<usize>)> = shape
            .faces()
            .iter()
            .map(|f| {
                let vertices: Vec<u32> = f.iter().map(|&k| cell.vertices[k]).collect();
                let entity = facet_entity.get(&sorted(&vertices)).copied();
                (vertices, entity)
            })
            .collect();
        let doubly = faces.iter().enumerate().any(|(i, (a, ea))| {
            faces[i + 1..].iter().any(|(b, eb)| {
                ea.is_some() && ea == eb && a.iter().filter(|v| b.contains(v)).count() >= 2
            })
        });
        if doubly {
            out.push(c);
        }
    }
    out
}

/// The edges to split so that no triangle or tetrahedron has two facets on one curved
/// entity — or on two entities that meet tangentially where the facets meet (a fillet and
/// the plane it runs into, a CAD face split along a smooth seam), which opens the cell's
/// corner to 180° just the same: for such a cell, the edge opposite the corner the two
/// facets share, unless that edge lies on a declared facet (splitting it would put a new
/// vertex on the boundary, off the geometry). Lower vertex id first, sorted, no repeats.
pub(crate) fn edges_opposite_doubly_curved_corners(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
    model: &hocurve_nurbs::GeometryModel,
) -> Vec<[u32; 2]> {
    let on_a_facet = |a: u32, b: u32| {
        linear
            .facets
            .iter()
            .any(|f| f.vertices.contains(&a) && f.vertices.contains(&b))
    };
    doubly_curved_corners(linear, association, model)
        .into_iter()
        .filter(|&[a, b]| !on_a_facet(a, b))
        .collect()
}

/// The facet edges opposite a simplex's doubly curved corner (see
/// [`edges_opposite_doubly_curved_corners`], which leaves them out), with the new vertex on
/// the geometry: where every facet holding the edge lies on one surface entity, at the
/// middle of the geodesic between its ends on it. A coarse rod (a cylinder meshed with a
/// handful of vertices round it) has tetrahedra with two facets on one half of it and the
/// opposite edge — a diameter — on the facets of the other half: no node placement on the
/// surface makes such a cell valid; split there, each half keeps one of the two facets
/// (`coarse_rod` in `fixtures/make_cad_fixtures.py`). Splits that would leave a
/// cell around the edge with less than a hundredth of its volume in either half are left
/// out ([`fair_splits`]). Lower vertex id first, sorted.
pub(crate) fn facet_edges_opposite_doubly_curved_corners(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
    model: &hocurve_nurbs::GeometryModel,
) -> Vec<([u32; 2], Option<[f64; 3]>)> {
    let entities_of = facet_edge_entities(linear, association);
    let mut positions: BTreeMap<[u32; 2], [f64; 3]> =
        doubly_curved_corners(linear, association, model)
            .into_iter()
            .filter_map(|edge| {
                let entities = entities_of.get(&edge)?;
                let (&Some(entity), 1) = (entities.first()?, entities.len()) else {
                    return None;
                };
                let (pa, pb) = (
                    linear.vertices[edge[0] as usize],
                    linear.vertices[edge[1] as usize],
                );
                Some((
                    edge,
                    midpoint_on_surface(model.entities.get(entity)?, pa, pb)?,
                ))
            })
            .collect();
    fair_splits(linear, &mut positions, 1e-2);
    positions.into_iter().map(|(e, q)| (e, Some(q))).collect()
}

/// The middle of the geodesic between `a` and `b` (points of it) on the surface `entity`:
/// where the curved facet edge's midpoint is placed. Not the point nearest the chord's
/// midpoint, which across half a cylinder is its axis, as near every point of the face
/// (the search lands on a corner). None for a curve.
fn midpoint_on_surface(
    entity: &hocurve_nurbs::GeometricEntity,
    a: [f64; 3],
    b: [f64; 3],
) -> Option<[f64; 3]> {
    let hocurve_nurbs::EntityGeometry::Surface(surface) = &entity.geometry else {
        return None;
    };
    let chart = hocurve_geodesic::SurfaceChart::new(surface);
    let (ua, ub) = chart.path_ends(entity.closest_point(a).param, entity.closest_point(b).param);
    let path = hocurve_geodesic::GeodesicPath::between(&chart, ua, ub, GEODESIC_TOLERANCE);
    let (_, x) = path.at_fraction(&chart, 0.5);
    // A closed form (cylinder, sphere...) has the exact point.
    Some(entity.nearest_point(x))
}

/// Relative length tolerance of [`midpoint_on_surface`]'s geodesic (the placement's).
const GEODESIC_TOLERANCE: f64 = 1e-10;

/// The edges opposite the corner two facets of a triangle or tetrahedron share when those
/// facets lie on one curved entity, or on two that meet tangentially there (see
/// [`edges_opposite_doubly_curved_corners`]). Lower vertex id first, sorted.
fn doubly_curved_corners(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
    model: &hocurve_nurbs::GeometryModel,
) -> BTreeSet<[u32; 2]> {
    let facet_entity = facet_entities(linear, association);
    let mut edges = BTreeSet::new();
    for cell in &linear.cells {
        if !matches!(
            cell.kind,
            hocurve_mesh::Shape::Tri | hocurve_mesh::Shape::Tet
        ) {
            continue;
        }
        let n = cell.vertices.len();
        // A simplex's facet k holds every vertex but vertex k.
        let entity: Vec<Option<usize>> = (0..n)
            .map(|skip| {
                let f: Vec<u32> = (0..n)
                    .filter(|&k| k != skip)
                    .map(|k| cell.vertices[k])
                    .collect();
                facet_entity.get(&sorted(&f)).copied()
            })
            .collect();
        let x = |k: usize| linear.vertices[cell.vertices[k] as usize];
        for i in 0..n {
            for j in i + 1..n {
                let (Some(ei), Some(ej)) = (entity[i], entity[j]) else {
                    continue;
                };
                // Facet i holds vertex j and facet j vertex i; both hold the rest.
                let shared: Vec<[f64; 3]> = (0..n).filter(|&k| k != i && k != j).map(x).collect();
                if ei != ej && !meet_tangentially(model, [ei, ej], &shared, [x(j), x(i)]) {
                    continue;
                }
                // Facets i and j share every vertex but i and j: the edge (i, j) is opposite
                // their common corner (an edge in a tetrahedron, a vertex in a triangle).
                let (a, b) = (cell.vertices[i], cell.vertices[j]);
                edges.insert([a.min(b), a.max(b)]);
            }
        }
    }
    edges
}

/// The largest angle (degrees) between two entities across their common edge (vertex, in
/// 2D) at which they count as meeting tangentially.
const TANGENT_DEGREES: f64 = 10.0;

/// Whether entities `pair[0]` and `pair[1]`, holding two facets of a cell that share the
/// points `shared` (an edge, or a vertex in 2D) and reach out to `far[0]` and `far[1]`
/// respectively, continue each other smoothly there: at every shared vertex (on both
/// entities), the directions into the two facets along the entities — a short step towards
/// the far vertex, projected onto the entity — across the shared edge are within
/// [`TANGENT_DEGREES`] of opposite. Measured in 3D, so poles and seams of the charts do not
/// matter; from the vertices, not the edge's midpoint, which a curved rim leaves off both.
fn meet_tangentially(
    model: &hocurve_nurbs::GeometryModel,
    pair: [usize; 2],
    shared: &[[f64; 3]],
    far: [[f64; 3]; 2],
) -> bool {
    use hocurve_nurbs::vec3::{add, dot, norm, reject, scale, sub};
    let (Some(a), Some(b)) = (model.entities.get(pair[0]), model.entities.get(pair[1])) else {
        return false;
    };
    let along = match shared {
        [p, q] => {
            let e = sub(*q, *p);
            let n = norm(e);
            if n.is_nan() || n <= 0.0 {
                return false;
            }
            Some(scale(e, 1.0 / n))
        }
        [_] => None,
        _ => return false,
    };
    let into = |entity: &hocurve_nurbs::GeometricEntity, base: [f64; 3], far: [f64; 3]| {
        let on = entity.nearest_point(base);
        let step = add(on, scale(sub(far, on), 1e-2));
        let d = sub(entity.nearest_point(step), on);
        let d = along.map_or(d, |e| reject(d, e));
        let n = norm(d);
        (n > 0.0).then(|| scale(d, 1.0 / n))
    };
    shared.iter().all(
        |&base| match (into(a, base, far[0]), into(b, base, far[1])) {
            (Some(da), Some(db)) => dot(da, db) < -TANGENT_DEGREES.to_radians().cos(),
            _ => false,
        },
    )
}

/// The surface edges to split, with the new vertex on the surface, so that no boundary
/// triangle has two edges on one feature curve: a coarsely split rim (a quarter-round of two
/// segments) leaves a facet through the arc's ends and its middle vertex, whose two edges on
/// the arc meet at 180° once curved — det J = 0 at that vertex in every cell on the facet,
/// whatever the interior nodes do. Splitting the facet's third edge (a surface edge of one
/// entity) at its midpoint moved onto the surface gives two facets with one rim edge each.
///
/// A corner qualifies when both its edges lie on the same set of two or more entities
/// (the facets holding each edge) and its vertex on exactly that set, so that the vertex is
/// inside their intersection curve, not a CAD corner. An edge is left alone when the moved
/// midpoint would leave a cell around it with less than a hundredth of its volume in either
/// half (a surface bending sharply over the edge). Lower vertex id first, sorted.
pub(crate) fn facet_edges_opposite_rim_corners(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
    model: &hocurve_nurbs::GeometryModel,
) -> Vec<([u32; 2], Option<[f64; 3]>)> {
    let key = |a: u32, b: u32| [a.min(b), a.max(b)];
    let mut edge_entities: BTreeMap<[u32; 2], BTreeSet<usize>> = BTreeMap::new();
    for (f, e) in linear.facets.iter().zip(&association.facet_entity) {
        let (Some(e), 3) = (*e, f.vertices.len()) else {
            continue;
        };
        for k in 0..3 {
            let (a, b) = (f.vertices[k], f.vertices[(k + 1) % 3]);
            edge_entities.entry(key(a, b)).or_default().insert(e);
        }
    }
    let entities_of = |a: u32, b: u32| edge_entities.get(&key(a, b));
    let mut wanted: BTreeMap<[u32; 2], usize> = BTreeMap::new();
    for (f, e) in linear.facets.iter().zip(&association.facet_entity) {
        let (Some(surface), 3) = (*e, f.vertices.len()) else {
            continue;
        };
        let v = &f.vertices;
        for k in 0..3 {
            let (c, a, b) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
            let (Some(ea), Some(eb), Some(opposite)) =
                (entities_of(c, a), entities_of(c, b), entities_of(a, b))
            else {
                continue;
            };
            let on_rim = ea.len() >= 2 && ea == eb;
            let inside_rim = association
                .vertex_entities
                .get(&c)
                .is_some_and(|list| list.iter().copied().eq(ea.iter().copied()));
            if on_rim && inside_rim && opposite.len() == 1 && opposite.contains(&surface) {
                wanted.insert(key(a, b), surface);
            }
        }
    }
    if wanted.is_empty() {
        return Vec::new();
    }
    let mut positions: BTreeMap<[u32; 2], [f64; 3]> = wanted
        .iter()
        .map(|(&[a, b], &surface)| {
            let (pa, pb) = (linear.vertices[a as usize], linear.vertices[b as usize]);
            let mid = [
                0.5 * (pa[0] + pb[0]),
                0.5 * (pa[1] + pb[1]),
                0.5 * (pa[2] + pb[2]),
            ];
            ([a, b], model.entities[surface].nearest_point(mid))
        })
        .collect();
    fair_splits(linear, &mut positions, 1e-2);
    positions.into_iter().map(|(e, q)| (e, Some(q))).collect()
}

/// Keeps only the split positions that leave both halves of every tetrahedron around their
/// edge at least the fraction `share` of its volume, with its orientation (a surface
/// bending sharply over the edge would fold one half, or leave it a sliver).
fn fair_splits(linear: &LinearMesh, positions: &mut BTreeMap<[u32; 2], [f64; 3]>, share: f64) {
    let key = |a: u32, b: u32| [a.min(b), a.max(b)];
    let mut keep: BTreeMap<[u32; 2], bool> = positions.keys().map(|&e| (e, true)).collect();
    for cell in &linear.cells {
        if cell.kind != hocurve_mesh::Shape::Tet || cell.vertices.len() != 4 {
            continue;
        }
        let v = &cell.vertices;
        for i in 0..4 {
            for j in i + 1..4 {
                let e = key(v[i], v[j]);
                let Some(&q) = positions.get(&e) else {
                    continue;
                };
                let x = |k: usize| linear.vertices[v[k] as usize];
                let parent = tet_volume([x(0), x(1), x(2), x(3)]);
                let with = |replaced: usize| {
                    let mut p = [x(0), x(1), x(2), x(3)];
                    p[replaced] = q;
                    tet_volume(p)
                };
                let fair = |child: f64| child * parent.signum() >= share * parent.abs();
                if !(parent != 0.0 && fair(with(i)) && fair(with(j))) {
                    keep.insert(e, false);
                }
            }
        }
    }
    positions.retain(|e, _| keep.get(e).copied().unwrap_or(false));
}

/// For each simplex among `cells` (positions in `linear`) that has no chord (see
/// [`longest_chords`]: all its vertices on one curved facet, or its boundary edges all on
/// facets), its longest edge on curved facets that the geometry bends (the midpoint moves
/// onto it by more than 1e-6 of the length), with the new vertex there: the midpoint moved
/// onto the facets' entity, or onto the intersection of their entities for an edge on a
/// feature curve. Curving folds such a cell where its curved facet spans too
/// much of the surface (a facet across a fillet, a hole rim of few segments) and no
/// interior chord is there to split; halving the facet's longest edge halves that span.
/// Splits that would leave a cell around the edge with less than a quarter of its volume
/// in either half (half of what the straight midpoint split leaves) are left out. Lower
/// vertex id first, sorted.
pub(crate) fn longest_curved_facet_edges(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
    model: &hocurve_nurbs::GeometryModel,
    cells: &[usize],
) -> Vec<([u32; 2], Option<[f64; 3]>)> {
    let key = |a: u32, b: u32| [a.min(b), a.max(b)];
    // The entities of the curved facets holding each facet edge.
    let mut edge_entities: BTreeMap<[u32; 2], BTreeSet<usize>> = BTreeMap::new();
    for (f, e) in linear.facets.iter().zip(&association.facet_entity) {
        let Some(e) = *e else {
            continue;
        };
        let v = &f.vertices;
        let n = v.len();
        let sides = if n == 2 { 1 } else { n };
        for k in 0..sides {
            edge_entities
                .entry(key(v[k], v[(k + 1) % n]))
                .or_default()
                .insert(e);
        }
    }
    let chords = longest_chord_of_each(linear, cells);
    let mut positions: BTreeMap<[u32; 2], [f64; 3]> = BTreeMap::new();
    for (&c, chord) in cells.iter().zip(chords) {
        let Some(cell) = linear.cells.get(c) else {
            continue;
        };
        if chord.is_some()
            || !matches!(
                cell.kind,
                hocurve_mesh::Shape::Tri | hocurve_mesh::Shape::Tet
            )
        {
            continue;
        }
        // The longest edge that the geometry bends: a straight one (a ruling of a
        // cylinder, however long) folds nothing.
        let v = &cell.vertices;
        let mut best: Option<(f64, [u32; 2], [f64; 3])> = None;
        for i in 0..v.len() {
            for j in i + 1..v.len() {
                let e = key(v[i], v[j]);
                let Some(on) = edge_entities.get(&e) else {
                    continue;
                };
                let entities: Vec<usize> = on.iter().copied().collect();
                let (pa, pb) = (
                    linear.vertices[e[0] as usize],
                    linear.vertices[e[1] as usize],
                );
                let mid = [
                    0.5 * (pa[0] + pb[0]),
                    0.5 * (pa[1] + pb[1]),
                    0.5 * (pa[2] + pb[2]),
                ];
                // On a CAD edge between faces, its midpoint by arc length (the faces may
                // meet tangentially, where no projection finds their edge); otherwise
                // the chord's midpoint snapped onto the entities.
                let target = |v: u32| {
                    association
                        .vertex_targets
                        .get(&v)
                        .copied()
                        .unwrap_or(linear.vertices[v as usize])
                };
                let q = hocurve_geodesic::feature::point_on_model_edge(
                    model,
                    &entities,
                    target(e[0]),
                    target(e[1]),
                    0.5,
                )
                .unwrap_or_else(|| hocurve_geodesic::association::snap_onto(model, &entities, mid));
                let sagitta = (0..3).map(|d| (q[d] - mid[d]).powi(2)).sum::<f64>().sqrt();
                let length = (0..3).map(|d| (pa[d] - pb[d]).powi(2)).sum::<f64>().sqrt();
                // (NaN from a degenerate edge is left out too.)
                let curved = sagitta > 1e-6 * length;
                if !curved {
                    continue;
                }
                if best.is_none_or(|(l, b, _)| length > l || (length == l && e < b)) {
                    best = Some((length, e, q));
                }
            }
        }
        if let Some((_, e, q)) = best {
            positions.insert(e, q);
        }
    }
    // At least half of what the straight midpoint split gives each half: refinement is
    // for cells that curving folds, a sliver child would be the next one.
    fair_splits(linear, &mut positions, 0.25);
    positions.into_iter().map(|(e, q)| (e, Some(q))).collect()
}

/// Six times the signed volume of a tetrahedron.
fn tet_volume(x: [[f64; 3]; 4]) -> f64 {
    let d = |i: usize| [x[i][0] - x[0][0], x[i][1] - x[0][1], x[i][2] - x[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// For each simplex among `cells` (positions in `linear`), its longest chord: an edge
/// between two vertices of declared facets that lies on no declared facet, so that it runs
/// through the domain. Such an edge is what curving squeezes: a cell whose edges on a curved
/// surface meet at a corner of one of its inner faces (or whose faces lie on two surfaces
/// near their junction) folds there when the surface bends towards the chord, and
/// splitting the chord at its midpoint (an interior vertex, off the boundary) gives two
/// cells with half the span each. Lower vertex id first, sorted, no repeats.
pub(crate) fn longest_chords(linear: &LinearMesh, cells: &[usize]) -> Vec<[u32; 2]> {
    let chords: BTreeSet<[u32; 2]> = longest_chord_of_each(linear, cells)
        .into_iter()
        .flatten()
        .collect();
    chords.into_iter().collect()
}

/// The longest chord (see [`longest_chords`]) of each of `cells`, in their order; `None`
/// for a cell without one (or not a simplex, or out of range).
pub(crate) fn longest_chord_of_each(linear: &LinearMesh, cells: &[usize]) -> Vec<Option<[u32; 2]>> {
    let mut on_boundary = vec![false; linear.vertices.len()];
    let mut facet_edges = BTreeSet::new();
    for f in &linear.facets {
        for &v in &f.vertices {
            if let Some(b) = on_boundary.get_mut(v as usize) {
                *b = true;
            }
        }
        let n = f.vertices.len();
        for k in 0..n {
            let (a, b) = (f.vertices[k], f.vertices[(k + 1) % n]);
            facet_edges.insert([a.min(b), a.max(b)]);
        }
    }
    let boundary = |v: u32| on_boundary.get(v as usize).copied().unwrap_or(false);
    let chord = |c: usize| -> Option<[u32; 2]> {
        let cell = linear.cells.get(c)?;
        if !matches!(
            cell.kind,
            hocurve_mesh::Shape::Tri | hocurve_mesh::Shape::Tet
        ) {
            return None;
        }
        let v = &cell.vertices;
        let mut best: Option<(f64, [u32; 2])> = None;
        for i in 0..v.len() {
            for j in i + 1..v.len() {
                let (a, b) = (v[i].min(v[j]), v[i].max(v[j]));
                if !boundary(a) || !boundary(b) || facet_edges.contains(&[a, b]) {
                    continue;
                }
                let (pa, pb) = (linear.vertices[a as usize], linear.vertices[b as usize]);
                let length = (0..3).map(|d| (pa[d] - pb[d]).powi(2)).sum::<f64>();
                // Ties go to the lower pair: the choice does not depend on the order of
                // the cell's vertices.
                if best.is_none_or(|(l, e)| length > l || (length == l && [a, b] < e)) {
                    best = Some((length, [a, b]));
                }
            }
        }
        best.map(|(_, e)| e)
    };
    cells.iter().map(|&c| chord(c)).collect()
}

/// The entities of the facets holding each facet edge (None for a facet on no curved
/// entity), keyed by its vertices, lower id first.
fn facet_edge_entities(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
) -> BTreeMap<[u32; 2], BTreeSet<Option<usize>>> {
    let mut entities_of: BTreeMap<[u32; 2], BTreeSet<Option<usize>>> = BTreeMap::new();
    for (f, e) in linear.facets.iter().zip(&association.facet_entity) {
        let n = f.vertices.len();
        for k in 0..n {
            let (a, b) = (f.vertices[k], f.vertices[(k + 1) % n]);
            entities_of
                .entry([a.min(b), a.max(b)])
                .or_default()
                .insert(*e);
        }
    }
    entities_of
}

/// A corner of a tetrahedron whose three edges in the cell all lie on curved facets
/// ([`flat_corners`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FlatCorner {
    /// Index into `linear.cells`.
    pub cell: usize,
    /// The corner's local vertex.
    pub corner: usize,
    /// What is left of the corner once curved, as a share of the straight one: the triple
    /// product of the unit directions in which the curved edges leave the vertex
    /// ([`curved_edge_direction`]) over that of the unit edge vectors. Zero or less where
    /// the facets' surfaces have one tangent plane at the vertex.
    pub share: f64,
    /// The two edges whose face keeps least of its corner, seen in the plane of the
    /// straight face: (a, b, (t_a × t_b) · (u_a × u_b) / |u_a × u_b|²), a and b indices
    /// among the corner's edges (to the other local vertices in increasing order), t the
    /// curved edges' unit directions and u the straight ones'. Zero or less where the two
    /// leave the vertex in opposite directions (the crest of a rounded rib spanned by one
    /// cell): |det J| there is at most |t_a × t_b| |t_c| in any cell that has both.
    pub pair: (usize, usize, f64),
}

impl FlatCorner {
    /// Whether curving flattens the corner: less than [`FLAT_CORNER`] of it is left.
    pub fn is_flat(&self) -> bool {
        self.share.is_nan() || self.share < FLAT_CORNER
    }

    /// The two edges that stay flat together (less than [`FLAT_CORNER`] of their face's
    /// corner left), if any: a half of the cell that keeps both stays flat, so only the
    /// edge between their far ends is worth splitting.
    pub fn flat_pair(&self) -> Option<(usize, usize)> {
        let (a, b, face) = self.pair;
        (face < FLAT_CORNER).then_some((a, b))
    }
}

/// The corners of tetrahedra whose three edges in the cell all lie on curved facets, with
/// what is left of each once curved ([`FlatCorner`]).
pub(crate) fn flat_corners(
    linear: &LinearMesh,
    entities_of: &BTreeMap<[u32; 2], BTreeSet<Option<usize>>>,
    model: &hocurve_nurbs::GeometryModel,
) -> Vec<FlatCorner> {
    use hocurve_nurbs::vec3::{cross, dot, norm, scale, sub};
    let key = |a: u32, b: u32| [a.min(b), a.max(b)];
    // The curved entities of the facets holding each facet edge (straight facets left out).
    let edge_entities: BTreeMap<[u32; 2], Vec<usize>> = entities_of
        .iter()
        .map(|(&e, set)| (e, set.iter().flatten().copied().collect::<Vec<usize>>()))
        .filter(|(_, entities)| !entities.is_empty())
        .collect();
    let unit = |d: [f64; 3]| {
        let n = norm(d);
        (n > 0.0 && n.is_finite()).then(|| scale(d, 1.0 / n))
    };
    // The direction of each curved edge at its first end, once per directed edge.
    let mut directions: BTreeMap<(u32, u32), Option<[f64; 3]>> = BTreeMap::new();
    let mut out = Vec::new();
    for (c, cell) in linear.cells.iter().enumerate() {
        if cell.kind != hocurve_mesh::Shape::Tet || cell.vertices.len() != 4 {
            continue;
        }
        let v = &cell.vertices;
        let x = |k: usize| linear.vertices[v[k] as usize];
        for k in 0..4 {
            let others: Vec<usize> = (0..4).filter(|&j| j != k).collect();
            let sets: Vec<&Vec<usize>> = others
                .iter()
                .filter_map(|&j| edge_entities.get(&key(v[k], v[j])))
                .collect();
            if sets.len() < 3 {
                continue;
            }
            let mut tangents = [[0.0; 3]; 3];
            let mut chords = [[0.0; 3]; 3];
            let mut ok = true;
            for (i, (&j, set)) in others.iter().zip(&sets).enumerate() {
                let tangent = *directions.entry((v[k], v[j])).or_insert_with(|| {
                    curved_edge_direction(model, set, x(k), x(j)).and_then(unit)
                });
                match (tangent, unit(sub(x(j), x(k)))) {
                    (Some(t), Some(u)) => {
                        tangents[i] = t;
                        chords[i] = u;
                    }
                    _ => ok = false,
                }
            }
            if !ok {
                continue;
            }
            let det = |a: [[f64; 3]; 3]| dot(a[0], cross(a[1], a[2]));
            let straight = det(chords);
            if straight == 0.0 || !straight.is_finite() {
                continue;
            }
            let face = |a: usize, b: usize| {
                let normal = cross(chords[a], chords[b]);
                dot(cross(tangents[a], tangents[b]), normal) / dot(normal, normal)
            };
            // (The straight corner is not flat, so no two chords are parallel.)
            let Some(pair) = [(0, 1), (0, 2), (1, 2)]
                .map(|(a, b)| (a, b, face(a, b)))
                .into_iter()
                .min_by(|p, q| p.2.total_cmp(&q.2))
            else {
                continue;
            };
            out.push(FlatCorner {
                cell: c,
                corner: k,
                share: det(tangents) / straight,
                pair,
            });
        }
    }
    out
}

/// Where the curved edge from `a` to `b` on `entities` (the entities of the facets holding
/// it) leaves `a`: its tangent there, from the points P at a twentieth and a tenth of the
/// way along its geodesic on one surface (or along the model's edge between several, or a
/// step towards `b` snapped onto the entities where neither is found) by Richardson's
/// extrapolation of the secants, 2 (P(h) − P(0))/h − (P(2h) − P(0))/(2h): second-order
/// accurate, where one secant leaves a flat corner's share at a few hundredths. Not
/// normalised.
fn curved_edge_direction(
    model: &hocurve_nurbs::GeometryModel,
    entities: &[usize],
    a: [f64; 3],
    b: [f64; 3],
) -> Option<[f64; 3]> {
    const STEP: f64 = 0.05;
    let extrapolated = |at: &dyn Fn(f64) -> Option<[f64; 3]>| {
        let (start, near, far) = (at(0.0)?, at(STEP)?, at(2.0 * STEP)?);
        Some(
            [0, 1, 2]
                .map(|i| 2.0 * (near[i] - start[i]) / STEP - (far[i] - start[i]) / (2.0 * STEP)),
        )
    };
    if let [e] = entities {
        let entity = model.entities.get(*e)?;
        if let hocurve_nurbs::EntityGeometry::Surface(surface) = &entity.geometry {
            let chart = hocurve_geodesic::SurfaceChart::new(surface);
            let (ua, ub) = (entity.closest_point(a).param, entity.closest_point(b).param);
            let path = hocurve_geodesic::GeodesicPath::between(&chart, ua, ub, GEODESIC_TOLERANCE);
            return extrapolated(&|t| Some(path.at_fraction(&chart, t).1));
        }
    }
    let on_edge = |t: f64| hocurve_geodesic::feature::point_on_model_edge(model, entities, a, b, t);
    if let Some(d) = extrapolated(&on_edge) {
        return Some(d);
    }
    let snap = |t: f64| {
        let p = [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
        Some(hocurve_geodesic::association::snap_onto(model, entities, p))
    };
    extrapolated(&snap)
}

/// What is left of a tetrahedron's corner once curved, as a share of the straight one,
/// below which the corner counts as flat ([`flat_corner_splits`]): the Ĩ below which a
/// certified cell is refined anyway ([`crate::pipeline::REFINE_BELOW`]).
const FLAT_CORNER: f64 = crate::pipeline::REFINE_BELOW;

/// The edges to split, with the new vertex's position, so that no tetrahedron keeps a
/// corner that curving flattens: a vertex whose three edges in the cell all lie on curved
/// facets of surfaces with one tangent plane there (one surface, or a fillet and the face
/// it runs into), whatever facets the cell itself has. Curved, those edges leave the
/// vertex in that plane, and det J there is the triple product of their directions — zero,
/// or of either sign once the edges bend ([`flat_corners`] measures it against the
/// straight corner's). Splitting an edge of the face opposite the vertex gives the vertex
/// an edge into the domain in each half: an edge through the domain (at its midpoint)
/// where that face has one, else a facet edge on one surface entity (at the middle of its
/// geodesic) — but where two of the edges leave the vertex in opposite directions (the
/// crest of a rounded rib spanned by one cell, [`FlatCorner::flat_pair`]) a half that
/// keeps both stays flat, so the edge between their far ends is the one split. Splits that
/// would leave a cell around the edge with less than a hundredth of its volume in either
/// half are left out ([`fair_splits`]).
pub(crate) fn flat_corner_splits(
    linear: &LinearMesh,
    association: &hocurve_geodesic::BoundaryAssociation,
    model: &hocurve_nurbs::GeometryModel,
) -> FlatCornerSplits {
    let key = |a: u32, b: u32| [a.min(b), a.max(b)];
    let entities_of = facet_edge_entities(linear, association);
    let length = |[a, b]: [u32; 2]| {
        let (pa, pb) = (linear.vertices[a as usize], linear.vertices[b as usize]);
        (0..3).map(|d| (pa[d] - pb[d]).powi(2)).sum::<f64>()
    };
    let mut positions: BTreeMap<[u32; 2], [f64; 3]> = BTreeMap::new();
    for corner in flat_corners(linear, &entities_of, model) {
        if !corner.is_flat() {
            continue;
        }
        let v = &linear.cells[corner.cell].vertices;
        let k = corner.corner;
        let face: Vec<u32> = (0..4).filter(|&j| j != k).map(|j| v[j]).collect();
        // The edge between the far ends of a flat pair; else the face's edges that can be
        // split — through the domain, or on facets of one surface entity — through the
        // domain first, longer first; ties go to the lower pair, so the choice does not
        // depend on the vertex order.
        let pairs: Vec<(usize, usize)> = match corner.flat_pair() {
            Some(pair) => vec![pair],
            None => vec![(0, 1), (0, 2), (1, 2)],
        };
        let mut candidates: Vec<(usize, usize, Option<usize>)> = Vec::new();
        for (i, j) in pairs {
            match entities_of.get(&key(face[i], face[j])) {
                None => candidates.push((i, j, None)),
                Some(set) => {
                    if let (Some(&Some(entity)), 1) = (set.first(), set.len()) {
                        candidates.push((i, j, Some(entity)));
                    }
                }
            }
        }
        let first = candidates.into_iter().min_by(|&(i, j, a), &(m, n, b)| {
            let (e, f) = (key(face[i], face[j]), key(face[m], face[n]));
            (a.is_some(), length(f), e)
                .partial_cmp(&(b.is_some(), length(e), f))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let Some((i, j, entity)) = first else {
            continue;
        };
        let (pa, pb) = (
            linear.vertices[face[i] as usize],
            linear.vertices[face[j] as usize],
        );
        let q = match entity {
            None => Some([0, 1, 2].map(|d| 0.5 * (pa[d] + pb[d]))),
            Some(entity) => model
                .entities
                .get(entity)
                .and_then(|entity| midpoint_on_surface(entity, pa, pb)),
        };
        if let Some(q) = q {
            positions.insert(key(face[i], face[j]), q);
        }
    }
    fair_splits(linear, &mut positions, 1e-2);
    let (through, on_surface): (Vec<_>, Vec<_>) = positions
        .into_iter()
        .map(|(e, q)| (e, Some(q)))
        .partition(|(e, _)| !entities_of.contains_key(e));
    FlatCornerSplits {
        through,
        on_surface,
    }
}

/// The splits of [`flat_corner_splits`]: edges through the domain, and facet edges with
/// the new vertex on their surface.
pub(crate) struct FlatCornerSplits {
    pub through: Vec<([u32; 2], Option<[f64; 3]>)>,
    pub on_surface: Vec<([u32; 2], Option<[f64; 3]>)>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    use hocurve_mesh::{Element, Shape};

    /// One tetrahedron 0 1 2 3 with the facets 0 1 2 and 0 1 3 declared.
    fn tet_with_two_facets() -> LinearMesh {
        let facet = |v: [u32; 3]| Element {
            kind: Shape::Tri,
            vertices: v.to_vec(),
            entity: 1,
        };
        LinearMesh {
            facets: vec![facet([0, 1, 2]), facet([0, 3, 1])],
            ..hocurve_testmeshes::unit_tet()
        }
    }

    fn association(facet_entity: Vec<Option<usize>>) -> hocurve_geodesic::BoundaryAssociation {
        hocurve_geodesic::BoundaryAssociation {
            facet_entity,
            vertex_targets: BTreeMap::new(),
            vertex_entities: BTreeMap::new(),
            tolerance: 0.0,
            by_name: 2,
            by_proximity: 0,
            unassociated: 0,
            max_vertex_move: 0.0,
        }
    }

    /// The planes z = 0 and y = 0 (bilinear patches over [−2, 2]²), and the cylinder about
    /// the line y = 0, z = 0.5 along x of radius 0.5, tangent to z = 0 along the x axis.
    fn planes_and_tangent_cylinder() -> hocurve_nurbs::GeometryModel {
        use hocurve_nurbs::{EntityGeometry, GeometricEntity};
        let plane = |corner: fn(f64, f64) -> [f64; 3]| {
            let s = hocurve_nurbs::shapes::bilinear_patch([
                [corner(-2.0, -2.0), corner(-2.0, 2.0)],
                [corner(2.0, -2.0), corner(2.0, 2.0)],
            ])
            .expect("plane");
            EntityGeometry::Surface(s)
        };
        let cylinder =
            hocurve_nurbs::shapes::cylinder([0.0, 0.0, 0.5], [1.0, 0.0, 0.0], 0.5, (-2.0, 2.0))
                .expect("cylinder");
        hocurve_nurbs::GeometryModel::new(
            vec![
                GeometricEntity::new("z0", "test", plane(|a, b| [a, b, 0.0])),
                GeometricEntity::new("y0", "test", plane(|a, b| [a, 0.0, b])),
                GeometricEntity::new("fillet", "test", EntityGeometry::Surface(cylinder)),
            ],
            None,
        )
    }

    #[test]
    fn a_cell_with_two_facets_on_one_entity_has_its_opposite_edge_split() {
        let mesh = tet_with_two_facets();
        let model = planes_and_tangent_cylinder();
        // Both facets on entity 0: they share the edge 0 1; the opposite edge is 2 3.
        let edges =
            edges_opposite_doubly_curved_corners(&mesh, &association(vec![Some(0); 2]), &model);
        assert_eq!(edges, vec![[2, 3]]);
        // On planes meeting at 90° (a feature edge), or one straight: nothing to split.
        for entities in [vec![Some(0), Some(1)], vec![Some(0), None]] {
            let edges = edges_opposite_doubly_curved_corners(&mesh, &association(entities), &model);
            assert!(edges.is_empty());
        }
        // Facet 0 3 1 on a fillet that runs tangentially into the plane z = 0 along the
        // edge 0 1 (vertex 3 moved onto it, 90° round): the corner opens to 180° as on one
        // entity.
        let mut filleted = mesh.clone();
        filleted.vertices[3] = [0.0, -0.5, 0.5];
        let edges = edges_opposite_doubly_curved_corners(
            &filleted,
            &association(vec![Some(0), Some(2)]),
            &model,
        );
        assert_eq!(edges, vec![[2, 3]]);
        // An opposite edge on a declared facet is left alone (its midpoint would be a new
        // boundary vertex off the geometry).
        let mut with_third = mesh.clone();
        with_third.facets.push(Element {
            kind: Shape::Tri,
            vertices: vec![1, 2, 3],
            entity: 2,
        });
        let edges = edges_opposite_doubly_curved_corners(
            &with_third,
            &association(vec![Some(0), Some(0), None]),
            &model,
        );
        assert!(edges.is_empty());
    }

    /// A cap (the plane z = 0) meeting at a curved rim a side that flares outwards (the
    /// cone from r = 1 at z = 0 to r = 1.5 at z = 1, its patch ending at the rim): they meet
    /// at about 63°, not tangentially. The chord's midpoint lies inside the rim, where the
    /// side's closest points all fall on the patch's end: measured from there, both
    /// directions were along the rim and the pair looked tangent.
    #[test]
    fn a_cap_meeting_a_flared_side_at_a_curved_rim_is_not_tangent() {
        use hocurve_nurbs::{EntityGeometry, GeometricEntity, NurbsSurface};
        let circle = |r: f64, z: f64| {
            hocurve_nurbs::shapes::circle([0.0, 0.0, z], [0.0, 0.0, 1.0], r).expect("circle")
        };
        let (bottom, top) = (circle(1.0, 0.0), circle(1.5, 1.0));
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (p, q) in bottom.control_points.iter().zip(&top.control_points) {
            points.extend([*p, *q]);
        }
        for w in &bottom.weights {
            weights.extend([*w, *w]);
        }
        let side = NurbsSurface::new(
            bottom.degree,
            1,
            bottom.knots.clone(),
            vec![0.0, 0.0, 1.0, 1.0],
            points,
            weights,
        )
        .expect("cone");
        let mut model = planes_and_tangent_cylinder();
        model.entities.push(GeometricEntity::new(
            "flared",
            "test",
            EntityGeometry::Surface(side),
        ));
        let rim = |t: f64| [t.cos(), t.sin(), 0.0];
        let shared = [rim(0.0), rim(1.0)];
        let cap_far = [0.2, 0.3, 0.0];
        let side_far = [1.25 * 0.5f64.cos(), 1.25 * 0.5f64.sin(), 0.5];
        assert!(!meet_tangentially(
            &model,
            [0, 3],
            &shared,
            [cap_far, side_far]
        ));
        // The plane and the cylinder tangent to it along the x axis are.
        let shared = [[0.0; 3], [1.0, 0.0, 0.0]];
        assert!(meet_tangentially(
            &model,
            [0, 2],
            &shared,
            [[0.5, 1.0, 0.0], [0.5, -0.5, 0.5]]
        ));
    }

    #[test]
    fn the_longest_chord_of_a_cell_is_its_longest_edge_through_the_domain() {
        // The unit tet 0 (origin), 1, 2, 3 (unit axes) with its facet 0 1 2 declared, and
        // vertex 3 on a declared facet of a neighbour: the chords are 0 3, 1 3 and 2 3
        // (both ends on the boundary, on no facet), and 1 3, 2 3 (length √2) beat 0 3
        // (length 1); the tie goes to the lower pair.
        let facet = |v: [u32; 3]| Element {
            kind: Shape::Tri,
            vertices: v.to_vec(),
            entity: 1,
        };
        let mut mesh = hocurve_testmeshes::unit_tet();
        mesh.vertices.extend([[1.0, 1.0, 1.0], [0.0, 1.0, 1.0]]);
        mesh.facets = vec![facet([0, 1, 2]), facet([3, 4, 5])];
        assert_eq!(longest_chords(&mesh, &[0]), vec![[1, 3]]);
        // The same cell with its vertices listed in another order: the same chord.
        let mut turned = mesh.clone();
        turned.cells[0].vertices = vec![3, 2, 1, 0];
        assert_eq!(longest_chords(&turned, &[0]), vec![[1, 3]]);
        // Vertex 3 inside the domain: every edge through the domain has an interior end.
        mesh.facets.truncate(1);
        assert!(longest_chords(&mesh, &[0]).is_empty());
        // Cells not asked about, or out of range, give nothing.
        assert!(longest_chords(&turned, &[]).is_empty());
        assert!(longest_chords(&turned, &[7]).is_empty());
        assert_eq!(
            longest_chord_of_each(&turned, &[0, 7, 0]),
            vec![Some([1, 3]), None, Some([1, 3])]
        );
    }

    #[test]
    fn a_cell_without_a_chord_gets_its_longest_curved_facet_edge_split_on_the_surface() {
        use hocurve_nurbs::shapes::AnalyticShape;
        use hocurve_nurbs::{EntityGeometry, GeometricEntity};
        // The unit cylinder about z; a tet with its facet A B C on it and D inside: A B a
        // ruling of length 5 (straight: splitting it would change nothing), A C and B C
        // curved (length 2.59, C 40° round at mid-height). The tie goes to the lower pair,
        // A C, split at its midpoint pushed out onto the cylinder: (cos 20°, sin 20°, 1.25).
        let nurbs = hocurve_nurbs::shapes::cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0, (-1.0, 6.0))
            .expect("cylinder");
        let mut cylinder = GeometricEntity::new("side", "test", EntityGeometry::Surface(nurbs));
        cylinder.analytic =
            Some(AnalyticShape::new_cylinder([0.0; 3], [0.0, 0.0, 1.0], 1.0).expect("cylinder"));
        let model = hocurve_nurbs::GeometryModel::new(vec![cylinder], None);
        let theta = 40f64.to_radians();
        let mut mesh = hocurve_testmeshes::unit_tet();
        mesh.vertices = vec![
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 5.0],
            [theta.cos(), theta.sin(), 2.5],
            [0.3, 0.2, 2.5],
        ];
        // Outward (towards +x) normal: A C B.
        mesh.cells[0].vertices = vec![0, 1, 2, 3];
        mesh.facets = vec![Element {
            kind: Shape::Tri,
            vertices: vec![0, 2, 1],
            entity: 1,
        }];
        let found = association(vec![Some(0)]);
        let splits = longest_curved_facet_edges(&mesh, &found, &model, &[0]);
        let [([0, 2], Some(q))] = splits[..] else {
            panic!("{splits:?}");
        };
        let half = 0.5 * theta;
        let expected = [half.cos(), half.sin(), 1.25];
        assert!((0..3).all(|d| (q[d] - expected[d]).abs() < 1e-14), "{q:?}");
        // Cells not asked about give nothing; nor does a cell with a chord (D on a
        // neighbour's facet: A D, B D, C D run through the domain).
        assert!(longest_curved_facet_edges(&mesh, &found, &model, &[]).is_empty());
        mesh.vertices.push([0.0, 0.0, 9.0]);
        mesh.vertices.push([0.0, 1.0, 9.0]);
        mesh.facets.push(Element {
            kind: Shape::Tri,
            vertices: vec![3, 4, 5],
            entity: 1,
        });
        let found = association(vec![Some(0), None]);
        assert!(longest_curved_facet_edges(&mesh, &found, &model, &[0]).is_empty());
    }

    /// The crest of a rounded rib spanned by one cell: a tetrahedron k a b c whose edges k a
    /// and k b run over a cylinder (axis y, radius 1) from its top k = (0, 0, 1) down to
    /// either side, a = (−1, 0, 0) and b = (1, 0, 0), and k c along its top. Curved, k a and
    /// k b leave k in opposite directions, so any half that keeps both stays flat: of the
    /// opposite face's edges through the domain, b c is the longer, but only splitting a b
    /// (at the axis) opens the corner in both halves.
    #[test]
    fn a_crest_between_two_curved_edges_is_split_between_their_ends() {
        use hocurve_nurbs::{EntityGeometry, GeometricEntity};
        let cylinder =
            hocurve_nurbs::shapes::cylinder([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, (-2.0, 4.0))
                .expect("cylinder");
        let model = hocurve_nurbs::GeometryModel::new(
            vec![GeometricEntity::new(
                "rib",
                "test",
                EntityGeometry::Surface(cylinder),
            )],
            None,
        );
        let facet = |v: [u32; 3]| Element {
            kind: Shape::Tri,
            vertices: v.to_vec(),
            entity: 1,
        };
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut mesh = LinearMesh {
            dim: 3,
            // k, a, b, c, and d beside b (for a facet k b d outside the cell).
            vertices: vec![
                [0.0, 0.0, 1.0],
                [-1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 3.0, 1.0],
                [h, -1.0, h],
            ],
            cells: vec![Element {
                kind: Shape::Tet,
                vertices: vec![0, 1, 2, 3],
                entity: 1,
            }],
            facets: vec![facet([0, 1, 3]), facet([0, 2, 4])],
            ..Default::default()
        };
        if mesh.check_orientation().is_err() {
            mesh.cells[0].vertices.swap(1, 2);
        }
        assert!(mesh.check_orientation().is_ok());
        let found = association(vec![Some(0), Some(0)]);
        let corners = flat_corners(&mesh, &facet_edge_entities(&mesh, &found), &model);
        // Only k has its three edges on facets (a and c have two, b one).
        assert_eq!(corners.len(), 1, "{corners:?}");
        let crest = corners[0];
        let v = &mesh.cells[crest.cell].vertices;
        assert_eq!(v[crest.corner], 0);
        assert!(crest.share.abs() < 1e-2, "share {}", crest.share);
        // The flat pair is k a, k b: t_a = −t_b, so nothing is left of their face's corner.
        let (i, j) = crest.flat_pair().expect("a flat pair");
        let others: Vec<u32> = (0..4)
            .filter(|&m| m != crest.corner)
            .map(|m| v[m])
            .collect();
        let mut ends = [others[i], others[j]];
        ends.sort_unstable();
        assert_eq!(ends, [1, 2]);
        assert!(crest.pair.2.abs() < 1e-2, "face {}", crest.pair.2);
        // b c (length √11) is longer than a b (2), and neither lies on a facet.
        let splits = flat_corner_splits(&mesh, &found, &model);
        assert!(splits.on_surface.is_empty());
        assert_eq!(splits.through.len(), 1, "{:?}", splits.through);
        assert_eq!(splits.through[0].0, [1, 2]);
        let q = splits.through[0].1.expect("a position");
        assert!(q.iter().all(|x| x.abs() < 1e-15), "{q:?}");
    }

    /// A tetrahedron with one facet on the plane z = 0 whose corner at the origin has its
    /// third edge on a facet of another cell: on the cylinder tangent to that plane along
    /// the x axis (a fillet), the corner is flat once curved and an edge of the opposite
    /// face through the domain is split; on the plane y = 0 (meeting z = 0 at 90°) the
    /// corner keeps its shape and nothing is split.
    #[test]
    fn a_corner_on_a_fillets_tangent_edge_is_flat_and_split() {
        let facet = |v: [u32; 3]| Element {
            kind: Shape::Tri,
            vertices: v.to_vec(),
            entity: 1,
        };
        let model = planes_and_tangent_cylinder();
        for (far, entity, flat) in [
            ([[0.5, 0.5, 0.5], [1.0, 0.5, 0.5]], 2, true),
            ([[0.5, 0.0, 0.5], [1.0, 0.0, 0.8]], 1, false),
        ] {
            let mesh = LinearMesh {
                dim: 3,
                vertices: vec![
                    [0.0, 0.0, 0.0],
                    [1.0, 0.0, 0.0],
                    [0.5, -1.0, 0.0],
                    far[0],
                    far[1],
                ],
                cells: vec![Element {
                    kind: Shape::Tet,
                    vertices: vec![0, 2, 1, 3],
                    entity: 1,
                }],
                facets: vec![facet([0, 1, 2]), facet([0, 3, 4])],
                ..Default::default()
            };
            assert!(mesh.check_orientation().is_ok());
            let found = association(vec![Some(0), Some(entity)]);
            let corners = flat_corners(&mesh, &facet_edge_entities(&mesh, &found), &model);
            // Only the origin has its three edges on facets.
            assert_eq!(corners.len(), 1, "{corners:?}");
            let FlatCorner {
                cell,
                corner: k,
                share,
                ..
            } = corners[0];
            assert_eq!((cell, k), (0, 0));
            if flat {
                assert!(share.abs() < 1e-2, "share {share}");
            } else {
                assert!((share - 1.0).abs() < 1e-9, "share {share}");
            }
            let splits = flat_corner_splits(&mesh, &found, &model);
            assert!(splits.on_surface.is_empty());
            if flat {
                // The longer of 1–3 and 2–3, neither on a facet.
                assert_eq!(splits.through.len(), 1);
                assert_eq!(splits.through[0].0, [2, 3]);
            } else {
                assert!(splits.through.is_empty());
            }
        }
    }
}
