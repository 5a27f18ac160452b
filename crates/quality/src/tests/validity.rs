use super::*;
use crate::jacobian::jacobian_determinants;
use crate::test_meshes::{hash01, single_element};
use crate::{scaled_jacobian, Sampling};
use hocurve_mesh::Shape;
use hocurve_testmeshes::{unit_cube, Fill, Kuhn};

const ALL_TYPES: [Shape; 5] = [
    Shape::Tri,
    Shape::Quad,
    Shape::Tet,
    Shape::Hex,
    Shape::Prism,
];

fn check_one(mesh: &HighOrderMesh, max_depth: usize) -> ValidityCheck {
    check_validity(
        mesh,
        &BezierOptions {
            max_depth,
            ..BezierOptions::default()
        },
    )
    .unwrap()[0]
}

/// Deterministic random points inside the reference element.
fn random_points(shape: Shape, count: usize) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    let mut seed = 7;
    while out.len() < count {
        let mut x = [0.0; 3];
        for c in x.iter_mut().take(shape.dim()) {
            *c = hash01(seed);
            seed += 1;
        }
        let inside = match shape {
            Shape::Tri | Shape::Prism => x[0] + x[1] <= 1.0,
            Shape::Tet => x[0] + x[1] + x[2] <= 1.0,
            _ => true,
        };
        if inside {
            out.push(x);
        }
    }
    out
}

#[test]
fn bezier_coefficients_reproduce_det_j_at_random_points() {
    // Randomly curved elements: every node moved by up to ±4 % of the element size. If a
    // degree of jacobian_degree were too low, the Bernstein polynomial could not match.
    for kind in ALL_TYPES {
        let shape = kind;
        // Quadrilaterals and hexahedra take their coefficients from the map's control
        // points (hexahedra to p = 8 against their error bound in the test below).
        let top = if matches!(shape, Shape::Quad | Shape::Hex) {
            5
        } else {
            3
        };
        for p in 1..=top {
            let mut mesh = single_element(kind, p, |x| x);
            for (i, x) in mesh.nodes.iter_mut().enumerate() {
                for d in 0..shape.dim() {
                    x[d] += 0.08 * (hash01(97 * i as u64 + d as u64) - 0.5);
                }
            }
            let bezier = JacobianBezier::new(shape, p, mesh.family).unwrap();
            let coords: Vec<[f64; 3]> = mesh.cells[0]
                .nodes
                .iter()
                .map(|&n| mesh.nodes[n as usize])
                .collect();
            let c = bezier.coefficients(&coords);
            let points = random_points(shape, 25);
            let want = jacobian_determinants(&mesh, 0, &points).unwrap();
            for (x, w) in points.iter().zip(&want) {
                let got = bezier.space().eval(&c, *x);
                // The reference value comes through the order-p Lagrange basis, whose own
                // rounding grows with p (6e-11 at p = 5 on the hexahedron).
                assert!(
                    (got - w).abs() < 1e-11 * 10f64.powi(p as i32 - 3).max(1.0),
                    "{kind} p={p} at {x:?}: {got} vs {w}"
                );
            }
        }
    }
}

#[test]
fn curved_valid_elements_are_certified_with_bounds_around_the_true_value() {
    // det J = 1 + 2εξ on every shape (see the jacobian tests): Ĩ = 1/(1 + 2ε).
    let eps = 0.4;
    let exact = 1.0 / (1.0 + 2.0 * eps);
    for kind in ALL_TYPES {
        for p in 2..=3 {
            let mesh = single_element(kind, p, |x| [x[0] + eps * x[0] * x[0], x[1], x[2]]);
            let check = check_one(&mesh, 4);
            assert_eq!(check.validity, Validity::Valid, "{kind} p={p}");
            // One region suffices: a positive polynomial with positive coefficients.
            assert_eq!(check.regions, 1, "{kind} p={p}");
            let (lo, hi) = (
                check.scaled_jacobian_lower_bound,
                check.scaled_jacobian_upper_bound,
            );
            assert!(
                lo <= exact + 1e-12 && exact <= hi + 1e-12,
                "{kind} p={p}: {lo} {hi}"
            );
            // Lattice sampling includes the vertices, where the extremes are: tight.
            // Up to the rounding margin, which ‖M⁻¹‖∞ amplifies (≈ 10⁻⁷ relative for
            // hexahedra at p = 3, see the module doc).
            assert!(
                (lo - exact).abs() < 1e-6 && (hi - exact).abs() < 1e-12,
                "{check:?}"
            );
            assert!((check.min_jacobian_lower_bound - 1.0).abs() < 1e-6);
        }
    }
}

#[test]
fn inversion_at_a_vertex_missed_by_quadrature_is_invalid() {
    // P2 triangle whose edge-0 mid node slides by a along the edge: x = ξ + 4aξ(1−ξ−η),
    // y = η, det J = 1 + 4a(1 − 2ξ − η): −0.2 at vertex (1, 0) for a = 0.3, positive at
    // every interior quadrature point.
    let a = 0.3;
    let mesh = single_element(Shape::Tri, 2, |x| {
        [x[0] + 4.0 * a * x[0] * (1.0 - x[0] - x[1]), x[1], 0.0]
    });
    let sampled = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
    assert!(
        sampled > 0.0,
        "the quadrature points should miss it: {sampled}"
    );
    let check = check_one(&mesh, 4);
    assert_eq!(check.validity, Validity::Invalid);
    let exact = (1.0 - 4.0 * a) / (1.0 + 4.0 * a);
    assert!(check.scaled_jacobian_lower_bound <= exact + 1e-12);
    assert!(check.scaled_jacobian_upper_bound >= exact - 1e-12);
    assert!(check.scaled_jacobian_upper_bound < 0.0);
}

/// x = Aξ + (B/3)(ξ − ½)³, y = η (z = ζ): det J = A + B(ξ − ½)², negative only for
/// |ξ − ½| < √(−A/B) = 0.08 (with A = −0.0256, B = 4) — between the Gauss points
/// (nearest 0.33, 0.67 at p = 3), the equispaced nodes (1/3, 2/3) and, for the
/// quadrilateral, the degree-5 Bernstein lattice (0.4, 0.6). The hexahedron's degree-8
/// lattice has ξ = ½ and finds it at once.
fn strip_fold(x: [f64; 3]) -> [f64; 3] {
    let (a, b) = (-0.0256, 4.0);
    [a * x[0] + b / 3.0 * (x[0] - 0.5).powi(3), x[1], x[2]]
}

#[test]
fn inversion_strictly_between_all_sample_points_is_never_called_valid() {
    for kind in [Shape::Quad, Shape::Hex] {
        let mesh = single_element(kind, 3, strip_fold);
        for sampling in [Sampling::Quadrature, Sampling::Nodes, Sampling::Both] {
            let sampled = scaled_jacobian(&mesh, sampling).unwrap()[0];
            assert!(sampled > 0.0, "{kind} {sampling:?}: {sampled}");
        }
        let unrefined = check_one(&mesh, 0);
        assert_ne!(unrefined.validity, Validity::Valid, "{kind}");
        let check = check_one(&mesh, 4);
        assert_eq!(check.validity, Validity::Invalid, "{kind}");
        if kind == Shape::Quad {
            // Not decided on the whole element; one halving puts a lattice point at
            // ξ = ½ where det J = A < 0.
            assert_eq!(unrefined.validity, Validity::Undecided);
            assert!(check.regions > 1, "{check:?}");
        }
        let exact = -0.0256 / (-0.0256 + 1.0);
        assert!(
            check.scaled_jacobian_lower_bound <= exact,
            "{kind}: {check:?}"
        );
        assert!(
            check.scaled_jacobian_upper_bound >= exact,
            "{kind}: {check:?}"
        );
    }
}

#[test]
fn jacobian_touching_zero_is_undecided() {
    // det J = 4(ξ − ½)² ≥ 0 with a zero on the plane ξ = ½: neither certificate applies.
    for kind in [Shape::Quad, Shape::Prism] {
        let mesh = single_element(kind, 3, |x| [4.0 / 3.0 * (x[0] - 0.5).powi(3), x[1], x[2]]);
        let check = check_one(&mesh, 2);
        assert_eq!(check.validity, Validity::Undecided, "{kind}");
        assert!(check.min_jacobian_lower_bound <= 0.0);
        assert!(check.regions > 1);
    }
}

#[test]
fn straight_meshes_are_valid_and_the_check_is_deterministic() {
    let linear = unit_cube(2, Fill::Tet(Kuhn::Lexicographic), 0.0);
    let mut mesh =
        HighOrderMesh::from_linear(&linear, 3, hocurve_nodes::NodeFamily::Fekete).unwrap();
    let checks = check_validity(&mesh, &BezierOptions::default()).unwrap();
    assert!(checks
        .iter()
        .all(|c| c.validity == Validity::Valid && c.regions == 1));
    assert!(checks
        .iter()
        .all(|c| (c.scaled_jacobian_lower_bound - 1.0).abs() < 1e-9));
    for (i, x) in mesh.nodes.iter_mut().enumerate() {
        for d in 0..3 {
            x[d] += 0.01 * (hash01(5 * i as u64 + d as u64) - 0.5);
        }
    }
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| check_validity(&mesh, &BezierOptions::default()).unwrap())
    };
    let one = run(1);
    assert_eq!(one, run(2));
    // The certified lower bound never exceeds the sampled scaled Jacobian.
    let sampled = scaled_jacobian(&mesh, Sampling::Both).unwrap();
    for (c, s) in one.iter().zip(&sampled) {
        assert!(c.scaled_jacobian_lower_bound <= s + 1e-12);
        if c.validity == Validity::Valid {
            assert!(c.scaled_jacobian_lower_bound > 0.0);
        }
    }
}

/// det J of a hexahedron at ξ from its nodes through 1D Lagrange polynomials on the tensor
/// nodes (the product formula, independent of the Vandermonde-based basis).
fn hex_det_by_tensor_lagrange(reference: &[[f64; 3]], coords: &[[f64; 3]], xi: [f64; 3]) -> f64 {
    let mut line: Vec<f64> = reference.iter().map(|x| x[0]).collect();
    line.sort_by(f64::total_cmp);
    line.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let ell = |i: usize, t: f64| -> (f64, f64) {
        // ℓ_i(t) and ℓ_i'(t).
        let mut value = 1.0;
        let mut slope = 0.0;
        for (m, &tm) in line.iter().enumerate() {
            if m == i {
                continue;
            }
            let factor = (t - tm) / (line[i] - tm);
            slope = slope * factor + value / (line[i] - tm);
            value *= factor;
        }
        (value, slope)
    };
    let index = |t: f64| line.iter().position(|&u| (u - t).abs() < 1e-12).unwrap();
    let mut j = [[0.0; 3]; 3];
    for (x, r) in coords.iter().zip(reference) {
        let (a, b, c) = (index(r[0]), index(r[1]), index(r[2]));
        let (la, da) = ell(a, xi[0]);
        let (lb, db) = ell(b, xi[1]);
        let (lc, dc) = ell(c, xi[2]);
        let grad = [da * lb * lc, la * db * lc, la * lb * dc];
        for d in 0..3 {
            for k in 0..3 {
                j[d][k] += x[d] * grad[k];
            }
        }
    }
    determinant(&j, 3)
}

#[test]
fn hexahedron_coefficients_match_det_j_by_1d_lagrange_products_within_their_error_bound() {
    // Every node moved at random: a generic map of Q_p, whose control points oscillate
    // more with p (the bound grows accordingly, and stays small for smooth maps).
    for p in [2, 4, 6, 8] {
        let mut mesh = single_element(Shape::Hex, p, |x| x);
        for (i, x) in mesh.nodes.iter_mut().enumerate() {
            for d in 0..3 {
                x[d] += 0.08 * (hash01(97 * i as u64 + d as u64) - 0.5);
            }
        }
        let tensor = crate::bezier_map::TensorJacobian::new(Shape::Hex, p, mesh.family)
            .unwrap()
            .expect("tensor nodes");
        let space = BernsteinSpace::for_jacobian(Shape::Hex, p).unwrap();
        let coords: Vec<[f64; 3]> = mesh.cells[0]
            .nodes
            .iter()
            .map(|&n| mesh.nodes[n as usize])
            .collect();
        let reference = hocurve_nodes::ReferenceNodes::new(Shape::Hex, p, mesh.family);
        let (c, error) = tensor.coefficients(&coords);
        // Σ B_α = 1: the value's error is at most the coefficients' error bound.
        let mut worst = 0.0f64;
        for x in random_points(Shape::Hex, 25) {
            let want = hex_det_by_tensor_lagrange(reference.points(), &coords, x);
            let got = space.eval(&c, x);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= error + 1e-12,
                "p = {p} at {x:?}: {got} vs {want}, bound {error:e}"
            );
        }
        // The bound is not vacuous (det J ≈ 1 here) up to p = 4; beyond, random nodes on
        // equispaced points make control points (and the bound) explode — smooth curved
        // elements stay certifiable (the hybrid mesh at p = 6: Ĩ ≥ 0.22).
        if p <= 4 {
            assert!(error < 1e-3, "p = {p}: bound {error:e}");
        }
        assert!(worst <= error, "p = {p}");
    }
}

/// x = Aξ + (B/3)(ξ − 0.3)³ (see below): Ĩ = A / (A + 0.49 B) exactly.
const CUBIC_A: f64 = 0.1;
const CUBIC_B: f64 = 4.0;
const CUBIC_EXACT: f64 = CUBIC_A / (CUBIC_A + 0.49 * CUBIC_B);

/// One element of `kind` at p = 3 under that map: its checker, node coordinates, Bézier
/// check and workspace.
fn cubic_element(
    kind: Shape,
) -> (
    JacobianBezier,
    Vec<[f64; 3]>,
    ValidityCheck,
    BezierWorkspace,
) {
    let (a, b) = (CUBIC_A, CUBIC_B);
    let mesh = single_element(kind, 3, |x| {
        [a * x[0] + b / 3.0 * (x[0] - 0.3).powi(3), x[1], x[2]]
    });
    let checker = JacobianBezier::new(kind, 3, mesh.family).unwrap();
    let coords: Vec<[f64; 3]> = mesh.cells[0]
        .nodes
        .iter()
        .map(|&n| mesh.nodes[n as usize])
        .collect();
    let mut ws = BezierWorkspace::default();
    let check = checker.check_with(&coords, &BezierOptions::default(), &mut ws);
    (checker, coords, check, ws)
}

#[test]
fn narrowed_bounds_close_in_on_the_true_scaled_jacobian() {
    // x = Aξ + (B/3)(ξ − 0.3)³: det J = A + B(ξ − 0.3)², smallest (A) inside at ξ = 0.3 (no
    // lattice or subdivision point), largest at ξ = 1: Ĩ = A / (A + 0.49 B) exactly. The
    // check's bound is far below it (its coefficients dip below A); refinement must reach
    // 95 % of it without passing it.
    let (a, b, exact) = (CUBIC_A, CUBIC_B, CUBIC_EXACT);
    for kind in ALL_TYPES {
        let (checker, coords, check, mut ws) = cubic_element(kind);
        assert_eq!(check.validity, Validity::Valid, "{kind}");
        assert!(
            check.scaled_jacobian_lower_bound < 0.9 * exact,
            "{kind}: {check:?}"
        );
        let goal = |max_regions| NarrowingGoal {
            target: 0.95 * exact,
            relative: 0.95,
            max_regions,
        };
        let narrowed = checker.refine_bounds(&coords, &check, &goal(4096), &mut ws);
        let (lo, hi) = (
            narrowed.scaled_jacobian_lower_bound,
            narrowed.scaled_jacobian_upper_bound,
        );
        assert!(
            lo >= 0.95 * exact && lo <= exact + 1e-9,
            "{kind}: {lo} vs {exact}"
        );
        assert!(hi >= exact - 1e-9, "{kind}: {hi} vs {exact}");
        assert!(narrowed.min_jacobian_lower_bound <= a + 1e-9);
        assert!(narrowed.max_jacobian_upper_bound >= a + 0.49 * b - 1e-9);
        assert_eq!(narrowed.validity, Validity::Valid);
        // With a budget of one region the bounds stay.
        let kept = checker.refine_bounds(&coords, &check, &goal(1), &mut ws);
        assert_eq!(
            kept.scaled_jacobian_lower_bound,
            check.scaled_jacobian_lower_bound
        );
    }
}

/// An element whose Ĩ lies below the mesh's target (the target came from values elsewhere,
/// or from corner values that miss its minimum) cannot reach it: narrowing stops once the
/// bound is within `relative` of the element's own upper bound, in a few regions, instead
/// of spending the whole budget (every cell of a layered sphere shell at p = 3 did: 57 s).
#[test]
fn narrowing_stops_at_the_elements_own_bound_when_the_target_is_out_of_reach() {
    let exact = CUBIC_EXACT;
    for kind in ALL_TYPES {
        let (checker, coords, check, mut ws) = cubic_element(kind);
        let goal = NarrowingGoal {
            target: 0.99,
            relative: 0.95,
            max_regions: 4096,
        };
        let narrowed = checker.refine_bounds(&coords, &check, &goal, &mut ws);
        let (lo, hi) = (
            narrowed.scaled_jacobian_lower_bound,
            narrowed.scaled_jacobian_upper_bound,
        );
        assert!(
            lo >= 0.95 * hi && lo <= exact + 1e-9,
            "{kind}: {lo} {hi} vs {exact}"
        );
        assert!(hi >= exact - 1e-9, "{kind}: {hi} vs {exact}");
        assert!(
            narrowed.regions < 400,
            "{kind}: {} regions",
            narrowed.regions
        );
    }
}

#[test]
fn the_mesh_bound_is_narrowed_to_the_tightness_asked_for() {
    let (a, b) = (0.1, 4.0);
    let exact = a / (a + 0.49 * b);
    for kind in [Shape::Tet, Shape::Hex] {
        let mesh = single_element(kind, 3, |x| {
            [a * x[0] + b / 3.0 * (x[0] - 0.3).powi(3), x[1], x[2]]
        });
        let loose = BezierOptions {
            tightness: 0.0,
            ..BezierOptions::default()
        };
        let before = check_validity(&mesh, &loose).unwrap()[0];
        let after = check_validity(&mesh, &BezierOptions::default()).unwrap()[0];
        assert!(before.scaled_jacobian_lower_bound < 0.9 * exact);
        // The target is 95 % of the smallest value sampled, itself ≥ the exact Ĩ.
        assert!(
            after.scaled_jacobian_lower_bound >= 0.95 * exact
                && after.scaled_jacobian_lower_bound <= exact + 1e-9,
            "{kind}: {after:?}"
        );
    }
}

/// Triangles and tetrahedra are decided from det J's exact coefficients and their exact
/// bisections at every order to p = 10 (degree 27 on the tetrahedron, past the sampled
/// conversion's limit): a curved valid element in one region with bounds around the truth,
/// a fold between every sample point found, a det J touching zero left undecided.
#[test]
fn simplices_are_decided_at_every_order_to_ten() {
    let eps = 0.4;
    let exact = 1.0 / (1.0 + 2.0 * eps);
    for kind in [Shape::Tri, Shape::Tet] {
        for p in [3, 6, 8, 10] {
            let mesh = single_element(kind, p, |x| [x[0] + eps * x[0] * x[0], x[1], x[2]]);
            let check = check_one(&mesh, 4);
            assert_eq!(check.validity, Validity::Valid, "{kind} p={p}");
            assert_eq!(check.regions, 1, "{kind} p={p}");
            let (lo, hi) = (
                check.scaled_jacobian_lower_bound,
                check.scaled_jacobian_upper_bound,
            );
            assert!(
                lo <= exact && exact <= hi + 1e-12,
                "{kind} p={p}: {lo} {hi}"
            );
            assert!(exact - lo < 1e-6, "{kind} p={p}: {lo}");

            let fold = single_element(kind, p, strip_fold);
            let sampled = scaled_jacobian(&fold, Sampling::Quadrature).unwrap()[0];
            let check = check_one(&fold, 4);
            assert_eq!(
                check.validity,
                Validity::Invalid,
                "{kind} p={p} (sampled {sampled})"
            );
            assert!(
                check.scaled_jacobian_upper_bound < 0.0,
                "{kind} p={p}: {check:?}"
            );

            let touching =
                single_element(kind, p, |x| [4.0 / 3.0 * (x[0] - 0.5).powi(3), x[1], x[2]]);
            let check = check_one(&touching, 2);
            assert_eq!(check.validity, Validity::Undecided, "{kind} p={p}");
            assert!(check.min_jacobian_lower_bound <= 0.0);
            // Bisections only, as deep as two midpoint refinements.
            assert!(check.regions > 1 && check.regions < 1 << (2 * kind.dim() + 1));
        }
    }
}
