use super::*;
use hocurve_nodes::{NodeFamily, ReferenceNodes, Shape};

fn straight_coords(shape: Shape, p: usize, corners: &[[f64; 3]]) -> Vec<[f64; 3]> {
    ReferenceNodes::new(shape, p, NodeFamily::GaussLobatto)
        .points()
        .iter()
        .map(|&xi| {
            let (w, nv) = shape.vertex_shape_functions(xi);
            let mut x = [0.0; 3];
            for v in 0..nv {
                for d in 0..3 {
                    x[d] += w[v] * corners[v][d];
                }
            }
            x
        })
        .collect()
}

/// uᵀ K u = ∫ σ : ε for a linear field u = A x: 2μ |sym A|² + λ (tr A)² times the volume.
fn check_energy(shape: Shape, corners: &[[f64; 3]], volume: f64) {
    let (lambda, mu) = (1.7, 0.6);
    let dim = shape.dim();
    let a = [[0.3, -0.2, 0.5], [0.7, 0.1, -0.4], [0.2, 0.9, -0.3]];
    let mut strain = 0.0;
    let mut trace = 0.0;
    for c in 0..dim {
        trace += a[c][c];
        for d in 0..dim {
            let e = 0.5 * (a[c][d] + a[d][c]);
            strain += e * e;
        }
    }
    let exact = volume * (2.0 * mu * strain + lambda * trace * trace);
    for p in 1..=4 {
        let reference = ReferenceStiffness::new(shape, p, NodeFamily::GaussLobatto).unwrap();
        let mut scratch = ElementScratch {
            coords: straight_coords(shape, p, corners),
            ..Default::default()
        };
        element_stiffness(&reference, lambda, mu, 0, &mut scratch).unwrap();
        let n = reference.len;
        let mut u = vec![0.0; n * dim];
        for (i, x) in scratch.coords.iter().enumerate() {
            for c in 0..dim {
                u[i * dim + c] = (0..dim).map(|d| a[c][d] * x[d]).sum();
            }
        }
        let size = n * dim;
        let mut energy = 0.0;
        for i in 0..size {
            for j in 0..size {
                energy += u[i] * scratch.matrix[i * size + j] * u[j];
            }
        }
        assert!(
            (energy - exact).abs() < 1e-10 * exact.abs(),
            "{shape:?} p={p}: {energy} vs {exact}"
        );
        // Symmetric, and rigid translations cost nothing.
        for i in 0..size {
            for j in 0..i {
                let (x, y) = (scratch.matrix[i * size + j], scratch.matrix[j * size + i]);
                assert!((x - y).abs() < 1e-11 * (1.0 + x.abs()));
            }
            for c in 0..dim {
                let s: f64 = (0..n).map(|b| scratch.matrix[i * size + b * dim + c]).sum();
                assert!(s.abs() < 1e-10, "translation energy {s}");
            }
        }
    }
}

#[test]
fn linear_fields_have_the_exact_strain_energy_on_every_shape() {
    let tri = [[0.1, 0.0, 0.0], [1.3, 0.2, 0.0], [0.4, 0.9, 0.0]];
    // Area = ½ |(1.2, 0.2) × (0.3, 0.9)| = ½ (1.08 − 0.06) = 0.51.
    check_energy(Shape::Tri, &tri, 0.51);
    // A trapezoid with corners (0,0), (2,0), (1.5,1), (0.5,1): area 1.5.
    let quad = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [1.5, 1.0, 0.0],
        [0.5, 1.0, 0.0],
    ];
    check_energy(Shape::Quad, &quad, 1.5);
    let tet = [
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.0],
        [0.2, 1.0, 0.1],
        [0.1, 0.3, 1.2],
    ];
    // det [[1,0.2,0.1],[0.1,1,0.3],[0,0.1,1.2]] / 6.
    let det = 1.0 * (1.0 * 1.2 - 0.3 * 0.1) - 0.2 * (0.1 * 1.2 - 0.0) + 0.1 * (0.01 - 0.0);
    check_energy(Shape::Tet, &tet, det / 6.0);
    // A frustum-like hexahedron: the unit cube with its top face shrunk to [0.25, 0.75]²
    // at height 1: volume ∫₀¹ (1 − z/2)² dz = 1 − 1/2 + 1/12 = 7/12.
    let hex = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.25, 0.25, 1.0],
        [0.75, 0.25, 1.0],
        [0.75, 0.75, 1.0],
        [0.25, 0.75, 1.0],
    ];
    check_energy(Shape::Hex, &hex, 7.0 / 12.0);
    // A prism with a sheared top: unit right triangle × height 2, volume 1.
    let prism = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.3, 0.1, 2.0],
        [1.3, 0.1, 2.0],
        [0.3, 1.1, 2.0],
    ];
    check_energy(Shape::Prism, &prism, 1.0);
}

#[test]
fn affine_fast_path_equals_quadrature() {
    // Same tetrahedron through both paths: move nothing, but disable the fast path.
    let tet = [
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.0],
        [0.2, 1.0, 0.1],
        [0.1, 0.3, 1.2],
    ];
    for p in 1..=4 {
        let fast = ReferenceStiffness::new(Shape::Tet, p, NodeFamily::Fekete).unwrap();
        let mut slow = fast.clone();
        slow.simplex_stiffness = None;
        let coords = straight_coords(Shape::Tet, p, &tet);
        let mut a = ElementScratch {
            coords: coords.clone(),
            ..Default::default()
        };
        let mut b = ElementScratch {
            coords,
            ..Default::default()
        };
        element_stiffness(&fast, 2.0, 1.0, 0, &mut a).unwrap();
        element_stiffness(&slow, 2.0, 1.0, 0, &mut b).unwrap();
        let scale = a.matrix.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for (x, y) in a.matrix.iter().zip(&b.matrix) {
            assert!((x - y).abs() < 1e-12 * scale, "p={p}: {x} vs {y}");
        }
    }
}

#[test]
fn collapsed_cells_are_errors() {
    let reference = ReferenceStiffness::new(Shape::Tri, 2, NodeFamily::Equispaced).unwrap();
    let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let mut scratch = ElementScratch {
        coords: straight_coords(Shape::Tri, 2, &flat),
        ..Default::default()
    };
    let err = element_stiffness(&reference, 1.0, 1.0, 7, &mut scratch).unwrap_err();
    assert!(matches!(err, ElasticError::DegenerateCell { cell: 7, .. }));
}
