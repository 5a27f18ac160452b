//! The Dirichlet and sliding data of the elastic analogy (the paper's Eqs. (2)–(3)): nodes
//! on curved boundaries prescribed to their targets, nodes of `slide` groups sliding in
//! their plane, every other boundary node fixed.

use std::collections::{BTreeMap, BTreeSet};

use hocurve_elastic::BoundaryConditions;
use hocurve_mesh::HighOrderMesh;
use hocurve_nurbs::vec3::{cross, dot, norm, sub};

use crate::pipeline::CurveError;

/// The Dirichlet and sliding data of the elastic analogy: nodes with a target on the
/// geometry move to it; nodes of `slide` groups slide in the group's plane; every other
/// boundary node is fixed. Precedence: curved target, then fixed (a node shared by a sliding
/// and a fixed facet, or by two sliding planes, stays put), then sliding.
pub(crate) fn boundary_conditions(
    mesh: &HighOrderMesh,
    targets: &BTreeMap<u32, [f64; 3]>,
    slide: &[String],
) -> Result<BoundaryConditions, CurveError> {
    // Topology facet → sliding normal, per requested group.
    let mut slide_normal: BTreeMap<usize, [f64; 3]> = BTreeMap::new();
    for name in slide {
        let facets = group_facets(mesh, name)?;
        let normal = plane_normal(mesh, name, &facets)?;
        for f in facets {
            slide_normal.insert(mesh.facet_ids[f] as usize, normal);
        }
    }
    let mut fixed = BTreeSet::new();
    let mut sliding: BTreeMap<u32, [f64; 3]> = BTreeMap::new();
    for (facet, nodes) in mesh.boundary_facet_nodes()? {
        match slide_normal.get(&facet) {
            None => fixed.extend(nodes),
            Some(normal) => {
                for n in nodes {
                    match sliding.get(&n) {
                        Some(m) if !parallel(m, normal) => {
                            fixed.insert(n);
                        }
                        _ => {
                            sliding.insert(n, *normal);
                        }
                    }
                }
            }
        }
    }
    let mut bc = BoundaryConditions::default();
    for n in fixed {
        bc.prescribed.insert(n, [0.0; 3]);
    }
    for (&n, &x) in targets {
        let x0 = mesh.nodes[n as usize];
        bc.prescribed
            .insert(n, [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]);
    }
    bc.sliding = sliding
        .into_iter()
        .filter(|(n, _)| !bc.prescribed.contains_key(n))
        .collect();
    Ok(bc)
}

pub(crate) fn parallel(a: &[f64; 3], b: &[f64; 3]) -> bool {
    norm(cross(*a, *b)) <= 1e-10 * norm(*a) * norm(*b)
}

/// Indices into `mesh.facets` of the boundary group `name` (dimension dim − 1).
pub(crate) fn group_facets(mesh: &HighOrderMesh, name: &str) -> Result<Vec<usize>, CurveError> {
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
    if facets.is_empty() {
        let available: Vec<&str> = mesh
            .physical_groups
            .iter()
            .filter(|g| g.dim == facet_dim)
            .map(|g| g.name.as_str())
            .collect();
        return Err(CurveError::UnknownSlideGroup {
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

/// The unit normal of the plane (line in 2D) through the vertices of `facets`, checked.
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
