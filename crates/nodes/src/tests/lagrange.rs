use super::*;

fn max_order(shape: Shape) -> usize {
    match shape {
        Shape::Line | Shape::Tri | Shape::Tet => 8,
        _ => 6,
    }
}

/// Deterministic pseudo-random points inside the reference element.
fn random_points(shape: Shape, count: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = Vec::with_capacity(count);
    while out.len() < count {
        let mut p = [next(), next(), next()];
        for c in p.iter_mut().skip(shape.dim()) {
            *c = 0.0;
        }
        let ok = match shape {
            Shape::Tri | Shape::Prism => p[0] + p[1] < 1.0,
            Shape::Tet => p[0] + p[1] + p[2] < 1.0,
            _ => true,
        };
        if ok {
            out.push(p);
        }
    }
    out
}

/// Monomial exponents of the order-p space of `shape`.
fn space_monomials(shape: Shape, p: usize) -> Vec<[usize; 3]> {
    let dim = shape.dim();
    let max = |d: usize| if d < dim { p } else { 0 };
    let mut out = Vec::new();
    for c in 0..=max(2) {
        for b in 0..=max(1) {
            for a in 0..=p {
                let ok = match shape {
                    Shape::Line | Shape::Quad | Shape::Hex => true,
                    Shape::Tri | Shape::Tet => a + b + c <= p,
                    Shape::Prism => a + b <= p,
                };
                if ok {
                    out.push([a, b, c]);
                }
            }
        }
    }
    out
}

fn monomial(x: [f64; 3], e: [usize; 3]) -> f64 {
    (0..3).map(|d| x[d].powi(e[d] as i32)).product()
}

fn monomial_grad(x: [f64; 3], e: [usize; 3]) -> [f64; 3] {
    let mut g = [0.0; 3];
    for (d, gd) in g.iter_mut().enumerate() {
        if e[d] > 0 {
            let mut f = e[d] as f64 * x[d].powi(e[d] as i32 - 1);
            for o in (0..3).filter(|&o| o != d) {
                f *= x[o].powi(e[o] as i32);
            }
            *gd = f;
        }
    }
    g
}

fn equispaced_bases() -> impl Iterator<Item = LagrangeBasis> {
    Shape::ALL.into_iter().flat_map(|shape| {
        (1..=max_order(shape)).map(move |p| {
            let nodes = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
            LagrangeBasis::new(&nodes).expect("equispaced nodes are unisolvent")
        })
    })
}

#[test]
fn lagrange_property_holds_at_the_nodes() {
    for lagrange in equispaced_bases() {
        let m = lagrange.interpolation_matrix(lagrange.nodes());
        let n = lagrange.len();
        for k in 0..n {
            for i in 0..n {
                let expected = if i == k { 1.0 } else { 0.0 };
                assert!(
                    (m[(k, i)] - expected).abs() < 1e-10,
                    "{:?} p={}: Φ{i}(x{k}) = {}",
                    lagrange.shape(),
                    lagrange.order(),
                    m[(k, i)]
                );
            }
        }
    }
}

#[test]
fn partition_of_unity_and_monomial_reproduction_at_random_points() {
    for lagrange in equispaced_bases() {
        let (shape, p, n) = (lagrange.shape(), lagrange.order(), lagrange.len());
        let points = random_points(shape, 4, p as u64);
        let (mut phi, mut grad) = (vec![0.0; n], vec![[0.0; 3]; n]);
        let (mut scratch, mut grad_scratch) = (vec![0.0; n], vec![[0.0; 3]; n]);
        let grad_matrices = lagrange.gradient_matrices(&points);
        for (k, &x) in points.iter().enumerate() {
            lagrange.eval_with(x, &mut scratch, &mut phi);
            lagrange.eval_grad_with(x, &mut grad_scratch, &mut grad);
            let sum: f64 = phi.iter().sum();
            assert!((sum - 1.0).abs() < 1e-11, "{shape:?} p={p}: ΣΦ = {sum}");
            for d in 0..3 {
                let s: f64 = grad.iter().map(|g| g[d]).sum();
                assert!(s.abs() < 1e-9, "{shape:?} p={p}: Σ∂{d}Φ = {s}");
                for i in 0..n {
                    assert!((grad_matrices[d][(k, i)] - grad[i][d]).abs() < 1e-11);
                }
            }
            for e in space_monomials(shape, p) {
                let nodal: Vec<f64> = lagrange.nodes().iter().map(|&y| monomial(y, e)).collect();
                let value: f64 = nodal.iter().zip(&phi).map(|(u, f)| u * f).sum();
                assert!(
                    (value - monomial(x, e)).abs() < 1e-10,
                    "{shape:?} p={p}: x^{e:?} at {x:?}: {value}"
                );
                let exact = monomial_grad(x, e);
                for d in 0..3 {
                    let g: f64 = nodal.iter().zip(&grad).map(|(u, g)| u * g[d]).sum();
                    assert!(
                        (g - exact[d]).abs() < 1e-8,
                        "{shape:?} p={p}: ∂{d} x^{e:?} at {x:?}: {g} vs {}",
                        exact[d]
                    );
                }
            }
        }
    }
}

#[test]
fn allocating_and_scratch_evaluations_agree() {
    let nodes = ReferenceNodes::new(Shape::Prism, 3, NodeFamily::Equispaced);
    let lagrange = LagrangeBasis::new(&nodes).unwrap();
    let n = lagrange.len();
    let x = [0.2, 0.3, 0.7];
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    lagrange.eval(x, &mut a);
    lagrange.eval_with(x, &mut vec![0.0; n], &mut b);
    assert_eq!(a, b);
    let m = lagrange.interpolation_matrix(&[x]);
    for i in 0..n {
        assert!((m[(0, i)] - a[i]).abs() < 1e-13);
    }
    let (mut ga, mut gb) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
    lagrange.eval_grad(x, &mut ga);
    lagrange.eval_grad_with(x, &mut vec![[0.0; 3]; n], &mut gb);
    assert_eq!(ga, gb);
}

#[test]
fn condition_numbers_are_reported_and_bounded() {
    for lagrange in equispaced_bases() {
        let cond = lagrange.condition_number();
        eprintln!(
            "equispaced {:>13} p={}: cond₂(V) = {cond:.3e}",
            lagrange.shape().name(),
            lagrange.order()
        );
        assert!((1.0..1e4).contains(&cond), "{cond}");
    }
    // Line p = 1: V = [[1, −√3], [1, √3]] has orthogonal columns of norms √2 and √6.
    let line = LagrangeBasis::new(&ReferenceNodes::new(Shape::Line, 1, NodeFamily::Equispaced));
    let cond = line.unwrap().condition_number();
    assert!((cond - 3f64.sqrt()).abs() < 1e-14, "{cond}");
}

#[test]
fn singular_node_sets_are_rejected() {
    // Six points on the edge y = 0: y, xy and y² vanish there, so P₂ restricted to them is
    // only 3-dimensional and V has rank 3.
    let points: Vec<[f64; 3]> = (0..6).map(|i| [i as f64 / 5.0, 0.0, 0.0]).collect();
    let err =
        LagrangeBasis::from_points(Shape::Tri, 2, NodeFamily::Equispaced, &points).unwrap_err();
    assert_eq!(
        err,
        NodesError::SingularVandermonde {
            shape: Shape::Tri,
            order: 2,
            family: NodeFamily::Equispaced
        }
    );
    assert!(err.to_string().contains("triangle"));
    // A repeated node.
    let mut points = ReferenceNodes::new(Shape::Quad, 2, NodeFamily::Equispaced)
        .points()
        .to_vec();
    points[8] = points[0];
    assert!(LagrangeBasis::from_points(Shape::Quad, 2, NodeFamily::Equispaced, &points).is_err());
}
