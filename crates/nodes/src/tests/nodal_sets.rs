use super::*;

#[test]
fn node_counts_match_complete_element_formulas() {
    for shape in Shape::ALL {
        for p in 1..=8 {
            let set = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
            assert_eq!(set.len(), shape.num_nodes(p), "{shape:?} p={p}");
        }
    }
}

#[test]
fn lattice_indices_are_the_equispaced_points_and_are_distinct() {
    for shape in Shape::ALL {
        for p in 1..=8 {
            let set = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
            let mut seen = std::collections::HashSet::new();
            for (x, l) in set.points().iter().zip(set.lattice()) {
                for d in 0..3 {
                    assert!(
                        (x[d] * p as f64 - l[d] as f64).abs() < 1e-12,
                        "{shape:?} p={p}"
                    );
                    assert!(l[d] >= 0 && l[d] <= p as i64);
                }
                assert!(seen.insert(*l), "{shape:?} p={p}: duplicate lattice {l:?}");
            }
        }
    }
}

#[test]
fn every_lattice_point_of_the_reference_element_is_present() {
    // Counting argument: all points (i,j,k)/p inside the shape appear exactly once.
    for shape in Shape::ALL {
        for p in 1..=6i64 {
            let set = ReferenceNodes::new(shape, p as usize, NodeFamily::Equispaced);
            let inside = |i: i64, j: i64, k: i64| match shape {
                Shape::Line => j == 0 && k == 0,
                Shape::Tri => k == 0 && i + j <= p,
                Shape::Quad => k == 0,
                Shape::Tet => i + j + k <= p,
                Shape::Hex => true,
                Shape::Prism => i + j <= p,
            };
            let mut count = 0;
            for k in 0..=p {
                for j in 0..=p {
                    for i in 0..=p {
                        if inside(i, j, k) {
                            count += 1;
                            assert!(set.index_of_lattice([i, j, k]).is_some());
                        }
                    }
                }
            }
            assert_eq!(count, set.len());
        }
    }
}

#[test]
fn entities_match_geometry() {
    // Edge nodes lie on their edge's segment, face nodes on their face's plane.
    let set = ReferenceNodes::new(Shape::Hex, 4, NodeFamily::Equispaced);
    let v = Shape::Hex.vertices();
    for (x, e) in set.points().iter().zip(set.entities()) {
        match *e {
            NodeEntity::Edge { edge, .. } => {
                let [a, b] = Shape::Hex.edges()[edge];
                let fixed: Vec<usize> = (0..3).filter(|&d| v[a][d] == v[b][d]).collect();
                for d in fixed {
                    assert_eq!(x[d], v[a][d]);
                }
            }
            NodeEntity::Face { face, .. } => {
                let f = Shape::Hex.faces()[face];
                let d = (0..3).find(|&d| f.iter().all(|&i| v[i][d] == v[f[0]][d]));
                let d = d.expect("hex faces are axis-aligned");
                assert_eq!(x[d], v[f[0]][d]);
            }
            _ => {}
        }
    }
}

/// The nodes of a 3D element on each face are exactly the face shape's set of the same
/// family mapped onto it, and on each edge the line set: neighbours agree.
#[test]
fn restriction_to_faces_and_edges_is_the_lower_dimensional_set() {
    for family in NodeFamily::ALL {
        for shape in [
            Shape::Tri,
            Shape::Quad,
            Shape::Tet,
            Shape::Hex,
            Shape::Prism,
        ] {
            for p in 1..=7 {
                let set = ReferenceNodes::new(shape, p, family);
                let v = shape.vertices();
                let on_entity = |corners: &[usize], sub: Shape| {
                    // Map the sub-shape's nodes onto the entity and find each among
                    // the element's nodes.
                    let sub_set = ReferenceNodes::new(sub, p, family);
                    let (o, a, b) = (corners[0], corners[1], corners[corners.len() - 1]);
                    for x in sub_set.points() {
                        let y = if sub == Shape::Line {
                            affine(v[o], &[(v[a], x[0])])
                        } else {
                            affine(v[o], &[(v[a], x[0]), (v[b], x[1])])
                        };
                        let found = set
                            .points()
                            .iter()
                            .any(|z| (0..3).all(|d| (z[d] - y[d]).abs() < 1e-14));
                        assert!(
                            found,
                            "{family} {shape:?} p={p}: {sub:?} node {y:?} missing"
                        );
                    }
                };
                for e in shape.edges() {
                    on_entity(e, Shape::Line);
                }
                for f in shape.faces() {
                    on_entity(f, Shape::face_shape(f.len()));
                }
            }
        }
    }
}

/// Φᵢ(xⱼ) = δᵢⱼ, ΣΦᵢ = 1, Σ∇Φᵢ = 0 and reproduction of degree-p polynomials, for every
/// family, shape and order.
#[test]
fn lagrange_bases_on_every_family_interpolate_and_reproduce_polynomials() {
    use crate::LagrangeBasis;
    for family in NodeFamily::ALL {
        for shape in Shape::ALL {
            let max_p = match shape {
                Shape::Hex | Shape::Prism => 5,
                _ => 8,
            };
            for p in 1..=max_p {
                let set = ReferenceNodes::new(shape, p, family);
                let basis = LagrangeBasis::new(&set).unwrap();
                let mut values = vec![0.0; set.len()];
                let mut grads = vec![[0.0; 3]; set.len()];
                for (j, x) in set.points().iter().enumerate() {
                    basis.eval(*x, &mut values);
                    for (i, v) in values.iter().enumerate() {
                        let want = if i == j { 1.0 } else { 0.0 };
                        assert!((v - want).abs() < 1e-9, "{family} {shape:?} p={p}");
                    }
                }
                // f = (x + 2y − z)^p at a point inside every shape.
                let f = |x: &[f64; 3]| (x[0] + 2.0 * x[1] - x[2]).powi(p as i32);
                let mut xi = [0.21, 0.17, 0.29];
                for c in xi.iter_mut().skip(shape.dim()) {
                    *c = 0.0;
                }
                basis.eval(xi, &mut values);
                basis.eval_grad(xi, &mut grads);
                let interpolated: f64 =
                    values.iter().zip(set.points()).map(|(v, x)| v * f(x)).sum();
                assert!(
                    (interpolated - f(&xi)).abs() < 1e-10,
                    "{family} {shape:?} p={p}"
                );
                assert!((values.iter().sum::<f64>() - 1.0).abs() < 1e-11);
                for d in 0..3 {
                    assert!(grads.iter().map(|g| g[d]).sum::<f64>().abs() < 1e-9);
                }
            }
        }
    }
}

#[test]
fn unsupported_order_is_an_error() {
    assert!(ReferenceNodes::try_new(Shape::Tri, 0, NodeFamily::Equispaced).is_err());
    assert!(ReferenceNodes::try_new(Shape::Tri, 99, NodeFamily::Equispaced).is_err());
}
