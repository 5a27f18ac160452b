use super::*;
use crate::assembly::assemble_condensed;
use crate::block_jacobi::{dof_cuts, entity_node_cuts};
use crate::vector_ops::spmv;
use crate::BoundaryConditions;
use hocurve_mesh::LinearMesh;
use hocurve_nodes::NodeFamily;
use hocurve_nodes::Shape;

/// dim P_(p−1) in `dim` dimensions.
fn gradient_space(dim: usize, p: usize) -> usize {
    match dim {
        2 => p * (p + 1) / 2,
        _ => p * (p + 1) * (p + 2) / 6,
    }
}

#[test]
fn reference_factors_have_the_rank_of_the_gradient_space_and_reproduce_the_reference_matrices() {
    for (shape, dim) in [(Shape::Tri, 2), (Shape::Tet, 3)] {
        for p in 1..=7 {
            let reference = ReferenceStiffness::new(shape, p, NodeFamily::Fekete).unwrap();
            let factors = ReferenceGradients::new(&reference).unwrap();
            assert_eq!(factors.rank(), gradient_space(dim, p), "{shape:?} p = {p}");
            let s = reference.simplex_stiffness.as_ref().unwrap();
            let n = reference.len;
            let scale = s.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for alpha in 0..dim {
                for beta in 0..dim {
                    for a in 0..n {
                        for b in 0..n {
                            let product: f64 = (0..factors.rank())
                                .map(|k| factors.factor(alpha, k, a) * factors.factor(beta, k, b))
                                .sum();
                            let exact = s[alpha * dim + beta][a * n + b];
                            assert!(
                                (product - exact).abs() <= 1e-12 * scale,
                                "{shape:?} p = {p}: {product} vs {exact}"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// The unit square in 3 × 3 quadrilaterals, the middle column split into triangles.
fn mixed_square() -> LinearMesh {
    use hocurve_mesh::{Element, Shape};
    let mut mesh = hocurve_testmeshes::unit_square(3, Shape::Quad, 0.0);
    let cells = std::mem::take(&mut mesh.cells);
    for (c, cell) in cells.into_iter().enumerate() {
        if c % 3 == 1 {
            let v = &cell.vertices;
            for tri in [[v[0], v[1], v[2]], [v[0], v[2], v[3]]] {
                mesh.cells.push(Element {
                    kind: Shape::Tri,
                    vertices: tri.to_vec(),
                    entity: 1,
                });
            }
        } else {
            mesh.cells.push(cell);
        }
    }
    mesh
}

/// The unit square in 2n² right triangles.
fn tri_square(n: usize) -> LinearMesh {
    use hocurve_mesh::{Element, Shape};
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            // Slightly sheared so that no two cells are congruent.
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            vertices.push([x + 0.1 * x * y, y + 0.05 * x * y, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut cells = Vec::new();
    for j in 0..n {
        for i in 0..n {
            for tri in [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ] {
                cells.push(Element {
                    kind: Shape::Tri,
                    vertices: tri.to_vec(),
                    entity: 1,
                });
            }
        }
    }
    LinearMesh {
        dim: 2,
        vertices,
        cells,
        ..Default::default()
    }
}

/// A mesh of order p with nodes on x = 0 prescribed (a non-zero field), on y = 0 sliding
/// on a slanted normal, the rest free; stiffened cell by cell.
fn system(linear: &LinearMesh, p: usize) -> (HighOrderMesh, Constraints, Vec<f64>) {
    let mesh = HighOrderMesh::from_linear(linear, p, NodeFamily::Fekete).unwrap();
    let mut bc = BoundaryConditions::default();
    for (n, x) in mesh.nodes.iter().enumerate() {
        if x[0] == 0.0 {
            bc.prescribed
                .insert(n as u32, [0.01 * x[1], -0.02 * x[2] + 0.01, 0.03]);
        } else if x[1] == 0.0 {
            bc.sliding.insert(n as u32, [0.2, 1.0, 0.1]);
        }
    }
    assert!(!bc.prescribed.is_empty() && !bc.sliding.is_empty());
    let constraints = Constraints::new(mesh.nodes.len(), mesh.dim, &bc);
    let stiffening = (0..mesh.cells.len())
        .map(|c| 1.0 + (c % 7) as f64)
        .collect();
    (mesh, constraints, stiffening)
}

fn pseudo_random(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| ((i.wrapping_mul(2_654_435_761) >> 5) % 1000) as f64 / 500.0 - 1.0)
        .collect()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn the_cell_by_cell_action_equals_the_assembled_condensed_matrix() {
    let material = Material::default();
    for (linear, p) in [
        (crate::p_multigrid::tests::tet_cube(2), 1),
        // 384 cells: several runs of several colours.
        (crate::p_multigrid::tests::tet_cube(4), 2),
        (crate::p_multigrid::tests::tet_cube(2), 3),
        (crate::p_multigrid::tests::tet_cube(1), 5),
        (tri_square(3), 2),
        (tri_square(2), 6),
        // Hexahedra and prisms (perturbed: not parallelepipeds), quadrilaterals, alone and
        // mixed with triangles: from the gradients at the quadrature points.
        (
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::HexPrism, 0.2),
            2,
        ),
        (
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::Hex, 0.2),
            3,
        ),
        (
            hocurve_testmeshes::unit_cube(1, hocurve_testmeshes::Fill::Prism, 0.0),
            4,
        ),
        (hocurve_testmeshes::unit_square(3, Shape::Quad, 0.2), 3),
        (mixed_square(), 2),
        // Extruded (affine) prisms: one Jacobian per cell, reference factors.
        (
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::Prism, 0.0),
            3,
        ),
        // From p = 4 by sum factorisation (perturbed cells: per-point Jacobians).
        (
            hocurve_testmeshes::unit_cube(1, hocurve_testmeshes::Fill::HexPrism, 0.2),
            4,
        ),
        (hocurve_testmeshes::unit_square(2, Shape::Quad, 0.2), 5),
    ] {
        let (mesh, constraints, stiffening) = system(&linear, p);
        assert!(MatrixFreeStiffness::applies(&mesh));
        let assembled = assemble_condensed(
            &mesh,
            &material,
            Some(&stiffening),
            &constraints,
            &mut |_| {},
        )
        .unwrap();
        let operator =
            MatrixFreeStiffness::new(&mesh, &material, Some(&stiffening), &constraints).unwrap();
        assert_eq!(operator.len(), constraints.len());
        let x = pseudo_random(constraints.len());
        let (mut expected, mut found) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        spmv(&assembled.matrix, &x, &mut expected);
        operator.apply(&x, &mut found);
        let scale = max_abs(&expected);
        for (e, f) in expected.iter().zip(&found) {
            assert!((e - f).abs() <= 1e-12 * scale, "p = {p}: {e} vs {f}");
        }
        // The prescribed nodes' load.
        let load = operator.prescribed_load(&constraints);
        let scale = max_abs(&assembled.rhs);
        assert!(scale > 0.0);
        for (e, f) in assembled.rhs.iter().zip(&load) {
            assert!((e - f).abs() <= 1e-12 * scale, "p = {p}: {e} vs {f}");
        }
        // The entity blocks of the smoother.
        let cuts = dof_cuts(&entity_node_cuts(&mesh), &constraints.first);
        let (from_matrix, from_cells) = (
            BlockJacobi::new(&assembled.matrix, &cuts),
            operator.block_jacobi(&cuts),
        );
        from_matrix.apply(&x, &mut expected);
        from_cells.apply(&x, &mut found);
        let scale = max_abs(&expected);
        for (e, f) in expected.iter().zip(&found) {
            assert!((e - f).abs() <= 1e-10 * scale, "p = {p}: {e} vs {f}");
        }
    }
}

#[test]
fn the_action_does_not_depend_on_the_number_of_threads() {
    let (mesh, constraints, _) = system(&crate::p_multigrid::tests::tet_cube(3), 3);
    let operator =
        MatrixFreeStiffness::new(&mesh, &Material::default(), None, &constraints).unwrap();
    let x = pseudo_random(constraints.len());
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut y = vec![0.0; x.len()];
        pool.install(|| operator.apply(&x, &mut y));
        y
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(5));
}

#[test]
fn curved_simplices_are_left_to_the_assembled_matrix() {
    let linear = crate::p_multigrid::tests::tet_cube(1);
    let mut mesh = HighOrderMesh::from_linear(&linear, 2, NodeFamily::Fekete).unwrap();
    assert!(MatrixFreeStiffness::applies(&mesh));
    // Move one edge node off its straight position.
    let node = mesh.cells[0].nodes[5] as usize;
    mesh.nodes[node][0] += 0.01;
    assert!(!MatrixFreeStiffness::applies(&mesh));
}

/// CG's f64 action and the smoothers' f32 one: the same bits with and without AVX2, on the dense path (tetrahedra)
/// and the sum-factorised one (curved prisms and hexahedra, quadrilaterals), affine cells and
/// cells with a Jacobian per point.
#[test]
fn the_avx2_action_has_the_bits_of_the_portable_one() {
    for (linear, p) in [
        (crate::p_multigrid::tests::tet_cube(2), 4),
        (
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::HexPrism, 0.2),
            3,
        ),
        (
            hocurve_testmeshes::unit_cube(1, hocurve_testmeshes::Fill::HexPrism, 0.2),
            5,
        ),
        (hocurve_testmeshes::unit_square(3, Shape::Quad, 0.2), 4),
    ] {
        let (mesh, constraints, stiffening) = system(&linear, p);
        let mut operator =
            MatrixFreeStiffness::new(&mesh, &Material::default(), Some(&stiffening), &constraints)
                .unwrap();
        let x = pseudo_random(constraints.len());
        let mut fast = vec![0.0; x.len()];
        operator.apply(&x, &mut fast);
        let mut fast_single = vec![0.0; x.len()];
        SinglePrecision(&operator).apply(&x, &mut fast_single);
        operator.avx2 = false;
        let mut portable = vec![0.0; x.len()];
        operator.apply(&x, &mut portable);
        assert_eq!(fast, portable, "p = {p}");
        let mut portable_single = vec![0.0; x.len()];
        SinglePrecision(&operator).apply(&x, &mut portable_single);
        assert_eq!(fast_single, portable_single, "f32, p = {p}");
    }
}

/// Prisms whose top triangle is a translate of the bottom one (extruded meshes) have a
/// constant Jacobian: below the sum-factorisation order they get the reference factors of
/// rank dim ∇P (36 at p = 3, against the 64 points of the rule) and one Jacobian per cell;
/// a perturbed prism keeps the per-point path.
#[test]
fn extruded_prisms_are_applied_with_one_jacobian_per_cell() {
    let material = Material::default();
    for (perturbation, affine) in [(0.0, true), (0.2, false)] {
        let linear =
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::Prism, perturbation);
        let (mesh, constraints, _) = system(&linear, 3);
        let operator = MatrixFreeStiffness::new(&mesh, &material, None, &constraints).unwrap();
        let part = &operator.parts[0];
        assert_eq!(
            part.reference.per_point, !affine,
            "perturbation {perturbation}"
        );
        if affine {
            assert_eq!(part.reference.m, 36);
            assert_eq!(part.geometry.len(), mesh.cells.len());
        }
    }
}

/// The smoothers' f32 action: within f32 round-off of the f64 one on every shape it takes
/// (simplices, affine and per-point prisms, hexahedra, quadrilaterals, 2D and 3D), the same
/// bits with and without AVX2 and for any thread count, sum-factorised parts (hexahedra,
/// quadrilaterals and curved prisms from order 3, affine prisms from order 4) included.
#[test]
fn the_single_precision_action_is_the_double_one_to_f32_round_off() {
    let material = Material::default();
    for (linear, p) in [
        (crate::p_multigrid::tests::tet_cube(2), 3),
        (crate::p_multigrid::tests::tet_cube(1), 6),
        (tri_square(2), 6),
        (
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::HexPrism, 0.2),
            2,
        ),
        (
            hocurve_testmeshes::unit_cube(2, hocurve_testmeshes::Fill::Prism, 0.0),
            3,
        ),
        (hocurve_testmeshes::unit_square(3, Shape::Quad, 0.2), 3),
        (mixed_square(), 2),
        (
            hocurve_testmeshes::unit_cube(1, hocurve_testmeshes::Fill::HexPrism, 0.2),
            4,
        ),
    ] {
        let (mesh, constraints, stiffening) = system(&linear, p);
        let mut operator =
            MatrixFreeStiffness::new(&mesh, &material, Some(&stiffening), &constraints).unwrap();
        let x = pseudo_random(constraints.len());
        let (mut double, mut fast) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        operator.apply(&x, &mut double);
        SinglePrecision(&operator).apply(&x, &mut fast);
        let scale = max_abs(&double);
        let worst = double
            .iter()
            .zip(&fast)
            .fold(0.0f64, |m, (d, f)| m.max((d - f).abs()));
        // f32 products: differences of order 1e-7 of the largest entry, never zero.
        assert!(
            worst > 0.0 && worst <= 1e-5 * scale,
            "p = {p}: {worst:e} of {scale:e}"
        );
        let threads = |n: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap();
            let mut y = vec![0.0; x.len()];
            pool.install(|| SinglePrecision(&operator).apply(&x, &mut y));
            y
        };
        assert_eq!(threads(1), threads(3), "p = {p}");
        operator.avx2 = false;
        let mut portable = vec![0.0; x.len()];
        SinglePrecision(&operator).apply(&x, &mut portable);
        assert_eq!(fast, portable, "p = {p}");
    }
}

/// Timing of the matrix-free mat-vecs (f64 and f32 cell actions), and of the block-Jacobi
/// smoother's B, on a p = 4 cube of
/// 6 × 10³ tetrahedra (run with `--ignored --nocapture`, release): best of 30.
#[test]
#[ignore]
fn mat_vec_timings() {
    let (mesh, constraints, _) = system(&crate::p_multigrid::tests::tet_cube(10), 4);
    let operator =
        MatrixFreeStiffness::new(&mesh, &Material::default(), None, &constraints).unwrap();
    let x = pseudo_random(operator.len());
    let mut y = vec![0.0; operator.len()];
    let single = SinglePrecision(&operator);
    let blocks = operator.block_jacobi(&dof_cuts(&entity_node_cuts(&mesh), &constraints.first));
    let mut best = [f64::MAX; 3];
    for _ in 0..30 {
        for (k, best) in best.iter_mut().enumerate() {
            let t = std::time::Instant::now();
            match k {
                0 => operator.apply(&x, &mut y),
                1 => single.apply(&x, &mut y),
                _ => blocks.apply(&x, &mut y),
            }
            *best = best.min(t.elapsed().as_secs_f64());
        }
    }
    println!(
        "{} cells, {} unknowns: f64 {:.2} ms, f32 {:.2} ms, block Jacobi {:.2} ms",
        mesh.cells.len(),
        operator.len(),
        1e3 * best[0],
        1e3 * best[1],
        1e3 * best[2]
    );
}

/// Timing of the f32 and f64 cell actions on curved prisms and hexahedra (perturbed cubes
/// of 2 × 12³ prisms and 10³ hexahedra), and on extruded prisms (one Jacobian per cell
/// when dense), at p = 2..5, dense against sum-factorised, and on the tetrahedra of the
/// same cube of prisms (run with `--ignored --nocapture`, release):
/// best of 20, ns per unknown.
#[test]
#[ignore]
fn extruded_action_timings() {
    use hocurve_testmeshes::{unit_cube, Fill, Kuhn};
    let meshes = [
        ("prisms", unit_cube(12, Fill::Prism, 0.1)),
        ("extruded", unit_cube(12, Fill::Prism, 0.0)),
        ("hexahedra", unit_cube(10, Fill::Hex, 0.1)),
        ("tetrahedra", unit_cube(12, Fill::Tet(Kuhn::Paired), 0.1)),
    ];
    for p in 2..=5 {
        for (name, linear) in &meshes {
            let (mesh, constraints, _) = system(linear, p);
            let mut line = format!("p = {p} {name:>10}:");
            let paths: &[(&str, [usize; 2])] = match *name {
                "tetrahedra" => &[("", [usize::MAX; 2])],
                _ => &[("dense", [usize::MAX; 2]), ("factorised", [1; 2])],
            };
            for &(path, from) in paths {
                let operator = MatrixFreeStiffness::factorised_from(
                    &mesh,
                    &Material::default(),
                    None,
                    &constraints,
                    from,
                )
                .unwrap();
                let x = pseudo_random(operator.len());
                let mut y = vec![0.0; operator.len()];
                let single = SinglePrecision(&operator);
                let mut best = [f64::MAX; 2];
                for _ in 0..20 {
                    for (k, best) in best.iter_mut().enumerate() {
                        let t = std::time::Instant::now();
                        match k {
                            0 => operator.apply(&x, &mut y),
                            _ => single.apply(&x, &mut y),
                        }
                        *best = best.min(t.elapsed().as_secs_f64());
                    }
                }
                let per = |s: f64| 1e9 * s / operator.len() as f64;
                line += &format!("  {path} f64 {:.1} f32 {:.1}", per(best[0]), per(best[1]));
            }
            println!("{line}");
        }
    }
}
