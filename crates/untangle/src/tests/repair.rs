//! Repairs of tangled meshes, checked by the Bézier certification of hocurve-quality.

use hocurve_mesh::{HighOrderMesh, Shape};
use hocurve_nodes::NodeFamily;
use hocurve_quality::{check_validity, BezierOptions, Validity};
use hocurve_testmeshes::{unit_cube, unit_square, Fill, Kuhn};

use crate::{untangle, UntangleOptions};

fn not_valid(mesh: &HighOrderMesh) -> Vec<usize> {
    check_validity(mesh, &BezierOptions::default())
        .expect("checkable")
        .iter()
        .enumerate()
        .filter(|(_, c)| c.validity != Validity::Valid)
        .map(|(e, _)| e)
        .collect()
}

fn boundary(mesh: &HighOrderMesh) -> Vec<u32> {
    let mut nodes: Vec<u32> = mesh
        .boundary_facet_nodes()
        .expect("facets")
        .into_iter()
        .flat_map(|(_, n)| n)
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// A straight order-`order` mesh and a tangled copy: the vertex nearest `at` dragged to `to`.
fn tangled(
    dim: usize,
    n: usize,
    order: usize,
    at: [f64; 3],
    to: [f64; 3],
) -> (HighOrderMesh, Vec<[f64; 3]>) {
    // The unit square or cube cut into n^d boxes, each into 2 triangles or 6 tetrahedra.
    let linear = if dim == 3 {
        unit_cube(n, Fill::Tet(Kuhn::LexicographicMiddleSwapped), 0.0)
    } else {
        unit_square(n, Shape::Tri, 0.0)
    };
    let mesh = HighOrderMesh::from_linear(&linear, order, NodeFamily::Equispaced).expect("mesh");
    let straight = mesh.nodes.clone();
    let mut tangled = mesh;
    let v = (0..linear.vertices.len())
        .min_by(|&a, &b| {
            let d = |v: usize| {
                (0..3)
                    .map(|k| (linear.vertices[v][k] - at[k]).powi(2))
                    .sum::<f64>()
            };
            d(a).total_cmp(&d(b))
        })
        .expect("vertices");
    tangled.nodes[v] = to;
    (tangled, straight)
}

#[test]
fn a_dragged_interior_vertex_is_untangled_in_2d_and_3d() {
    for (dim, order) in [(2, 2), (2, 4), (3, 2), (3, 3)] {
        let to = if dim == 2 {
            [0.93, 0.4, 0.0]
        } else {
            [0.93, 0.4, 0.55]
        };
        let (mut mesh, straight) = tangled(
            dim,
            2,
            order,
            [0.5, 0.5, if dim == 3 { 0.5 } else { 0.0 }],
            to,
        );
        let bad = not_valid(&mesh);
        assert!(
            !bad.is_empty(),
            "dim {dim} p {order}: the test mesh must be tangled"
        );
        let fixed = boundary(&mesh);
        let before = mesh.nodes.clone();
        let report = untangle(
            &mut mesh,
            &straight,
            &bad,
            &fixed,
            &UntangleOptions::default(),
        )
        .expect("untangle");
        assert!(report.min_ratio > 0.0, "dim {dim} p {order}: {report:?}");
        assert_eq!(
            not_valid(&mesh),
            Vec::<usize>::new(),
            "dim {dim} p {order}: {report:?}"
        );
        for &n in &fixed {
            assert_eq!(
                mesh.nodes[n as usize], before[n as usize],
                "boundary node {n} moved"
            );
        }
    }
}

#[test]
fn only_nodes_whose_cells_are_all_in_the_patch_move() {
    // A 4×4 grid of squares; the vertex at (0.25, 0.25) is dragged across its neighbours.
    let (mut mesh, straight) = tangled(2, 4, 3, [0.25, 0.25, 0.0], [0.45, 0.3, 0.0]);
    let bad = not_valid(&mesh);
    assert!(!bad.is_empty());
    let before = mesh.nodes.clone();
    let fixed = boundary(&mesh);
    let options = UntangleOptions {
        rings: 1,
        ..Default::default()
    };
    untangle(&mut mesh, &straight, &bad, &fixed, &options).expect("untangle");
    assert!(not_valid(&mesh).is_empty());
    // The patch: the bad cells and every cell sharing a vertex with one. No node of a
    // cell outside it moves.
    let vertices_of = |c: usize| mesh.cells[c].nodes[..3].to_vec();
    let near: Vec<u32> = bad.iter().flat_map(|&c| vertices_of(c)).collect();
    for (c, cell) in mesh.cells.iter().enumerate() {
        if vertices_of(c).iter().any(|v| near.contains(v)) {
            continue;
        }
        for &n in &cell.nodes {
            assert_eq!(
                mesh.nodes[n as usize], before[n as usize],
                "cell {c} node {n}"
            );
        }
    }
    let moved = mesh
        .nodes
        .iter()
        .zip(&before)
        .filter(|(a, b)| a != b)
        .count();
    assert!(moved > 0);
}

#[test]
fn the_result_does_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        let (mut mesh, straight) = tangled(3, 2, 2, [0.5, 0.5, 0.5], [0.9, 0.45, 0.5]);
        let bad = not_valid(&mesh);
        let fixed = boundary(&mesh);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            untangle(
                &mut mesh,
                &straight,
                &bad,
                &fixed,
                &UntangleOptions::default(),
            )
        })
        .expect("untangle");
        mesh.nodes
    };
    let one = run(1);
    let two = run(2);
    assert!(one
        .iter()
        .zip(&two)
        .all(|(a, b)| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())));
}

#[test]
fn bad_arguments_are_errors() {
    let (mut mesh, straight) = tangled(2, 2, 2, [0.5, 0.5, 0.0], [0.9, 0.4, 0.0]);
    let options = UntangleOptions::default();
    assert!(untangle(&mut mesh, &straight[1..], &[0], &[], &options).is_err());
    assert!(untangle(&mut mesh, &straight, &[10_000], &[], &options).is_err());
    let report = untangle(&mut mesh, &straight, &[], &[], &options).expect("nothing to do");
    assert_eq!(report.patches, 0);
}

/// Sliding boundary nodes (issue 21: end planes of extruded layers) move only within their
/// plane or line: a vertex on the side y = 0 of the square (the face y = 0 of the cube),
/// dragged along it past its neighbours so that its cells fold, stays folded when held and
/// is untangled when it may slide in the plane y = 0 or along the x axis, its y exactly 0.
#[test]
fn sliding_nodes_are_untangled_within_their_plane_or_line() {
    use crate::{untangle_sliding, NodeConstraint};
    use std::collections::BTreeMap;
    for (dim, constraint) in [
        (2, NodeConstraint::Plane([0.0, 1.0, 0.0])),
        (2, NodeConstraint::Line([1.0, 0.0, 0.0])),
        (3, NodeConstraint::Plane([0.0, 1.0, 0.0])),
    ] {
        let at = [0.5, 0.0, if dim == 3 { 0.5 } else { 0.0 }];
        let to = [0.97, 0.0, at[2]];
        let (mut mesh, straight) = tangled(dim, 2, 2, at, to);
        let bad = not_valid(&mesh);
        assert!(!bad.is_empty(), "dim {dim}: the test mesh must be tangled");
        let node = mesh
            .nodes
            .iter()
            .position(|x| *x == to)
            .expect("the dragged vertex") as u32;
        let fixed: Vec<u32> = boundary(&mesh).into_iter().filter(|&n| n != node).collect();
        // Held: nothing can move the folded vertex, so the cells stay tangled.
        let mut held = mesh.clone();
        untangle(
            &mut held,
            &straight,
            &bad,
            &boundary(&mesh),
            &UntangleOptions::default(),
        )
        .expect("untangle");
        assert_eq!(held.nodes[node as usize], to);
        let sliding = BTreeMap::from([(node, constraint)]);
        untangle_sliding(
            &mut mesh,
            &straight,
            &bad,
            &fixed,
            &sliding,
            &UntangleOptions::default(),
        )
        .expect("untangle");
        let x = mesh.nodes[node as usize];
        assert_eq!(not_valid(&mesh), Vec::<usize>::new(), "dim {dim}: {x:?}");
        assert_eq!(x[1], 0.0, "dim {dim}: left its plane: {x:?}");
        assert!(x[0] < 0.9, "dim {dim}: did not slide back: {x:?}");
    }
}

#[test]
fn a_constraint_keeps_the_part_of_a_motion_it_allows() {
    use crate::NodeConstraint;
    let g = [1.0, 2.0, 3.0];
    assert_eq!(
        NodeConstraint::Plane([0.0, 0.0, 1.0]).project(g),
        [1.0, 2.0, 0.0]
    );
    assert_eq!(
        NodeConstraint::Line([0.0, 1.0, 0.0]).project(g),
        [0.0, 2.0, 0.0]
    );
    let s = 0.5f64.sqrt();
    let p = NodeConstraint::Plane([s, s, 0.0]).project(g);
    assert!((p[0] + 0.5).abs() < 1e-15 && (p[1] - 0.5).abs() < 1e-15 && p[2] == 3.0);
}

/// The patch's Hessian, assembled from the cells' blocks (the chain rule through
/// T = J W⁻¹), against central differences of its gradient, in 2D and 3D.
#[test]
fn a_patchs_hessian_matches_differences_of_its_gradient() {
    use crate::newton::BlockHessian;
    use crate::patch::{components, free_nodes, patch_cells, patch_energy, samplers};
    use std::collections::BTreeMap;
    for (dim, order) in [(2, 3), (3, 2)] {
        // Untangled but curved: a vertex moved off its straight place, not through a cell.
        let (mesh, straight) = tangled(dim, 2, order, [0.5, 0.5, 0.5], [0.58, 0.45, 0.53]);
        let elements: Vec<usize> = (0..mesh.cells.len()).collect();
        let in_patch = patch_cells(&mesh, &elements, 0);
        let free = free_nodes(&mesh, &in_patch, &boundary(&mesh));
        let groups = components(&mesh, &in_patch, &free);
        let samplers = samplers(&mesh, &groups).expect("samplers");
        let index: BTreeMap<_, _> = samplers
            .iter()
            .enumerate()
            .map(|(i, s)| (s.shape(), i))
            .collect();
        let (energy, variables, _) =
            patch_energy(&mesh, &straight, &groups[0], &free, &samplers, &index);
        let n = variables.len();
        let x: Vec<[f64; 3]> = variables.iter().map(|&v| mesh.nodes[v as usize]).collect();
        let mut hessian = BlockHessian::pattern(&energy, n).expect("a small patch");
        let mut grad = vec![[0.0; 3]; n];
        let (e, _) = hessian.assemble(&energy, &x, 0.0, &mut grad);
        let mut reference = vec![[0.0; 3]; n];
        assert_eq!(e, energy.evaluate(&x, 0.0, Some(&mut reference)).energy);
        for (a, b) in grad.iter().zip(&reference) {
            for d in 0..dim {
                assert!((a[d] - b[d]).abs() < 1e-10 * (1.0 + b[d].abs()));
            }
        }
        // A direction v moving every free node: H v against (∇E(x + hv) − ∇E(x − hv)) / 2h.
        let v: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let s = i as f64;
                let mut d = [(0.7 * s).sin(), (1.3 * s).cos(), (0.4 * s + 1.0).sin()];
                d[dim..].fill(0.0);
                d
            })
            .collect();
        let mut hv = vec![[0.0; 3]; n];
        hessian.multiply(&v, &mut hv);
        let h = 1e-6;
        let shifted = |sign: f64| {
            let y: Vec<[f64; 3]> = x
                .iter()
                .zip(&v)
                .map(|(x, v)| {
                    [
                        x[0] + sign * h * v[0],
                        x[1] + sign * h * v[1],
                        x[2] + sign * h * v[2],
                    ]
                })
                .collect();
            let mut g = vec![[0.0; 3]; n];
            energy.evaluate(&y, 0.0, Some(&mut g));
            g
        };
        let (plus, minus) = (shifted(1.0), shifted(-1.0));
        let scale = hv.iter().flatten().fold(0.0f64, |m, a| m.max(a.abs()));
        assert!(
            scale > 1.0,
            "dim {dim}: a Hessian that vanishes tests nothing"
        );
        for i in 0..n {
            for d in 0..dim {
                let fd = (plus[i][d] - minus[i][d]) / (2.0 * h);
                assert!(
                    (fd - hv[i][d]).abs() < 1e-6 * scale,
                    "dim {dim} node {i} [{d}]: {fd} vs {}",
                    hv[i][d]
                );
            }
        }
    }
}

/// The repair converges to the minimum of the energy, not to where its iterations happen
/// to stop: the same patch (a boundary node pushed out, so that the minimum is not the
/// straight mesh) untangled from two different tangles ends at one point, to 1e-9 (the
/// conjugate gradients alone left the two 2.6e-4 apart). What makes the same model from
/// STEP and from IGES, 1e-9 apart, curve to the same mesh.
#[test]
fn two_tangles_of_one_patch_are_repaired_to_the_same_minimum() {
    for (dim, order) in [(2, 3), (3, 2)] {
        let centre = [0.5, 0.5, if dim == 3 { 0.5 } else { 0.0 }];
        let run = |to: [f64; 3]| {
            let (mut mesh, straight) = tangled(dim, 2, order, centre, to);
            let fixed = boundary(&mesh);
            // The boundary node nearest (1, 0.5, ·) pushed outwards, as curving would.
            let pushed = fixed
                .iter()
                .copied()
                .min_by(|&a, &b| {
                    let d = |n: u32| {
                        let x = straight[n as usize];
                        (x[0] - 1.0).powi(2) + (x[1] - 0.5).powi(2) + (x[2] - centre[2]).powi(2)
                    };
                    d(a).total_cmp(&d(b))
                })
                .expect("boundary");
            mesh.nodes[pushed as usize][0] += 0.15;
            assert!(
                !not_valid(&mesh).is_empty(),
                "dim {dim}: the test mesh must be tangled"
            );
            // Every cell in the patch: the same free nodes from either tangle.
            let every: Vec<usize> = (0..mesh.cells.len()).collect();
            untangle(
                &mut mesh,
                &straight,
                &every,
                &fixed,
                &UntangleOptions::default(),
            )
            .expect("untangle");
            assert!(not_valid(&mesh).is_empty(), "dim {dim}");
            (mesh.nodes, straight)
        };
        let (a, straight) = run([0.93, 0.4, if dim == 3 { 0.55 } else { 0.0 }]);
        let (b, _) = run([0.1, 0.85, if dim == 3 { 0.2 } else { 0.0 }]);
        let gap = a
            .iter()
            .zip(&b)
            .flat_map(|(p, q)| (0..3).map(move |d| (p[d] - q[d]).abs()))
            .fold(0.0, f64::max);
        let moved = a
            .iter()
            .zip(&straight)
            .flat_map(|(p, q)| (0..3).map(move |d| (p[d] - q[d]).abs()))
            .fold(0.0, f64::max);
        assert!(
            moved > 1e-3,
            "dim {dim}: the minimum is the straight mesh: tests nothing"
        );
        assert!(gap < 1e-9, "dim {dim} p {order}: {gap:e}");
    }
}
