use super::*;

fn exact_monomial(i: i32, j: i32) -> f64 {
    factorial(i) * factorial(j) / factorial(i + j + 2)
}

fn integrate(rule: &QuadratureRule, i: i32, j: i32) -> f64 {
    rule.integrate(|p| p[0].powi(i) * p[1].powi(j))
}

#[test]
fn symmetric_rules_are_exact_to_their_degree_and_not_beyond() {
    for (degree, points) in [
        (1, 3),
        (2, 3),
        (3, 6),
        (4, 6),
        (5, 12),
        (6, 12),
        (7, 16),
        (8, 16),
    ] {
        let rule = symmetric_triangle(degree).unwrap();
        assert_eq!(rule.len(), points, "degree {degree}");
        let exact_to = degree.div_ceil(2) * 2;
        for s in 0..=exact_to as i32 {
            for i in 0..=s {
                let (q, e) = (integrate(&rule, i, s - i), exact_monomial(i, s - i));
                // Absolute: the smallest moments are ~1e-4 (x⁴y⁴).
                assert!(
                    (q - e).abs() <= 1e-15,
                    "degree {degree}: x^{i} y^{}: {q} vs {e}",
                    s - i
                );
            }
        }
        let s = exact_to as i32 + 1;
        let worst = (0..=s)
            .map(|i| (integrate(&rule, i, s - i) / exact_monomial(i, s - i) - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(
            worst > 1e-8,
            "degree {degree}: exact at {s} too ({worst:e})"
        );
    }
    assert!(symmetric_triangle(9).is_none());
}

#[test]
fn symmetric_rules_have_positive_weights_inside_and_map_onto_themselves() {
    for degree in [2, 4, 6, 8] {
        let rule = symmetric_triangle(degree).unwrap();
        for (p, &w) in rule.points.iter().zip(&rule.weights) {
            assert!(w > 0.0 && p[0] > 0.0 && p[1] > 0.0 && p[0] + p[1] < 1.0);
        }
        // The reflection (x, y) ↦ (y, x) and the rotation (x, y) ↦ (1 − x − y, x) of the
        // triangle map each point onto a point of the same weight.
        let maps: [fn([f64; 3]) -> [f64; 3]; 2] =
            [|p| [p[1], p[0], 0.0], |p| [1.0 - p[0] - p[1], p[0], 0.0]];
        for map in maps {
            for (p, &w) in rule.points.iter().zip(&rule.weights) {
                let image = map(*p);
                let found = rule.points.iter().zip(&rule.weights).any(|(q, &v)| {
                    (q[0] - image[0]).abs() < 1e-15 && (q[1] - image[1]).abs() < 1e-15 && v == w
                });
                assert!(found, "degree {degree}: image of {p:?}");
            }
        }
    }
}
