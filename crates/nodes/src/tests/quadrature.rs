use super::*;

fn factorial(n: usize) -> f64 {
    (1..=n).map(|k| k as f64).product()
}

/// ∫ x^a y^b z^c over the reference element, in closed form.
fn exact_monomial_integral(shape: Shape, [a, b, c]: [usize; 3]) -> f64 {
    let line = |k: usize| 1.0 / (k + 1) as f64;
    match shape {
        Shape::Line | Shape::Quad | Shape::Hex => line(a) * line(b) * line(c),
        Shape::Tri => factorial(a) * factorial(b) / factorial(a + b + 2),
        Shape::Tet => factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3),
        Shape::Prism => factorial(a) * factorial(b) / factorial(a + b + 2) * line(c),
    }
}

/// Exponents (a, b, c) of the monomials the rule of `degree` must integrate exactly,
/// with (b, c) = 0 beyond the shape's dimension.
fn monomials(shape: Shape, degree: usize) -> Vec<[usize; 3]> {
    let dim = shape.dim();
    let mut out = Vec::new();
    let max = |d: usize| if d < dim { degree } else { 0 };
    for c in 0..=max(2) {
        for b in 0..=max(1) {
            for a in 0..=degree {
                let ok = match shape {
                    Shape::Line | Shape::Quad | Shape::Hex => true,
                    Shape::Tri | Shape::Tet => a + b + c <= degree,
                    Shape::Prism => a + b <= degree,
                };
                if ok {
                    out.push([a, b, c]);
                }
            }
        }
    }
    out
}

fn monomial(p: [f64; 3], e: [usize; 3]) -> f64 {
    p[0].powi(e[0] as i32) * p[1].powi(e[1] as i32) * p[2].powi(e[2] as i32)
}

fn volume(shape: Shape) -> f64 {
    exact_monomial_integral(shape, [0, 0, 0])
}

fn inside(shape: Shape, p: [f64; 3]) -> bool {
    let unit = |t: f64| (0.0..=1.0).contains(&t);
    let dim_ok = (shape.dim()..3).all(|d| p[d] == 0.0);
    dim_ok
        && match shape {
            Shape::Line | Shape::Quad | Shape::Hex => p.iter().all(|&t| unit(t)),
            Shape::Tri | Shape::Prism => unit(p[0]) && unit(p[1]) && p[0] + p[1] <= 1.0,
            Shape::Tet => p.iter().all(|&t| unit(t)) && p[0] + p[1] + p[2] <= 1.0,
        }
        && (shape != Shape::Prism || unit(p[2]))
}

#[test]
fn rules_integrate_monomials_exactly_up_to_their_degree() {
    for shape in Shape::ALL {
        for degree in 0..=14 {
            let rule = QuadratureRule::new(shape, degree);
            let n = degree / 2 + 1;
            assert_eq!(rule.len(), n.pow(shape.dim() as u32), "{shape:?}");
            let vol: f64 = rule.weights.iter().sum();
            assert!((vol - volume(shape)).abs() < 4e-15, "{shape:?} {degree}");
            for (p, w) in rule.points.iter().zip(&rule.weights) {
                assert!(*w > 0.0 && inside(shape, *p), "{shape:?} {p:?}");
            }
            // Exact to degree 2n − 1 (≥ degree; = degree + 1 for even degree).
            for e in monomials(shape, 2 * n - 1) {
                let q = rule.integrate(|p| monomial(p, e));
                let exact = exact_monomial_integral(shape, e);
                assert!(
                    (q - exact).abs() <= 1e-13 * exact,
                    "{shape:?} degree {degree}: x^{e:?}: {q} vs {exact}"
                );
            }
            // ... and not beyond: some monomial of degree 2n is integrated wrongly.
            let worst = monomials(shape, 2 * n)
                .into_iter()
                .map(|e| {
                    let exact = exact_monomial_integral(shape, e);
                    (rule.integrate(|p| monomial(p, e)) - exact).abs() / exact
                })
                .fold(0.0, f64::max);
            assert!(worst > 1e-10, "{shape:?} degree {degree}: {worst}");
        }
    }
}

#[test]
fn symmetric_rules_integrate_like_the_collapsed_ones_with_fewer_points() {
    for shape in Shape::ALL {
        for degree in 0..=12 {
            let (rule, collapsed) = (
                QuadratureRule::symmetric(shape, degree),
                QuadratureRule::new(shape, degree),
            );
            let fewer = matches!(shape, Shape::Tri | Shape::Prism) && degree % 2 == 0;
            if fewer && (2..=8).contains(&degree) {
                assert!(rule.len() < collapsed.len(), "{shape:?} {degree}");
            } else {
                assert_eq!(rule, collapsed, "{shape:?} {degree}");
            }
            for (p, w) in rule.points.iter().zip(&rule.weights) {
                assert!(*w > 0.0 && inside(shape, *p), "{shape:?} {p:?}");
            }
            for e in monomials(shape, degree) {
                let q = rule.integrate(|p| monomial(p, e));
                let exact = exact_monomial_integral(shape, e);
                assert!(
                    (q - exact).abs() <= 1e-13 * exact,
                    "{shape:?} degree {degree}: x^{e:?}: {q} vs {exact}"
                );
            }
        }
    }
}
