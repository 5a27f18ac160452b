use super::*;

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// ∫₋₁¹ xᵏ dx.
fn monomial_integral(k: usize) -> f64 {
    if k % 2 == 1 {
        0.0
    } else {
        2.0 / (k as f64 + 1.0)
    }
}

fn factorial(n: usize) -> f64 {
    (1..=n).map(|k| k as f64).product()
}

fn binomial(n: usize, k: usize) -> f64 {
    factorial(n) / (factorial(k) * factorial(n - k))
}

/// ∫₋₁¹ (1 − x)^α (1 + x)^(β+k) dx = 2^(α+β+k+1) α!(β+k)!/(α+β+k+1)! (a Beta function;
/// no cancellation). The (1 + x)ᵏ, k ≤ m, span the polynomials of degree ≤ m.
fn jacobi_moment(alpha: usize, beta: usize, k: usize) -> f64 {
    2f64.powi((alpha + beta + k + 1) as i32) * factorial(alpha) * factorial(beta + k)
        / factorial(alpha + beta + k + 1)
}

fn check_sorted_and_symmetric(rule: &Rule1D) {
    let n = rule.len();
    for i in 1..n {
        assert!(rule.points[i - 1] < rule.points[i]);
    }
    for i in 0..n {
        assert_eq!(rule.points[i], -rule.points[n - 1 - i]);
        assert_eq!(rule.weights[i], rule.weights[n - 1 - i]);
        assert!(rule.weights[i] > 0.0);
    }
}

#[test]
fn gauss_legendre_is_exact_to_degree_2n_minus_1_and_not_beyond() {
    for n in 1..=40 {
        let rule = gauss_legendre(n);
        assert_eq!(rule.len(), n);
        check_sorted_and_symmetric(&rule);
        for k in 0..2 * n {
            let q = rule.integrate(|x| x.powi(k as i32));
            assert!(
                (q - monomial_integral(k)).abs() < 1e-14,
                "n={n} k={k}: {q} vs {}",
                monomial_integral(k)
            );
        }
        if n <= 12 {
            // The error for x^{2n} is 2^{2n+1} (n!)^4 / ((2n+1) ((2n)!)^2) > 0.
            let k = 2 * n;
            let q = rule.integrate(|x| x.powi(k as i32));
            let expected_error = 2f64.powi(k as i32 + 1) * factorial(n).powi(4)
                / ((k as f64 + 1.0) * factorial(k).powi(2));
            let err = monomial_integral(k) - q;
            assert!(rel_err(err, expected_error) < 1e-6, "n={n}: {err}");
        }
    }
}

#[test]
fn gauss_legendre_is_accurate_at_high_order() {
    // Discrete orthogonality Σ wᵢ Pⱼ(xᵢ) Pₖ(xᵢ) = 2/(2j+1) δⱼₖ for j + k ≤ 2n − 1.
    let n = 40;
    let rule = gauss_legendre(n);
    for j in 0..n {
        for k in j..2 * n - j {
            let q = rule.integrate(|x| jacobi(j, 0.0, 0.0, x) * jacobi(k, 0.0, 0.0, x));
            let exact = if j == k {
                2.0 / (2 * j + 1) as f64
            } else {
                0.0
            };
            assert!((q - exact).abs() < 2e-14, "j={j} k={k}: {q}");
        }
    }
    // And the nodes are zeros of P_n to full precision.
    for &x in &rule.points {
        let p = jacobi(n, 0.0, 0.0, x);
        let dp = jacobi_derivative(n, 0.0, 0.0, x);
        assert!((p / dp).abs() < 4e-16, "x={x}");
    }
}

#[test]
fn closed_form_nodes() {
    let gl2 = gauss_legendre(2);
    let r = 1.0 / 3f64.sqrt();
    assert!((gl2.points[1] - r).abs() < 3e-16 && gl2.points[0] == -gl2.points[1]);
    assert!((gl2.weights[0] - 1.0).abs() < 1e-15);

    let gl3 = gauss_legendre(3);
    let r = (0.6f64).sqrt();
    assert!((gl3.points[2] - r).abs() < 2e-16);
    assert_eq!(gl3.points[1], 0.0);
    assert!((gl3.weights[1] - 8.0 / 9.0).abs() < 1e-15);
    assert!((gl3.weights[0] - 5.0 / 9.0).abs() < 1e-15);

    let gll4 = gauss_lobatto_legendre(4);
    let r = 1.0 / 5f64.sqrt();
    assert_eq!(gll4.points[0], -1.0);
    assert_eq!(gll4.points[3], 1.0);
    assert!((gll4.points[2] - r).abs() < 1e-16);
    assert!((gll4.weights[0] - 1.0 / 6.0).abs() < 1e-15);
    assert!((gll4.weights[1] - 5.0 / 6.0).abs() < 1e-15);

    // GLL n = 5: 0, ±√(3/7), ±1 with weights 32/45, 49/90, 1/10.
    let gll5 = gauss_lobatto_legendre(5);
    assert!((gll5.points[3] - (3.0f64 / 7.0).sqrt()).abs() < 2e-16);
    assert!((gll5.weights[2] - 32.0 / 45.0).abs() < 1e-15);
    assert!((gll5.weights[3] - 49.0 / 90.0).abs() < 1e-15);
    assert!((gll5.weights[4] - 0.1).abs() < 1e-15);
}

#[test]
fn gauss_lobatto_is_exact_to_degree_2n_minus_3_and_not_beyond() {
    for n in 2..=40 {
        let rule = gauss_lobatto_legendre(n);
        assert_eq!(rule.len(), n);
        check_sorted_and_symmetric(&rule);
        for k in 0..=2 * n - 3 {
            let q = rule.integrate(|x| x.powi(k as i32));
            assert!((q - monomial_integral(k)).abs() < 1e-14, "n={n} k={k}: {q}");
        }
        if n <= 10 {
            let k = 2 * n - 2;
            let q = rule.integrate(|x| x.powi(k as i32));
            assert!((q - monomial_integral(k)).abs() > 1e-8, "n={n}");
        }
        // The interior nodes are the zeros of P'_{n-1}.
        for &x in &rule.points[1..n - 1] {
            assert!(jacobi_derivative(n - 1, 0.0, 0.0, x).abs() < 1e-11 * n as f64);
        }
    }
}

#[test]
fn gauss_jacobi_is_exact_for_weighted_monomials() {
    for (alpha, beta) in [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 3), (5, 0)] {
        for n in 1..=20 {
            let rule = gauss_jacobi(n, alpha as f64, beta as f64);
            for i in 1..n {
                assert!(rule.points[i - 1] < rule.points[i]);
            }
            for k in 0..2 * n {
                let q = rule.integrate(|x| (1.0 + x).powi(k as i32));
                let exact = jacobi_moment(alpha, beta, k);
                assert!(
                    rel_err(q, exact) < 1e-14,
                    "α={alpha} β={beta} n={n} k={k}: {q} vs {exact}"
                );
            }
            if n <= 6 {
                let k = 2 * n;
                let q = rule.integrate(|x| (1.0 + x).powi(k as i32));
                assert!(rel_err(q, jacobi_moment(alpha, beta, k)) > 1e-10, "n={n}");
            }
        }
    }
}

#[test]
fn gauss_chebyshev_closed_forms() {
    use std::f64::consts::PI;
    for n in [1, 2, 5, 17, 40] {
        // First kind, α = β = −1/2: xᵢ = −cos((2i+1)π/(2n)), wᵢ = π/n.
        let rule = gauss_jacobi(n, -0.5, -0.5);
        check_sorted_and_symmetric(&rule);
        for i in 0..n {
            let x = -((2 * i + 1) as f64 * PI / (2 * n) as f64).cos();
            assert!((rule.points[i] - x).abs() < 1e-15, "n={n} i={i}");
            assert!(rel_err(rule.weights[i], PI / n as f64) < 1e-13);
        }
        // Second kind, α = β = 1/2: xᵢ = −cos(iπ/(n+1)), wᵢ = π/(n+1) sin²(iπ/(n+1)).
        let rule = gauss_jacobi(n, 0.5, 0.5);
        check_sorted_and_symmetric(&rule);
        for i in 0..n {
            let theta = (i + 1) as f64 * PI / (n + 1) as f64;
            assert!((rule.points[i] + theta.cos()).abs() < 1e-15, "n={n} i={i}");
            let w = PI / (n + 1) as f64 * theta.sin().powi(2);
            assert!(rel_err(rule.weights[i], w) < 1e-13, "n={n} i={i}");
        }
    }
}

#[test]
fn gauss_jacobi_with_half_integer_exponents() {
    // α = 1/2, β = 0: ∫(1−x)^{1/2} dx = 2^{3/2}/(3/2) = 4√2/3 and
    // ∫(1−x)^{1/2} x dx = ∫(1-x)^{1/2}(1 - (1-x)) = 4√2/3 − 2^{5/2}/(5/2) = 4√2/3 − 8√2/5.
    let rule = gauss_jacobi(3, 0.5, 0.0);
    let s2 = 2f64.sqrt();
    assert!(rel_err(rule.integrate(|_| 1.0), 4.0 * s2 / 3.0) < 1e-14);
    assert!(rel_err(rule.integrate(|x| x), 4.0 * s2 / 3.0 - 8.0 * s2 / 5.0) < 1e-14);
}

#[test]
fn jacobi_polynomials_match_closed_forms() {
    for x in [-1.0, -0.3, 0.0, 0.71, 1.0] {
        assert!((jacobi(2, 0.0, 0.0, x) - 0.5 * (3.0 * x * x - 1.0)).abs() < 1e-15);
        let p3 = 0.5 * (5.0 * x * x * x - 3.0 * x);
        assert!((jacobi(3, 0.0, 0.0, x) - p3).abs() < 1e-15);
        assert!((jacobi_derivative(3, 0.0, 0.0, x) - 0.5 * (15.0 * x * x - 3.0)).abs() < 1e-14);
        // P₁^{(α,β)} = (α+1) + (α+β+2)(x−1)/2.
        assert!((jacobi(1, 2.0, 3.0, x) - (3.0 + 3.5 * (x - 1.0))).abs() < 1e-15);
    }
    // Pₙ^{(α,β)}(1) = binom(n+α, n).
    for n in 0..12 {
        for alpha in 0..5 {
            let p = jacobi(n, alpha as f64, 1.5, 1.0);
            assert!(
                rel_err(p, binomial(n + alpha, n)) < 1e-13,
                "n={n} α={alpha}"
            );
        }
    }
    // Derivative against central differences.
    let h = 1e-6;
    for n in 1..8 {
        let x = 0.37;
        let fd = (jacobi(n, 1.5, 2.0, x + h) - jacobi(n, 1.5, 2.0, x - h)) / (2.0 * h);
        assert!((jacobi_derivative(n, 1.5, 2.0, x) - fd).abs() < 1e-6 * fd.abs().max(1.0));
    }
}

#[test]
fn weight_integral_and_gamma() {
    // ∫ (1−x)^α dx = 2^{α+1}/(α+1).
    for alpha in [0.0, 1.0, 2.0, 7.0, 31.0, 200.0] {
        let exact = 2f64.powf(alpha + 1.0) / (alpha + 1.0);
        assert!(rel_err(jacobi_weight_integral(alpha, 0.0), exact) < 1e-14);
    }
    // Γ(1/3)Γ(2/3) = π / sin(π/3).
    let g = gamma(1.0 / 3.0) * gamma(2.0 / 3.0);
    let exact = std::f64::consts::PI / (std::f64::consts::PI / 3.0).sin();
    assert!(rel_err(g, exact) < 1e-14);
    assert!(rel_err(gamma(4.5), 11.631_728_396_567_45) < 1e-14); // 105√π/16
    assert!((gamma(4.5) - 105.0 * std::f64::consts::PI.sqrt() / 16.0).abs() < 1e-14);
}

#[test]
fn homogeneous_recurrence_matches_orthonormal_polynomials() {
    // Q_k(s, 1) = p̃_k(2s − 1) = √((2k+1)/2) P_k(2s − 1) for Legendre, and
    // Q_k(s, w) = p̃_k((2s − w)/w) wᵏ.
    let rec = JacobiRecurrence::new(6, 0.0, 0.0);
    let (mut v, mut ds, mut dw) = ([0.0; 7], [0.0; 7], [0.0; 7]);
    let (s, w) = (0.3, 0.7);
    rec.eval_homogeneous(s, w, &mut v, &mut ds, &mut dw);
    let h = 1e-6;
    let (mut vp, mut vm, mut d1, mut d2) = ([0.0; 7], [0.0; 7], [0.0; 7], [0.0; 7]);
    for (k, value) in v.iter().enumerate() {
        let t = (2.0 * s - w) / w;
        let exact = ((2 * k + 1) as f64 / 2.0).sqrt() * jacobi(k, 0.0, 0.0, t) * w.powi(k as i32);
        assert!((value - exact).abs() < 1e-14, "k={k}");
    }
    rec.eval_homogeneous(s + h, w, &mut vp, &mut d1, &mut d2);
    rec.eval_homogeneous(s - h, w, &mut vm, &mut d1, &mut d2);
    for k in 0..7 {
        assert!((ds[k] - (vp[k] - vm[k]) / (2.0 * h)).abs() < 1e-7);
    }
    rec.eval_homogeneous(s, w + h, &mut vp, &mut d1, &mut d2);
    rec.eval_homogeneous(s, w - h, &mut vm, &mut d1, &mut d2);
    for k in 0..7 {
        assert!((dw[k] - (vp[k] - vm[k]) / (2.0 * h)).abs() < 1e-7);
    }
}
