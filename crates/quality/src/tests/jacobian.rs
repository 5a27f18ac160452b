use super::*;
use crate::test_meshes::{hash01, single_element, single_element_of_family};
use hocurve_mesh::Shape;
use hocurve_nodes::{QuadratureRule, ReferenceNodes};
use hocurve_testmeshes::{unit_cube, Fill, Kuhn};

const ALL_TYPES: [Shape; 5] = [
    Shape::Tri,
    Shape::Quad,
    Shape::Tet,
    Shape::Hex,
    Shape::Prism,
];
const ALL_SAMPLINGS: [Sampling; 3] = [Sampling::Quadrature, Sampling::Nodes, Sampling::Both];

/// A dense set of reference points of `shape` including its vertices: the equispaced
/// order-10 lattice.
fn dense_points(shape: Shape) -> Vec<[f64; 3]> {
    ReferenceNodes::new(shape, 10, NodeFamily::Equispaced)
        .points()
        .to_vec()
}

#[test]
fn affine_elements_of_every_type_have_unit_scaled_jacobian() {
    // A general affine map with det A = 2.57 > 0: J = A everywhere, so Ĩ = 1.
    let affine = |x: [f64; 3]| {
        [
            1.3 * x[0] + 0.4 * x[1] - 0.2 * x[2] + 5.0,
            -0.3 * x[0] + 1.1 * x[1] + 0.1 * x[2] - 2.0,
            0.2 * x[0] + 0.1 * x[1] + 1.7 * x[2] + 1e3,
        ]
    };
    for kind in ALL_TYPES {
        for family in NodeFamily::ALL {
            for p in 1..=4 {
                let mesh = single_element_of_family(kind, p, family, |x| {
                    let y = affine(x);
                    if kind.dim() == 2 {
                        [y[0], y[1], 0.0]
                    } else {
                        y
                    }
                });
                for sampling in ALL_SAMPLINGS {
                    let q = scaled_jacobian(&mesh, sampling).unwrap()[0];
                    // Not bit-exact: the basis gradients carry the rounding of the
                    // Vandermonde inverse (cond ~ 10² at p = 4).
                    assert!((q - 1.0).abs() < 1e-11, "{kind} {family} p={p}: {q}");
                }
            }
        }
    }
}

#[test]
fn bilinear_quad_matches_the_hand_derivation() {
    // Corners (0,0), (1,0), (c,d), (0,1): x = ξ(1 + (c−1)η), y = η(1 + (d−1)ξ), so
    // x_ξ y_η − x_η y_ξ = (1+(c−1)η)(1+(d−1)ξ) − (c−1)ξ (d−1)η = 1 + (d−1)ξ + (c−1)η:
    // linear, extreme at the corners: values 1, d, c, c+d−1 → with c = 1.5, d = 1.2,
    // Ĩ = 1 / 1.7. At the interior Gauss points g₀ < … < g_last of the quadrature rule
    // it is (1 + 0.7 g₀) / (1 + 0.7 g_last).
    let (c, d) = (1.5, 1.2);
    let bilinear = |x: [f64; 3]| {
        [
            x[0] * (1.0 + (c - 1.0) * x[1]),
            x[1] * (1.0 + (d - 1.0) * x[0]),
            0.0,
        ]
    };
    for p in 1..=3 {
        let mesh = single_element(Shape::Quad, p, bilinear);
        let exact = 1.0 / 1.7;
        for sampling in [Sampling::Nodes, Sampling::Both] {
            let q = scaled_jacobian(&mesh, sampling).unwrap()[0];
            assert!((q - exact).abs() < 1e-13, "p={p}: {q}");
        }
        let gauss = hocurve_nodes::gauss_legendre(p + 1).points;
        let (g0, g1) = (0.5 * (gauss[0] + 1.0), 0.5 * (gauss[p] + 1.0));
        let at_quadrature = (1.0 + 0.7 * g0) / (1.0 + 0.7 * g1);
        let q = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
        assert!(
            (q - at_quadrature).abs() < 1e-13,
            "p={p}: {q} vs {at_quadrature}"
        );
        assert!(q > exact);
    }
}

#[test]
fn trilinear_hex_matches_the_hand_derivation() {
    // x = ξ(1 + αη), y = η, z = ζ(1 + βξ) (vertices (1,1,·) and (1,·,1) moved):
    // J = [[1+αη, αξ, 0], [0, 1, 0], [βζ, 0, 1+βξ]], det J = (1+αη)(1+βξ) by expansion
    // along the second row. Extremes at (0,0,·) and (1,1,·): Ĩ = 1/((1+α)(1+β)).
    let (alpha, beta) = (0.5, 0.3);
    let map = |x: [f64; 3]| {
        [
            x[0] * (1.0 + alpha * x[1]),
            x[1],
            x[2] * (1.0 + beta * x[0]),
        ]
    };
    for p in 1..=3 {
        let mesh = single_element(Shape::Hex, p, map);
        let exact = 1.0 / ((1.0 + alpha) * (1.0 + beta));
        let q = scaled_jacobian(&mesh, Sampling::Both).unwrap()[0];
        assert!((q - exact).abs() < 1e-13, "p={p}: {q}");
        let gauss = hocurve_nodes::gauss_legendre(p + 1).points;
        let (g0, g1) = (0.5 * (gauss[0] + 1.0), 0.5 * (gauss[p] + 1.0));
        let at_quadrature =
            (1.0 + alpha * g0) * (1.0 + beta * g0) / ((1.0 + alpha * g1) * (1.0 + beta * g1));
        let q = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
        assert!((q - at_quadrature).abs() < 1e-13, "p={p}: {q}");
    }
}

#[test]
fn curved_elements_match_the_analytic_jacobian() {
    // x ↦ x + εx² (p ≥ 2) or x + εx³ (p ≥ 3) in the first coordinate: det J = 1 + 2εξ or
    // 1 + 3εξ², from 1 at ξ = 0 to 1 + 2ε or 1 + 3ε at ξ = 1 (every shape spans
    // ξ ∈ [0, 1]), so Ĩ = 1/(1 + 2ε) or 1/(1 + 3ε).
    let eps = 0.4;
    type Case = (usize, fn(f64) -> f64, fn(f64) -> f64, f64);
    let cases: [Case; 2] = [
        (
            2,
            |x| x + 0.4 * x * x,
            |x| 1.0 + 0.8 * x,
            1.0 / (1.0 + 2.0 * eps),
        ),
        (
            3,
            |x| x + 0.4 * x * x * x,
            |x| 1.0 + 1.2 * x * x,
            1.0 / (1.0 + 3.0 * eps),
        ),
    ];
    for kind in ALL_TYPES {
        let shape = kind;
        for (min_order, map, det, exact) in cases {
            for p in min_order..=4 {
                let mesh = single_element(kind, p, |x| [map(x[0]), x[1], x[2]]);
                let dense = dense_points(shape);
                let dets = jacobian_determinants(&mesh, 0, &dense).unwrap();
                for (x, d) in dense.iter().zip(&dets) {
                    assert!((d - det(x[0])).abs() < 1e-10, "{kind} p={p} at {x:?}");
                }
                let (lo, hi) = min_max(&dets);
                assert!((scaled_ratio(lo, hi) - exact).abs() < 1e-10);
                // The paper's quadrature sampling sees a value ≥ the true minimum, and
                // exactly the analytic value at its own points.
                let rule = QuadratureRule::new(shape, 2 * p);
                let (xmin, xmax) = min_max(&rule.points.iter().map(|x| x[0]).collect::<Vec<_>>());
                let q = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0];
                assert!(q >= exact, "{kind} p={p}: {q} < {exact}");
                assert!((q - det(xmin) / det(xmax)).abs() < 1e-10, "{kind} p={p}");
                let q = scaled_jacobian(&mesh, Sampling::Nodes).unwrap()[0];
                assert!((q - exact).abs() < 1e-10, "{kind} p={p}");
            }
        }
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let linear = unit_cube(3, Fill::Tet(Kuhn::Lexicographic), 0.0);
    let mut mesh = HighOrderMesh::from_linear(&linear, 3, NodeFamily::Fekete).unwrap();
    for (i, x) in mesh.nodes.iter_mut().enumerate() {
        for d in 0..3 {
            x[d] += 0.005 * (hash01(3 * i as u64 + d as u64) - 0.5);
        }
    }
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| scaled_jacobian(&mesh, Sampling::Both).unwrap())
    };
    let one = run(1);
    assert_eq!(one.len(), 162);
    let (lo, hi) = min_max(&one);
    assert!(lo > 0.0 && hi < 1.0, "{lo} {hi}");
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&run(2)));
    assert_eq!(bits(&one), bits(&run(3)));
}

#[test]
fn inverted_and_degenerate_elements_score_at_most_zero() {
    // Mirrored triangle: det J = −1 everywhere → Ĩ = −1/1 = −1.
    let mesh = single_element(Shape::Tri, 2, |x| [x[1], x[0], 0.0]);
    let q = scaled_jacobian(&mesh, Sampling::Both).unwrap()[0];
    assert!((q + 1.0).abs() < 1e-13, "{q}");
    // Flattened tet: det J ≡ 0 → 0.
    let mesh = single_element(Shape::Tet, 2, |x| [x[0], x[1], 0.0]);
    assert_eq!(
        scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0],
        0.0
    );
    // NaN coordinates → counted as invalid (0), never NaN.
    let mesh = single_element(Shape::Quad, 1, |x| [x[0], f64::NAN, 0.0]);
    assert_eq!(
        scaled_jacobian(&mesh, Sampling::Quadrature).unwrap()[0],
        0.0
    );
}

#[test]
fn bad_input_is_reported_with_the_element() {
    let mut mesh = single_element(Shape::Tet, 2, |x| x);
    assert!(matches!(
        jacobian_determinants(&mesh, 3, &[[0.1; 3]]),
        Err(QualityError::ElementOutOfRange {
            element: 3,
            count: 1
        })
    ));
    mesh.cells[0].nodes[4] = 999;
    let err = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap_err();
    assert!(matches!(
        err,
        QualityError::NodeOutOfRange {
            element: 0,
            node: 999,
            ..
        }
    ));
    mesh.cells[0].nodes.pop();
    let err = scaled_jacobian(&mesh, Sampling::Quadrature).unwrap_err();
    assert!(err.to_string().contains("has 9 nodes"), "{err}");
}

/// Throughput on ~1 M order-3 tetrahedra (not a timed assertion; run with
/// `cargo test -p hocurve-quality --release -- --ignored --nocapture throughput`).
#[test]
#[ignore]
fn throughput_one_million_p3_tets() {
    let t = std::time::Instant::now();
    let linear = unit_cube(55, Fill::Tet(Kuhn::Lexicographic), 0.0);
    let mesh = HighOrderMesh::from_linear(&linear, 3, NodeFamily::Fekete).unwrap();
    println!(
        "{} tets, {} nodes, built in {:.2?}",
        mesh.cells.len(),
        mesh.nodes.len(),
        t.elapsed()
    );
    for sampling in ALL_SAMPLINGS {
        let t = std::time::Instant::now();
        let q = scaled_jacobian(&mesh, sampling).unwrap();
        println!("scaled_jacobian {sampling:?}: {:.2?}", t.elapsed());
        assert!(q.iter().all(|&v| (v - 1.0).abs() < 1e-10));
    }
    let t = std::time::Instant::now();
    let checks = crate::check_validity(&mesh, &crate::BezierOptions::default()).unwrap();
    println!("check_validity: {:.2?}", t.elapsed());
    assert!(checks.iter().all(|c| c.validity == crate::Validity::Valid));
    let t = std::time::Instant::now();
    let quality = crate::assess(&mesh, &crate::QualityOptions::default()).unwrap();
    println!("assess (quadrature, no Bézier): {:.2?}", t.elapsed());
    println!("{}", quality.summary);
    for shape in [
        Shape::Tri,
        Shape::Quad,
        Shape::Tet,
        Shape::Hex,
        Shape::Prism,
    ] {
        for p in 1..=4 {
            let space = crate::BernsteinSpace::for_jacobian(shape, p).unwrap();
            println!(
                "{shape:?} p={p}: {} coefficients, conversion norm {:.3e}",
                space.len(),
                space.conversion_norm()
            );
        }
    }
}
