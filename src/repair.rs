//! Repair of the elements the certification did not find valid (beyond the paper, whose
//! elastic analogy does not guarantee det J > 0): the nodes around them that lie on no
//! boundary (or slide on a plane, within it, or lie inside a plane face of the geometry,
//! within that) are untangled by a Jacobian-barrier optimisation ([`hocurve_untangle`]),
//! the boundary nodes staying on the geometry, in
//! patches that widen by one ring of cells per round (at most [`MAX_UNTANGLE_RINGS`]) until
//! every element is certified. Then valid elements certified with a poor Ĩ are reshaped by
//! the same optimisation ([`reshape_poor_elements`]).

use std::collections::{BTreeMap, BTreeSet};

use hocurve_mesh::{HighOrderMesh, Shape};
use hocurve_quality::{MeshQuality, Sampling, Validity};
use hocurve_untangle::{untangle_sliding, NodeConstraint, UntangleOptions};

use crate::pipeline::{invalid_cells, CurveError};

/// Rings of neighbouring cells the widest untangling patch reaches.
pub const MAX_UNTANGLE_RINGS: usize = 3;

/// What the untangling did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Untangling {
    /// Elements not certified valid when the untangling started.
    pub elements: usize,
    /// Rounds run (patch rings 1, 2, ...).
    pub rounds: usize,
}

/// The elements with det J ≤ 0 found, or that the Bézier check left undecided.
pub fn not_certified(quality: &MeshQuality) -> Vec<usize> {
    let mut cells: BTreeSet<usize> = invalid_cells(quality).into_iter().collect();
    if let Some(checks) = &quality.validity {
        cells.extend(
            checks
                .iter()
                .enumerate()
                .filter(|(_, c)| c.validity == Validity::Undecided)
                .map(|(e, _)| e),
        );
    }
    cells.into_iter().collect()
}

/// A cell touching the curved boundary this stretched (longest over shortest edge, the
/// paper's Sect. 5 measure) marks a boundary-layer mesh: isotropic tetrahedral meshes stay
/// below ~5, wall layers reach 10²–10⁴.
pub const LAYER_STRETCH: f64 = 10.0;

/// Whether the straight mesh has boundary-layer structure: a cell with a node in `targets`
/// (on the curved boundary) stretched by at least [`LAYER_STRETCH`]. Such meshes get the
/// [`jacobian_stiffening`] in their first solve (issue 21: thin cells at the wall must move
/// rigidly rather than shear).
pub fn has_boundary_layer(
    straight: &HighOrderMesh,
    targets: &std::collections::BTreeMap<u32, [f64; 3]>,
) -> Result<bool, hocurve_quality::QualityError> {
    let stretching = hocurve_quality::stretching(straight)?;
    Ok(straight
        .cells
        .iter()
        .zip(&stretching)
        .any(|(cell, &s)| s >= LAYER_STRETCH && cell.nodes.iter().any(|n| targets.contains_key(n))))
}

/// Tezduyar's Jacobian-based stiffening: cell c's Young's modulus scaled by
/// max_k |J_k| / |J_c| (≥ 1), J_c the Jacobian of c's straight shape at its first vertex,
/// so that small cells (the thin layers at a wall) move rigidly instead of absorbing the
/// boundary's displacement by shearing.
pub fn jacobian_stiffening(straight: &HighOrderMesh) -> Vec<f64> {
    let corner = |cell: &hocurve_mesh::HighOrderElement| -> f64 {
        // The vertices joined to vertex 0 by an edge, in Gmsh's vertex order.
        let neighbours: &[usize] = match cell.kind {
            Shape::Quad => &[1, 3],
            Shape::Hex => &[1, 3, 4],
            Shape::Tri => &[1, 2],
            _ => &[1, 2, 3],
        };
        let x = |k: usize| straight.nodes[cell.nodes[k] as usize];
        let mut m = [[0.0, 0.0, 1.0_f64]; 3];
        for (row, &k) in m.iter_mut().zip(neighbours) {
            *row = [x(k)[0] - x(0)[0], x(k)[1] - x(0)[1], x(k)[2] - x(0)[2]];
        }
        (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
            .abs()
    };
    let jacobians: Vec<f64> = straight.cells.iter().map(corner).collect();
    let largest = jacobians.iter().copied().fold(0.0, f64::max);
    jacobians
        .iter()
        .map(|&j| {
            let s = largest / j;
            // A degenerate straight cell (rejected on input) would give ∞: left as it is.
            if s.is_finite() {
                s.max(1.0)
            } else {
                1.0
            }
        })
        .collect()
}

/// A plane: a point of it and its unit normal.
pub(crate) type Plane = ([f64; 3], [f64; 3]);

/// The nodes placed on the geometry whose entities are all one plane (a plane face, or
/// coplanar faces of an assembly's parts, not where a plane meets another surface), with
/// that plane (a point, the unit normal): the repair may move them within it and they stay
/// on the geometry. A curved facet edge whose vertex's other facet edge runs along the
/// curve's tangent there (a plane's mesh vertex on the tangent of a hole's rim at a rim
/// vertex) closes that facet's corner to 0° once curved, whatever the free nodes do; bent
/// within the plane, the straight edge opens it again.
pub(crate) fn nodes_in_planar_faces(
    model: &hocurve_nurbs::GeometryModel,
    entities: &BTreeMap<u32, Vec<usize>>,
) -> BTreeMap<u32, Plane> {
    let mut planes: BTreeMap<usize, Option<Plane>> = BTreeMap::new();
    let mut plane_of = |entity: usize| {
        *planes.entry(entity).or_insert_with(|| {
            match model.entities.get(entity).map(|e| &e.geometry) {
                Some(hocurve_nurbs::EntityGeometry::Surface(s)) => s.plane(),
                _ => None,
            }
        })
    };
    // Coplanar: normals parallel, and each plane through the other's point, to round-off.
    let reach = 1e-9 * model.size();
    let coplanar = |(p, n): Plane, (q, m): Plane| {
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let offset = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        dot(n, m).abs() >= 1.0 - 1e-12 && dot(offset, n).abs() <= reach
    };
    entities
        .iter()
        .filter_map(|(&node, on)| {
            let (&first, rest) = on.split_first()?;
            let plane = plane_of(first)?;
            for &other in rest {
                if !coplanar(plane, plane_of(other)?) {
                    return None;
                }
            }
            Some((node, plane))
        })
        .collect()
}

/// Untangles the patches around the elements of `mesh` that `quality` does not certify,
/// widening them round by round, and returns the quality of the repaired mesh (measured by
/// `assess`, which must certify). `straight` holds the straight-sided node positions (the
/// shapes aimed at); `on_geometry` the nodes placed on the geometry, which stay where they
/// are — but for those in `in_planes` (see [`nodes_in_planar_faces`]), which move within
/// their plane and are put back onto it exactly after each round — like every other
/// boundary node except the `sliding` ones, which move within their plane or line;
/// `hopeless` the cells no node move can make valid (two faces on one curved entity
/// meeting along an edge), which are not tried; nor are cells folded where held nodes
/// alone shape them ([`invalid_where_held`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn untangle_not_certified(
    mesh: &mut HighOrderMesh,
    straight: &[[f64; 3]],
    on_geometry: impl IntoIterator<Item = u32>,
    in_planes: &BTreeMap<u32, Plane>,
    sliding: &BTreeMap<u32, NodeConstraint>,
    hopeless: &[usize],
    mut quality: MeshQuality,
    assess: &dyn Fn(&HighOrderMesh) -> Result<MeshQuality, CurveError>,
) -> Result<(MeshQuality, Untangling), CurveError> {
    let mut done = Untangling::default();
    // Cells whose det J vanishes on a boundary edge whatever the free nodes do are left out.
    let repairable = |quality: &MeshQuality| -> Vec<usize> {
        not_certified(quality)
            .into_iter()
            .filter(|c| !hopeless.contains(c))
            .collect()
    };
    let mut bad = repairable(&quality);
    if bad.is_empty() || quality.validity.is_none() {
        return Ok((quality, done));
    }
    let mut sliding = sliding.clone();
    for (&node, &(_, normal)) in in_planes {
        sliding.entry(node).or_insert(NodeConstraint::Plane(normal));
    }
    let on_geometry = on_geometry
        .into_iter()
        .filter(|n| !in_planes.contains_key(n));
    let fixed = held_nodes(mesh, on_geometry, &sliding)?;
    let mut held = vec![false; mesh.nodes.len()];
    for &n in &fixed {
        if let Some(h) = held.get_mut(n as usize) {
            *h = true;
        }
    }
    // Cells folded where only held nodes shape them are left to the refinement: each
    // round would run the optimiser to its limit on them in vain.
    let beyond_reach = invalid_where_held(mesh, &bad, &held)?;
    bad.retain(|c| !beyond_reach.contains(c));
    if bad.is_empty() {
        return Ok((quality, done));
    }
    done.elements = bad.len();
    for rings in 1..=MAX_UNTANGLE_RINGS {
        let options = UntangleOptions {
            rings,
            ..UntangleOptions::default()
        };
        untangle_sliding(mesh, straight, &bad, &fixed, &sliding, &options)?;
        // Moves along the plane leave a node off it by round-off: put back exactly.
        for (&node, &(point, normal)) in in_planes {
            if let Some(x) = mesh.nodes.get_mut(node as usize) {
                let off: f64 = (0..3).map(|d| (x[d] - point[d]) * normal[d]).sum();
                for d in 0..3 {
                    x[d] -= off * normal[d];
                }
            }
        }
        done.rounds = rings;
        quality = assess(mesh)?;
        bad = repairable(&quality);
        bad.retain(|c| !beyond_reach.contains(c));
        if bad.is_empty() {
            break;
        }
    }
    Ok((quality, done))
}

/// Reference points of a cell's edges (fractions of the edge from its first vertex) at
/// which [`invalid_where_held`] looks, besides the vertices.
const EDGE_SAMPLES: [f64; 3] = [0.25, 0.5, 0.75];

/// The cells of `cells` with det J ≤ 0 at a point where the map is shaped by held nodes
/// alone (`held[n]`): at a vertex, J is the derivatives along its edges, which the nodes of
/// those edges fix; on an edge, the derivatives along the two faces meeting there. Where
/// every node whose basis function has a gradient there is held, no move of the free
/// nodes changes det J, so untangling cannot make the cell valid (splitting it can): a
/// tetrahedron's corner whose three edges lie on the geometry and open flat once curved, a
/// 2D cell's corner on two curved boundary edges. Which nodes matter is read off the
/// basis (gradients above 1e-9 of the largest at the point), for every shape and family.
pub(crate) fn invalid_where_held(
    mesh: &HighOrderMesh,
    cells: &[usize],
    held: &[bool],
) -> Result<Vec<usize>, CurveError> {
    let mut tables = BTreeMap::new();
    let mut out = Vec::new();
    for &c in cells {
        let Some(cell) = mesh.cells.get(c) else {
            continue;
        };
        let shape = cell.kind;
        if let std::collections::btree_map::Entry::Vacant(slot) = tables.entry(shape) {
            let reference =
                hocurve_nodes::ReferenceElement::shared(shape, mesh.order, mesh.family)?;
            let vertices = shape.vertices();
            let mut points: Vec<[f64; 3]> = vertices.to_vec();
            for &[a, b] in shape.edges() {
                for t in EDGE_SAMPLES {
                    points.push(std::array::from_fn(|d| {
                        vertices[a][d] + t * (vertices[b][d] - vertices[a][d])
                    }));
                }
            }
            let basis = reference.tabulate(&points);
            // The local nodes whose basis functions have a gradient at each point.
            let shaping: Vec<Vec<usize>> = (0..points.len())
                .map(|q| {
                    let g = basis.gradients(q);
                    let size = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
                    let largest = g.iter().map(size).fold(0.0, f64::max);
                    (0..g.len())
                        .filter(|&i| size(&g[i]) > 1e-9 * largest)
                        .collect()
                })
                .collect();
            slot.insert((basis, shaping));
        }
        let (basis, shaping) = &tables[&shape];
        let coords: Vec<[f64; 3]> = cell.nodes.iter().map(|&n| mesh.nodes[n as usize]).collect();
        let fixed_and_folded = shaping.iter().enumerate().any(|(q, nodes)| {
            nodes
                .iter()
                .all(|&i| held.get(cell.nodes[i] as usize) == Some(&true))
                && hocurve_nodes::determinant(&basis.jacobian(&coords, q), mesh.dim) <= 0.0
        });
        if fixed_and_folded {
            out.push(c);
        }
    }
    Ok(out)
}

/// The nodes a repair must not move (sorted): those on the geometry and every other
/// boundary node except the ones sliding on a plane or line (`sliding`), which move only
/// within it.
fn held_nodes(
    mesh: &HighOrderMesh,
    on_geometry: impl IntoIterator<Item = u32>,
    sliding: &BTreeMap<u32, NodeConstraint>,
) -> Result<Vec<u32>, CurveError> {
    let on_geometry: BTreeSet<u32> = on_geometry.into_iter().collect();
    let mut fixed = on_geometry.clone();
    fixed.extend(
        mesh.boundary_facet_nodes()?
            .into_iter()
            .flat_map(|(_, nodes)| nodes)
            .filter(|n| !sliding.contains_key(n)),
    );
    Ok(fixed.into_iter().collect())
}

/// Certified Ĩ below which a valid element is reshaped after the solve (see
/// [`reshape_poor_elements`]): the quality the issue tracker asks of boundary-layer meshes
/// with stretch ≥ 1000 is 0.2, the paper's hardest case reached 0.015.
pub const RESHAPE_BELOW: f64 = 0.3;

/// What the reshaping of poor elements did.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Reshaping {
    /// Valid elements certified below the threshold after the solve.
    pub elements: usize,
    /// Whether the reshaped mesh was kept (it raised the certified min Ĩ).
    pub kept: bool,
    /// Certified min Ĩ before and after (equal when not kept).
    pub min_before: f64,
    /// See `min_before`.
    pub min_after: f64,
}

/// The smallest certified lower bound of Ĩ (a NaN bound counts as −∞).
fn certified_minimum(quality: &MeshQuality) -> f64 {
    crate::correction_choice::certified_scaled_jacobians(quality)
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// Beyond validity: when every element is certified valid but some only with Ĩ below
/// `threshold`, the free nodes around them (and sliding boundary nodes, within their
/// planes) are moved by the same distortion-energy optimisation as the untangling, in
/// patches of one ring, widened to two while that helps. A result is kept only if every
/// element stays certified and the certified min Ĩ rises; otherwise the mesh is left as it
/// was. Boundary nodes on the geometry never move.
pub(crate) fn reshape_poor_elements(
    mesh: &mut HighOrderMesh,
    straight: &[[f64; 3]],
    on_geometry: impl IntoIterator<Item = u32>,
    sliding: &BTreeMap<u32, NodeConstraint>,
    threshold: f64,
    mut quality: MeshQuality,
    assess: &dyn Fn(&HighOrderMesh) -> Result<MeshQuality, CurveError>,
) -> Result<(MeshQuality, Reshaping), CurveError> {
    let candidates = |quality: &MeshQuality| -> Vec<usize> {
        quality.validity.as_ref().map_or_else(Vec::new, |checks| {
            (0..checks.len())
                .filter(|&c| {
                    checks[c].validity == Validity::Valid
                        && checks[c].scaled_jacobian_lower_bound < threshold
                })
                .collect()
        })
    };
    let mut done = Reshaping {
        min_before: certified_minimum(&quality),
        ..Reshaping::default()
    };
    done.min_after = done.min_before;
    if mesh.order < 2 || candidates(&quality).is_empty() || !not_certified(&quality).is_empty() {
        return Ok((quality, done));
    }
    // Only what curving did is reshaped: a cell whose straight shape already has a low Ĩ
    // (a skewed quadrilateral or hexahedron) is the input's, not ours to change.
    let mut straight_mesh = mesh.clone();
    straight_mesh.nodes.copy_from_slice(straight);
    let straight_quality = hocurve_quality::scaled_jacobian(&straight_mesh, Sampling::Quadrature)?;
    drop(straight_mesh);
    let poor = |quality: &MeshQuality| -> Vec<usize> {
        let checks = quality.validity.as_deref().unwrap_or(&[]);
        candidates(quality)
            .into_iter()
            .filter(|&c| checks[c].scaled_jacobian_lower_bound < threshold * straight_quality[c])
            .collect()
    };
    let mut cells = poor(&quality);
    done.elements = cells.len();
    if cells.is_empty() {
        return Ok((quality, done));
    }
    // The vertices stay: they are the user's mesh (first-layer heights, spacing), only the
    // high-order nodes between them are reshaped.
    let mut fixed = held_nodes(mesh, on_geometry, sliding)?;
    fixed.extend(0..mesh.layout().num_vertices() as u32);
    fixed.sort_unstable();
    fixed.dedup();
    for rings in 1..=2 {
        let before = mesh.nodes.clone();
        let options = UntangleOptions {
            rings,
            ..UntangleOptions::default()
        };
        untangle_sliding(mesh, straight, &cells, &fixed, sliding, &options)?;
        let reshaped = assess(mesh)?;
        let minimum = certified_minimum(&reshaped);
        if !not_certified(&reshaped).is_empty()
            || !crate::correction_choice::significantly_better(minimum, done.min_after)
        {
            mesh.nodes = before;
            break;
        }
        done.kept = true;
        done.min_after = minimum;
        quality = reshaped;
        cells = poor(&quality);
        if cells.is_empty() {
            break;
        }
    }
    Ok((quality, done))
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_nurbs::shapes::{bilinear_patch, sphere};
    use hocurve_nurbs::{EntityGeometry, GeometricEntity, GeometryModel};

    /// A quadratic triangle whose edge 0–1 bends back past the edge 0–2 at vertex 0: with
    /// x_m the edge's middle node, the tangent at 0 is 4 x_m − 3 x_0 − x_1 = (−0.6, 1.2),
    /// and det J(0) = det[(−0.6, 1.2), (0, 1)] = −0.6 whatever else moves. Beyond reach
    /// when every node of both edges at vertex 0 is held, not when x_m is free; a cell
    /// negative only where a free node shapes it is not.
    #[test]
    fn a_corner_folded_by_held_nodes_alone_is_beyond_the_untanglers_reach() {
        let linear = hocurve_mesh::LinearMesh {
            dim: 2,
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            cells: vec![hocurve_mesh::Element {
                kind: Shape::Tri,
                vertices: vec![0, 1, 2],
                entity: 1,
            }],
            ..Default::default()
        };
        let mut mesh =
            HighOrderMesh::from_linear(&linear, 2, hocurve_nodes::NodeFamily::Equispaced).unwrap();
        let near = |mesh: &HighOrderMesh, x: [f64; 3]| {
            (0..mesh.nodes.len())
                .min_by(|&a, &b| {
                    let d = |n: usize| {
                        (0..2)
                            .map(|k| (mesh.nodes[n][k] - x[k]).powi(2))
                            .sum::<f64>()
                    };
                    d(a).total_cmp(&d(b))
                })
                .unwrap()
        };
        let middle = near(&mesh, [0.5, 0.0, 0.0]);
        let opposite = near(&mesh, [0.5, 0.5, 0.0]);
        mesh.nodes[middle] = [0.1, 0.3, 0.0];
        let all_held = vec![true; mesh.nodes.len()];
        assert_eq!(invalid_where_held(&mesh, &[0], &all_held).unwrap(), [0]);
        let mut held = all_held.clone();
        held[middle] = false;
        assert!(invalid_where_held(&mesh, &[0], &held).unwrap().is_empty());
        // Only the node opposite vertex 0 free: it does not shape J at vertex 0.
        let mut held = all_held;
        held[opposite] = false;
        assert_eq!(invalid_where_held(&mesh, &[0], &held).unwrap(), [0]);
        // Straight again: valid everywhere, nothing beyond reach.
        mesh.nodes[middle] = [0.5, 0.0, 0.0];
        assert!(
            invalid_where_held(&mesh, &[0], &vec![true; mesh.nodes.len()])
                .unwrap()
                .is_empty()
        );
    }

    /// Nodes on one plane, or on two coplanar faces (an assembly's parts touching), slide
    /// in that plane; nodes where a plane meets a parallel one 1e-6 away, or a sphere, or
    /// on the sphere alone, do not.
    #[test]
    fn nodes_slide_where_all_their_entities_are_one_plane() {
        let square = |x0: f64, z: f64| {
            let surface = bilinear_patch([
                [[x0, 0.0, z], [x0, 1.0, z]],
                [[x0 + 1.0, 0.0, z], [x0 + 1.0, 1.0, z]],
            ])
            .unwrap();
            GeometricEntity::new("square", "test", EntityGeometry::Surface(surface))
        };
        let ball = GeometricEntity::new(
            "ball",
            "test",
            EntityGeometry::Surface(sphere([0.5, 0.5, 2.0], 0.5).unwrap()),
        );
        let model = GeometryModel::new(
            vec![square(0.0, 0.0), square(1.0, 0.0), square(2.0, 1e-6), ball],
            None,
        );
        let entities: BTreeMap<u32, Vec<usize>> = [
            (0, vec![0]),
            (1, vec![0, 1]),
            (2, vec![1, 2]),
            (3, vec![0, 3]),
            (4, vec![3]),
        ]
        .into_iter()
        .collect();
        let sliding = nodes_in_planar_faces(&model, &entities);
        assert_eq!(sliding.keys().copied().collect::<Vec<_>>(), [0, 1]);
        for (_, (point, normal)) in sliding {
            assert!(point[2].abs() < 1e-15);
            assert!((normal[2].abs() - 1.0).abs() < 1e-15, "{normal:?}");
        }
    }
}
