use super::*;
use crate::QuadratureRule;

fn max_order(shape: Shape) -> usize {
    if shape == Shape::Hex {
        6
    } else {
        8
    }
}

/// Deterministic pseudo-random points inside the reference element.
fn random_points(shape: Shape, count: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
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

#[test]
fn dimensions_match_node_counts() {
    for shape in Shape::ALL {
        for p in 0..=8 {
            assert_eq!(OrthonormalBasis::new(shape, p).len(), shape.num_nodes(p));
        }
    }
    assert_eq!(OrthonormalBasis::new(Shape::Prism, 3).len(), 4 * 4 * 5 / 2);
}

#[test]
fn bases_are_orthonormal() {
    for shape in Shape::ALL {
        for p in 0..=max_order(shape) {
            let basis = OrthonormalBasis::new(shape, p);
            let rule = QuadratureRule::new(shape, 2 * p);
            let v = basis.vandermonde(&rule.points);
            let mut wv = v.clone();
            for (i, w) in rule.weights.iter().enumerate() {
                wv.row_mut(i).scale_mut(*w);
            }
            let gram = v.transpose() * wv;
            let n = basis.len();
            for i in 0..n {
                for j in 0..n {
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (gram[(i, j)] - expected).abs() < 1e-12,
                        "{shape:?} p={p}: <ψ{i}, ψ{j}> = {}",
                        gram[(i, j)]
                    );
                }
            }
        }
    }
}

#[test]
fn constant_function_is_one_over_sqrt_volume() {
    for (shape, volume) in [
        (Shape::Line, 1.0),
        (Shape::Tri, 0.5),
        (Shape::Quad, 1.0),
        (Shape::Tet, 1.0 / 6.0),
        (Shape::Hex, 1.0),
        (Shape::Prism, 0.5),
    ] {
        let basis = OrthonormalBasis::new(shape, 3);
        let mut out = vec![0.0; basis.len()];
        basis.eval([0.1, 0.2, 0.3], &mut out);
        let first = out[0];
        assert!((first - 1.0 / f64::sqrt(volume)).abs() < 1e-14, "{shape:?}");
    }
}

/// Central differences of all basis functions.
fn finite_difference_gradient(basis: &OrthonormalBasis, x: [f64; 3]) -> Vec<[f64; 3]> {
    let n = basis.len();
    let h = 1e-5;
    let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
    let mut out = vec![[0.0; 3]; n];
    for d in 0..basis.shape().dim() {
        let (mut xp, mut xm) = (x, x);
        xp[d] += h;
        xm[d] -= h;
        basis.eval(xp, &mut plus);
        basis.eval(xm, &mut minus);
        for j in 0..n {
            out[j][d] = (plus[j] - minus[j]) / (2.0 * h);
        }
    }
    out
}

#[test]
fn gradients_match_finite_differences_inside_and_at_vertices() {
    // The functions are polynomials, so central differences are meaningful at the
    // vertices too (half the stencil lies outside the element).
    for shape in Shape::ALL {
        for p in [1, 3, max_order(shape)] {
            let basis = OrthonormalBasis::new(shape, p);
            let mut points = random_points(shape, 5, p as u64);
            points.extend_from_slice(shape.vertices());
            let mut grads = vec![[0.0; 3]; basis.len()];
            let mut values = vec![0.0; basis.len()];
            let mut grads2 = vec![[0.0; 3]; basis.len()];
            let mut values2 = vec![0.0; basis.len()];
            for x in points {
                basis.eval_grad(x, &mut grads);
                basis.eval(x, &mut values);
                basis.eval_with_grad(x, &mut values2, &mut grads2);
                assert_eq!(values, values2);
                assert_eq!(grads, grads2);
                let fd = finite_difference_gradient(&basis, x);
                let scale = values.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                for j in 0..basis.len() {
                    for d in 0..3 {
                        let err = (grads[j][d] - fd[j][d]).abs();
                        assert!(
                            err < 1e-6 * scale * (p * p) as f64,
                            "{shape:?} p={p} at {x:?}: ∂{d}ψ{j} = {} vs {}",
                            grads[j][d],
                            fd[j][d]
                        );
                    }
                }
            }
        }
    }
}

/// Monomial exponents in the space of order p on `shape`.
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

#[test]
fn projection_reproduces_monomials_with_exact_gradients_at_vertices() {
    // The L² projection c_j = ∫ m ψ_j of a monomial m of the space reproduces it exactly;
    // its gradient Σ c_j ∇ψ_j must equal ∇m everywhere, including the collapsed vertices.
    for shape in Shape::ALL {
        let p = 5;
        let basis = OrthonormalBasis::new(shape, p);
        let rule = QuadratureRule::new(shape, 2 * p);
        let v = basis.vandermonde(&rule.points);
        let mut points = random_points(shape, 4, 7);
        points.extend_from_slice(shape.vertices());
        let mut values = vec![0.0; basis.len()];
        let mut grads = vec![[0.0; 3]; basis.len()];
        for e in space_monomials(shape, p) {
            let coeffs: Vec<f64> = (0..basis.len())
                .map(|j| {
                    (0..rule.len())
                        .map(|q| rule.weights[q] * monomial(rule.points[q], e) * v[(q, j)])
                        .sum()
                })
                .collect();
            for &x in &points {
                basis.eval_with_grad(x, &mut values, &mut grads);
                let value: f64 = coeffs.iter().zip(&values).map(|(c, v)| c * v).sum();
                assert!(
                    (value - monomial(x, e)).abs() < 1e-11,
                    "{shape:?} {e:?} {x:?}"
                );
                let exact = monomial_grad(x, e);
                for d in 0..3 {
                    let g: f64 = coeffs.iter().zip(&grads).map(|(c, g)| c * g[d]).sum();
                    assert!(
                        (g - exact[d]).abs() < 1e-10,
                        "{shape:?} x^{e:?} at {x:?}: ∂{d} = {g} vs {}",
                        exact[d]
                    );
                }
            }
        }
    }
}

#[test]
fn least_squares_fit_at_random_points_reproduces_degree_p_monomials() {
    for shape in Shape::ALL {
        let p = 4;
        let basis = OrthonormalBasis::new(shape, p);
        let points = random_points(shape, 2 * basis.len(), 11);
        let v = basis.vandermonde(&points);
        let svd = v.svd(true, true);
        let check = random_points(shape, 5, 12);
        let vc = basis.vandermonde(&check);
        for e in space_monomials(shape, p) {
            let rhs = DMatrix::from_fn(points.len(), 1, |i, _| monomial(points[i], e));
            let c = svd.solve(&rhs, 1e-14).expect("SVD solve");
            let fit = &vc * c;
            for (i, x) in check.iter().enumerate() {
                assert!(
                    (fit[(i, 0)] - monomial(*x, e)).abs() < 1e-11,
                    "{shape:?} {e:?}"
                );
            }
        }
    }
}

#[test]
fn gradient_vandermonde_matches_eval_grad() {
    let basis = OrthonormalBasis::new(Shape::Tet, 3);
    let points = random_points(Shape::Tet, 3, 5);
    let d = basis.gradient_vandermonde(&points);
    let mut g = vec![[0.0; 3]; basis.len()];
    for (i, &x) in points.iter().enumerate() {
        basis.eval_grad(x, &mut g);
        for j in 0..basis.len() {
            for k in 0..3 {
                assert_eq!(d[k][(i, j)], g[j][k]);
            }
        }
    }
}
