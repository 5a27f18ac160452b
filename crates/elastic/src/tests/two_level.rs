use super::*;
use crate::assembly::assemble;
use crate::block_matrix::{BlockOperator, BlockPattern};
use crate::condensation::condense_matrix;
use crate::pcg::pcg;
use crate::vector_ops::spmv;
use crate::{BoundaryConditions, Material};
use hocurve_mesh::{Element, ElementType, LinearMesh};
use hocurve_nodes::NodeFamily;

/// The unit cube as n³ small cubes of 6 tetrahedra each, interior vertices moved by up to
/// 20 % of h so that the cells are general.
pub(crate) fn tet_cube(n: usize) -> LinearMesh {
    let h = 1.0 / n as f64;
    let id = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let mut vertices = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let mut x = [i as f64 * h, j as f64 * h, k as f64 * h];
                if [i, j, k].iter().all(|&c| c > 0 && c < n) {
                    for (d, xd) in x.iter_mut().enumerate() {
                        let t = (i * 12 + j * 78 + k * 37 + d * 4) as f64;
                        *xd += 0.2 * h * ((t.sin() * 43758.5453).fract() * 2.0 - 1.0);
                    }
                }
                vertices.push(x);
            }
        }
    }
    let volume = |v: &[[f64; 3]], t: &[u32]| {
        let p = |k: usize| v[t[k] as usize];
        let e = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
        let (u, w, z) = (e(p(1), p(0)), e(p(2), p(0)), e(p(3), p(0)));
        u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0])
            + u[2] * (w[0] * z[1] - w[1] * z[0])
    };
    let mut cells = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let v = |b: usize| id(i + (b & 1), j + ((b >> 1) & 1), k + (b >> 2));
                for (a, b) in [(1, 2), (2, 1), (1, 4), (4, 1), (2, 4), (4, 2)] {
                    let mut tet = vec![v(0), v(a), v(a | b), v(7)];
                    if volume(&vertices, &tet) < 0.0 {
                        tet.swap(2, 3);
                    }
                    cells.push(Element {
                        kind: ElementType::Tet,
                        vertices: tet,
                        entity: 1,
                    });
                }
            }
        }
    }
    LinearMesh {
        dim: 3,
        vertices,
        cells,
        ..Default::default()
    }
}

/// The condensed system of the cube with its bottom fixed and its top pushed sideways.
fn cube_system(n: usize, p: usize) -> (HighOrderMesh, StiffnessMatrix, Vec<f64>, Constraints) {
    let mesh = HighOrderMesh::from_linear(&tet_cube(n), p, NodeFamily::Fekete).unwrap();
    let assembled = assemble(&mesh, &Material::default()).unwrap();
    let mut bc = BoundaryConditions::default();
    for (node, x) in mesh.nodes.iter().enumerate() {
        if x[2] < 1e-12 {
            bc.prescribed.insert(node as u32, [0.0; 3]);
        } else if x[2] > 1.0 - 1e-12 {
            bc.prescribed.insert(node as u32, [0.1, 0.05 * x[0], 0.0]);
        }
    }
    let constraints = Constraints::new(mesh.nodes.len(), 3, &bc);
    let mut full = vec![0.0; mesh.nodes.len() * 3];
    spmv(&assembled.matrix, &constraints.prescribed, &mut full);
    full.iter_mut().for_each(|v| *v = -*v);
    let rhs = constraints.restrict(&full);
    let a = condense_matrix(&assembled.matrix, &assembled.graph, &constraints);
    (mesh, a, rhs, constraints)
}

/// Point Jacobi, z = diag(A)⁻¹ r: the reference whose iteration count grows with p.
struct PointJacobi(Vec<f64>);
impl Preconditioner for PointJacobi {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        z.iter_mut()
            .zip(r.iter().zip(&self.0))
            .for_each(|(z, (r, d))| *z = r / d);
    }
}

#[test]
fn lanczos_estimates_the_smoothed_spectrum() {
    let (mesh, a, _, constraints) = cube_system(2, 3);
    let assembled = assemble(&mesh, &Material::default()).unwrap();
    let mut two_level = TwoLevel::new(
        &a,
        &a,
        &constraints,
        &mesh,
        &assembled.cells_of_node,
        &assembled.references,
        3,
    )
    .unwrap();
    let estimate = two_level.estimate_lambda_max();
    // Reference: many power steps on B A, which is similar to the symmetric positive
    // definite B^½ A B^½; the Lanczos value must be just below it.
    let n = a.rows();
    let mut x: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
    let (mut ax, mut y) = (vec![0.0; n], vec![0.0; n]);
    let mut lambda = 0.0;
    for _ in 0..2000 {
        let len = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        x.iter_mut().for_each(|v| *v /= len);
        spmv(&a, &x, &mut ax);
        two_level.smoother.apply(&ax, &mut y);
        lambda = y.iter().map(|v| v * v).sum::<f64>().sqrt();
        std::mem::swap(&mut x, &mut y);
    }
    println!("Lanczos {estimate}, power {lambda}");
    assert!(estimate <= lambda * (1.0 + 1e-8), "{estimate} > {lambda}");
    assert!(estimate > 0.95 * lambda, "{estimate} ≪ {lambda}");
}

fn iterations(n: usize, p: usize) -> (usize, usize) {
    let (mesh, a, rhs, constraints) = cube_system(n, p);
    let assembled = assemble(&mesh, &Material::default()).unwrap();
    let pattern = BlockPattern::new(&a, &assembled.graph, &constraints).unwrap();
    let single = BlockOperator::single(&pattern, &a);
    let mut two_level = TwoLevel::new(
        &a,
        &single,
        &constraints,
        &mesh,
        &assembled.cells_of_node,
        &assembled.references,
        3,
    )
    .unwrap();
    let mut x = vec![0.0; rhs.len()];
    let with_two_level = pcg(&a, &rhs, &mut x, &mut two_level, 1e-10, 5000);
    let diagonal = (0..a.rows())
        .map(|r| a.get(r, r).copied().unwrap_or(1.0))
        .collect();
    let mut x = vec![0.0; rhs.len()];
    let with_jacobi = pcg(&a, &rhs, &mut x, &mut PointJacobi(diagonal), 1e-10, 5000);
    (with_two_level, with_jacobi)
}

#[test]
fn largest_eigenvalue_of_tridiagonal_matrices() {
    // tridiag(−1, 2, −1) of size m: λ_max = 2 + 2 cos(π/(m + 1)).
    let m = 9;
    let exact = 2.0 + 2.0 * (std::f64::consts::PI / (m + 1) as f64).cos();
    let lambda = largest_eigenvalue(&vec![2.0; m], &vec![-1.0; m - 1]);
    assert!((lambda - exact).abs() < 1e-12, "{lambda} vs {exact}");
    assert_eq!(largest_eigenvalue(&[3.5], &[]), 3.5);
    assert_eq!(largest_eigenvalue(&[], &[]), 0.0);
}

#[test]
fn iterations_grow_little_with_p() {
    // Measured on this 3³-cube (162 tets): two-level 17 → 45 iterations from p = 2 to 4
    // (ratio 2.6), point Jacobi 172 → 567 (ratio 3.3).
    let (two_level_2, jacobi_2) = iterations(3, 2);
    let (two_level_4, jacobi_4) = iterations(3, 4);
    println!("p = 2: two-level {two_level_2}, Jacobi {jacobi_2}; p = 4: {two_level_4}, {jacobi_4}");
    let ratio = |a: usize, b: usize| a as f64 / b as f64;
    assert!(
        ratio(two_level_4, two_level_2) < 3.0,
        "{two_level_2} → {two_level_4}"
    );
    assert!(ratio(jacobi_4, jacobi_2) > 3.0, "{jacobi_2} → {jacobi_4}");
    assert!(two_level_4 * 8 < jacobi_4, "{two_level_4} vs {jacobi_4}");
}
