//! The Dirichlet and sliding data of the elastic analogy (the paper's Eqs. (2)–(3)): nodes
//! on curved boundaries prescribed to their targets, nodes of `slide` groups sliding in
//! their planes, every other boundary node fixed.
//!
//! A sliding group may be made of several planes (the two end planes of an extruded
//! mesh, the sides of a box): its facets are split into connected coplanar pieces, and each
//! node slides in the plane of its piece; a node on two pieces meeting at an angle moves
//! along their common line, one on three or more stays put.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_elastic::BoundaryConditions;
use hocurve_mesh::HighOrderMesh;
use hocurve_nurbs::vec3::{cross, dot, norm, sub};

use crate::pipeline::CurveError;

/// The Dirichlet and sliding data of the elastic analogy: nodes with a target on the
/// geometry move to it; nodes of `slide` groups slide in their pieces' planes (along the
/// line where two meet); every other boundary node is fixed. Precedence: curved target,
/// then fixed (a node shared by a sliding and a fixed facet stays put), then sliding.
pub(crate) fn boundary_conditions(
    mesh: &HighOrderMesh,
    targets: &BTreeMap<u32, [f64; 3]>,
    slide: &[String],
) -> Result<BoundaryConditions, CurveError> {
    // Topology facet → unit normal of its plane, per requested group.
    let mut slide_normal: BTreeMap<usize, [f64; 3]> = BTreeMap::new();
    for name in slide {
        let facets = group_facets(mesh, name, "slide")?;
        for piece in planar_pieces(mesh, name, &facets)?.pieces {
            for &f in &piece.facets {
                slide_normal.insert(mesh.facet_ids[f] as usize, piece.normal);
            }
        }
    }
    let mut fixed = BTreeSet::new();
    // The distinct planes each sliding node lies in.
    let mut planes: BTreeMap<u32, Vec<[f64; 3]>> = BTreeMap::new();
    for (facet, nodes) in mesh.boundary_facet_nodes()? {
        match slide_normal.get(&facet) {
            None => fixed.extend(nodes),
            Some(normal) => {
                for n in nodes {
                    let list = planes.entry(n).or_default();
                    if !list.iter().any(|m| parallel(m, normal)) {
                        list.push(*normal);
                    }
                }
            }
        }
    }
    let mut bc = BoundaryConditions::default();
    for (&n, x) in targets {
        let x0 = mesh.nodes[n as usize];
        bc.prescribed
            .insert(n, [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]);
    }
    for n in fixed {
        bc.prescribed.entry(n).or_insert([0.0; 3]);
    }
    for (n, normals) in planes {
        if bc.prescribed.contains_key(&n) {
            continue;
        }
        match normals[..] {
            [normal] => {
                bc.sliding.insert(n, normal);
            }
            [a, b] if mesh.dim == 3 => {
                bc.along_line.insert(n, cross(a, b));
            }
            _ => {
                bc.prescribed.insert(n, [0.0; 3]);
            }
        }
    }
    Ok(bc)
}

/// A connected set of coplanar facets of a sliding group and their plane's unit normal.
#[derive(Debug, Clone)]
pub(crate) struct PlanarPiece {
    /// Indices into `mesh.facets`.
    pub facets: Vec<usize>,
    pub normal: [f64; 3],
}

/// A sliding group's planar pieces.
#[derive(Debug, Clone)]
pub(crate) struct PlanarGroup {
    /// In order of their first facet.
    pub pieces: Vec<PlanarPiece>,
    /// The smallest angle (degrees, in [0, 90]) between the planes of two pieces that
    /// share a corner sub-entity; None when no two pieces touch.
    pub smallest_crease_degrees: Option<f64>,
}

/// The facets `facets` of group `name` split into connected coplanar pieces (facets
/// sharing an edge, in 2D a vertex, with parallel normals); an error if a piece is not
/// planar (a warped quadrilateral) or a facet is degenerate.
pub(crate) fn planar_pieces(
    mesh: &HighOrderMesh,
    name: &str,
    facets: &[usize],
) -> Result<PlanarGroup, CurveError> {
    let normals: Vec<[f64; 3]> = facets
        .iter()
        .map(|&f| plane_normal(mesh, name, &[f]))
        .collect::<Result<_, _>>()?;
    // Facets sharing a corner sub-entity (edge in 3D, vertex in 2D), by its sorted corners.
    let mut sharing: BTreeMap<Vec<u32>, Vec<usize>> = BTreeMap::new();
    for (k, &f) in facets.iter().enumerate() {
        let facet = &mesh.facets[f];
        let corners = &facet.nodes[..facet.kind.num_vertices()];
        if mesh.dim == 2 {
            for &v in corners {
                sharing.entry(vec![v]).or_default().push(k);
            }
        } else {
            for i in 0..corners.len() {
                let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
                sharing.entry(vec![a.min(b), a.max(b)]).or_default().push(k);
            }
        }
    }
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); facets.len()];
    for list in sharing.values() {
        for &a in list {
            for &b in list {
                if a != b && parallel(&normals[a], &normals[b]) {
                    neighbours[a].push(b);
                }
            }
        }
    }
    let mut piece_of = vec![usize::MAX; facets.len()];
    let mut pieces = Vec::new();
    for start in 0..facets.len() {
        if piece_of[start] != usize::MAX {
            continue;
        }
        let id = pieces.len();
        piece_of[start] = id;
        let mut members = vec![start];
        let mut stack = vec![start];
        while let Some(k) = stack.pop() {
            for &m in &neighbours[k] {
                if piece_of[m] == usize::MAX {
                    piece_of[m] = id;
                    members.push(m);
                    stack.push(m);
                }
            }
        }
        members.sort_unstable();
        let piece_facets: Vec<usize> = members.iter().map(|&k| facets[k]).collect();
        let normal = plane_normal(mesh, name, &piece_facets)?;
        pieces.push(PlanarPiece {
            facets: piece_facets,
            normal,
        });
    }
    let mut smallest: Option<f64> = None;
    for list in sharing.values() {
        for &a in list {
            for &b in list {
                let (pa, pb) = (piece_of[a], piece_of[b]);
                if pa < pb {
                    let (na, nb) = (pieces[pa].normal, pieces[pb].normal);
                    let degrees = norm(cross(na, nb)).atan2(dot(na, nb).abs()).to_degrees();
                    smallest = Some(smallest.map_or(degrees, |s| s.min(degrees)));
                }
            }
        }
    }
    Ok(PlanarGroup {
        pieces,
        smallest_crease_degrees: smallest,
    })
}

/// Planes of one group meeting at less than this (degrees) are taken for the facets of a
/// curved surface, which does not slide by default.
const DEFAULT_SLIDE_CREASE_DEGREES: f64 = 30.0;

/// The groups that slide: `slide`, then (sorted by name) every other named boundary group
/// not in `fix` that is made of planes meeting at no less than 30°
/// ([`DEFAULT_SLIDE_CREASE_DEGREES`]), is not itself on the geometry (none of its facets
/// has all its nodes in `targets`) and touches it (some node in `targets`): the end and
/// symmetry planes of extruded and half models, whose nodes must follow the curved wall's
/// in-plane motion rather than hold the cells next to it. The second value flags the
/// groups that slide by default.
pub(crate) fn sliding_groups(
    mesh: &HighOrderMesh,
    targets: &BTreeMap<u32, [f64; 3]>,
    slide: &[String],
    fix: &[String],
) -> Result<Vec<(String, bool)>, CurveError> {
    for name in fix {
        group_facets(mesh, name, "fix")?;
        if slide.contains(name) {
            return Err(CurveError::SlideAndFix { name: name.clone() });
        }
    }
    let mut groups: Vec<(String, bool)> = slide.iter().map(|n| (n.clone(), false)).collect();
    let facet_dim = mesh.dim - 1;
    let names: BTreeSet<&str> = mesh
        .physical_groups
        .iter()
        .filter(|g| g.dim == facet_dim && !g.name.is_empty())
        .map(|g| g.name.as_str())
        .filter(|n| !slide.iter().any(|s| s == n) && !fix.iter().any(|f| f == n))
        .collect();
    if targets.is_empty() {
        return Ok(groups);
    }
    for name in names {
        // A group the file names but puts no facet in (MSH 2.2 with Mesh.SaveAll) has
        // nothing to slide.
        let Ok(facets) = group_facets(mesh, name, "slide") else {
            continue;
        };
        let on_geometry = |f: &usize| {
            mesh.facets[*f]
                .nodes
                .iter()
                .all(|n| targets.contains_key(n))
        };
        let touches = facets
            .iter()
            .any(|&f| mesh.facets[f].nodes.iter().any(|n| targets.contains_key(n)));
        if !touches || facets.iter().any(on_geometry) {
            continue;
        }
        let Ok(planar) = planar_pieces(mesh, name, &facets) else {
            continue;
        };
        if planar
            .smallest_crease_degrees
            .is_none_or(|d| d >= DEFAULT_SLIDE_CREASE_DEGREES)
        {
            groups.push((name.to_string(), true));
        }
    }
    Ok(groups)
}

/// Whether two normals are parallel (either sign) to within 1e-6 rad: facets of one
/// plane whose vertices carry rounding, not two planes (whose common line would then be
/// ill-defined); [`plane_normal`] checks each piece's flatness on its own.
fn parallel(a: &[f64; 3], b: &[f64; 3]) -> bool {
    norm(cross(*a, *b)) <= 1e-6 * norm(*a) * norm(*b)
}

/// Indices into `mesh.facets` of the boundary group `name` (dimension dim − 1); an error
/// naming the command-line `option` if there is none.
pub(crate) fn group_facets(
    mesh: &HighOrderMesh,
    name: &str,
    option: &'static str,
) -> Result<Vec<usize>, CurveError> {
    let facet_dim = mesh.dim - 1;
    let tags: Vec<i32> = mesh
        .physical_groups
        .iter()
        .filter(|g| g.dim == facet_dim && g.name == name)
        .map(|g| g.tag)
        .collect();
    let facets: Vec<usize> = mesh
        .facets
        .iter()
        .enumerate()
        .filter(|(_, f)| {
            mesh.entity_physicals
                .get(&(facet_dim, f.entity))
                .is_some_and(|p| p.iter().any(|t| tags.contains(t)))
        })
        .map(|(i, _)| i)
        .collect();
    if facets.is_empty() && !tags.is_empty() {
        return Err(CurveError::EmptySlideGroup {
            option,
            name: name.to_string(),
        });
    }
    if facets.is_empty() {
        let available: Vec<&str> = mesh
            .physical_groups
            .iter()
            .filter(|g| g.dim == facet_dim)
            .map(|g| g.name.as_str())
            .collect();
        return Err(CurveError::UnknownSlideGroup {
            option,
            name: name.to_string(),
            available: if available.is_empty() {
                "no named boundary groups".to_string()
            } else {
                available.join(", ")
            },
        });
    }
    Ok(facets)
}

/// The unit normal of the plane (line in 2D) through the vertices of `facets`, checked:
/// an error if a vertex lies off it by more than 1e-8 of their spread.
pub(crate) fn plane_normal(
    mesh: &HighOrderMesh,
    name: &str,
    facets: &[usize],
) -> Result<[f64; 3], CurveError> {
    let vertices: BTreeSet<u32> = facets
        .iter()
        .flat_map(|&f| {
            let facet = &mesh.facets[f];
            let corners = facet.kind.num_vertices();
            facet.nodes[..corners].to_vec()
        })
        .collect();
    let points: Vec<[f64; 3]> = vertices.iter().map(|&v| mesh.nodes[v as usize]).collect();
    let count = points.len() as f64;
    let mut centre = [0.0; 3];
    for p in &points {
        for d in 0..3 {
            centre[d] += p[d] / count;
        }
    }
    // Summed facet normals: area-weighted in 3D (cross products of corner fans), edge
    // normals in 2D.
    let mut normal = [0.0; 3];
    for &f in facets {
        let facet = &mesh.facets[f];
        let corners = facet.kind.num_vertices();
        let x: Vec<[f64; 3]> = facet.nodes[..corners]
            .iter()
            .map(|&n| mesh.nodes[n as usize])
            .collect();
        if mesh.dim == 2 {
            let t = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
            // Orientation-free: make the normal point the same way as the running sum.
            let n = [t[1], -t[0], 0.0];
            let sign = if n[0] * normal[0] + n[1] * normal[1] < 0.0 {
                -1.0
            } else {
                1.0
            };
            normal[0] += sign * n[0];
            normal[1] += sign * n[1];
        } else {
            for k in 1..corners - 1 {
                let a = sub(x[k], x[0]);
                let b = sub(x[k + 1], x[0]);
                let n = cross(a, b);
                let sign = if dot(n, normal) < 0.0 { -1.0 } else { 1.0 };
                for d in 0..3 {
                    normal[d] += sign * n[d];
                }
            }
        }
    }
    let length = norm(normal);
    let size = points
        .iter()
        .map(|p| norm(sub(*p, centre)))
        .fold(0.0, f64::max);
    if length.is_nan() || length <= 0.0 {
        return Err(CurveError::SlideGroupNotPlanar {
            name: name.to_string(),
            distance: f64::NAN,
        });
    }
    let normal = normal.map(|v| v / length);
    let distance = points
        .iter()
        .map(|p| dot(sub(*p, centre), normal).abs())
        .fold(0.0, f64::max);
    if distance > 1e-8 * size.max(f64::MIN_POSITIVE) {
        return Err(CurveError::SlideGroupNotPlanar {
            name: name.to_string(),
            distance,
        });
    }
    Ok(normal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hocurve_mesh::{Element, LinearMesh, PhysicalGroup, Shape};
    use hocurve_nodes::NodeFamily;
    use hocurve_testmeshes::{high_order, unit_cube, Fill};

    /// The unit cube in 2³ hexahedra at order 2 with the boundary groups "top" (z = 1),
    /// "sides" (the four planes x, y = 0, 1: one group) and "bottom" (z = 0).
    fn cube_with_groups() -> HighOrderMesh {
        let mut linear: LinearMesh = unit_cube(2, Fill::Hex, 0.0);
        let id = |i: usize, j: usize, k: usize| (i + 3 * (j + 3 * k)) as u32;
        let mut quad = |v: [u32; 4], entity: i32| {
            linear.facets.push(Element {
                kind: Shape::Quad,
                vertices: v.to_vec(),
                entity,
            })
        };
        for a in 0..2 {
            for b in 0..2 {
                quad(
                    [
                        id(a, b, 0),
                        id(a + 1, b, 0),
                        id(a + 1, b + 1, 0),
                        id(a, b + 1, 0),
                    ],
                    3,
                );
                quad(
                    [
                        id(a, b, 2),
                        id(a + 1, b, 2),
                        id(a + 1, b + 1, 2),
                        id(a, b + 1, 2),
                    ],
                    1,
                );
                for side in [0, 2] {
                    quad(
                        [
                            id(side, a, b),
                            id(side, a + 1, b),
                            id(side, a + 1, b + 1),
                            id(side, a, b + 1),
                        ],
                        2,
                    );
                    quad(
                        [
                            id(a, side, b),
                            id(a + 1, side, b),
                            id(a + 1, side, b + 1),
                            id(a, side, b + 1),
                        ],
                        2,
                    );
                }
            }
        }
        for (tag, name) in [(1, "top"), (2, "sides"), (3, "bottom")] {
            linear.physical_groups.push(PhysicalGroup {
                dim: 2,
                tag,
                name: name.into(),
            });
            linear.entity_physicals.insert((2, tag), vec![tag]);
        }
        high_order(&linear, 2, NodeFamily::Equispaced)
    }

    #[test]
    fn a_group_of_four_planes_slides_in_each_and_along_the_lines_where_two_meet() {
        let mesh = cube_with_groups();
        // The top face is the curved wall: its nodes have targets (pushed up in the middle).
        let mut targets = BTreeMap::new();
        for n in 0..mesh.nodes.len() as u32 {
            let x = mesh.nodes[n as usize];
            if x[2] == 1.0 {
                let bump = 0.1 * x[0] * (1.0 - x[0]) * x[1] * (1.0 - x[1]);
                targets.insert(n, [x[0], x[1], 1.0 + bump]);
            }
        }
        // The sides touch the top and are planes at 90°: they slide by default; the bottom
        // does not touch it.
        let groups = sliding_groups(&mesh, &targets, &[], &[]).unwrap();
        assert_eq!(groups, [("sides".to_string(), true)]);
        assert!(sliding_groups(&mesh, &targets, &[], &["sides".into()])
            .unwrap()
            .is_empty());
        let bc = boundary_conditions(&mesh, &targets, &["sides".into()]).unwrap();
        let (mut planes, mut lines) = (0, 0);
        for (n, x) in mesh.nodes.iter().enumerate() {
            let n = n as u32;
            let on = |d: usize| x[d] == 0.0 || x[d] == 1.0;
            let (side_x, side_y) = (on(0), on(1));
            if x[2] == 1.0 {
                assert!(
                    bc.prescribed[&n] != [0.0; 3]
                        || x[0] * x[1] * (1.0 - x[0]) * (1.0 - x[1]) == 0.0
                );
            } else if x[2] == 0.0 {
                assert_eq!(bc.prescribed[&n], [0.0; 3], "bottom node {x:?}");
            } else if side_x && side_y {
                // A vertical edge of the box: along z.
                let t = bc.along_line[&n];
                assert!(t[0] == 0.0 && t[1] == 0.0 && t[2] != 0.0, "{t:?} at {x:?}");
                lines += 1;
            } else if side_x || side_y {
                let normal = bc.sliding[&n];
                let axis = if side_x { 0 } else { 1 };
                assert!(normal[axis] != 0.0 && normal[1 - axis] == 0.0 && normal[2] == 0.0);
                planes += 1;
            } else {
                assert!(!bc.prescribed.contains_key(&n) && !bc.sliding.contains_key(&n));
            }
        }
        // Order 2 on 2³ cells (5 × 5 nodes a side): 3 nodes strictly inside each of the 4
        // vertical edges, 3 × 3 strictly inside each side.
        assert_eq!((lines, planes), (4 * 3, 4 * 9));
    }

    /// MSH 2.2 written with Gmsh's Mesh.SaveAll names the groups but puts every element
    /// outside them (physical tag 0): such a group neither slides by default nor is
    /// taken for a group that does not exist.
    #[test]
    fn a_named_group_without_facets_is_not_slid_and_said_to_be_empty() {
        let mut mesh = cube_with_groups();
        mesh.physical_groups.push(PhysicalGroup {
            dim: 2,
            tag: 4,
            name: "saved_all".into(),
        });
        let mut targets = BTreeMap::new();
        for (n, x) in mesh.nodes.iter().enumerate() {
            if x[2] == 1.0 {
                targets.insert(n as u32, *x);
            }
        }
        let groups = sliding_groups(&mesh, &targets, &[], &[]).unwrap();
        assert_eq!(groups, [("sides".to_string(), true)]);
        let empty = group_facets(&mesh, "saved_all", "slide").unwrap_err();
        assert!(
            matches!(&empty, CurveError::EmptySlideGroup { name, .. } if name == "saved_all"),
            "{empty}"
        );
        let unknown = group_facets(&mesh, "nowhere", "fix").unwrap_err();
        assert!(
            matches!(unknown, CurveError::UnknownSlideGroup { .. }),
            "{unknown}"
        );
    }

    #[test]
    fn pieces_of_a_group_and_their_creases() {
        let mesh = cube_with_groups();
        let sides = group_facets(&mesh, "sides", "slide").unwrap();
        let planar = planar_pieces(&mesh, "sides", &sides).unwrap();
        assert_eq!(planar.pieces.len(), 4);
        assert!(planar.pieces.iter().all(|p| p.facets.len() == 4));
        let crease = planar.smallest_crease_degrees.unwrap();
        assert!((crease - 90.0).abs() < 1e-9, "{crease}");
        let top = group_facets(&mesh, "top", "slide").unwrap();
        let planar = planar_pieces(&mesh, "top", &top).unwrap();
        assert_eq!(planar.pieces.len(), 1);
        assert_eq!(planar.smallest_crease_degrees, None);
    }
}
