//! The distortion measure against exact values and finite differences.

use crate::energy::Mat;
use crate::inverse_mean_ratio;

fn rotation_scaled(s: f64) -> Mat {
    let (c, n) = (0.6f64, 0.8f64); // cos, sin of one angle
                                   // R = Rz(θ) · Rx(θ), scaled.
    let rz = [[c, -n, 0.0], [n, c, 0.0], [0.0, 0.0, 1.0]];
    let rx = [[1.0, 0.0, 0.0], [0.0, c, -n], [0.0, n, c]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = s * (0..3).map(|k| rz[i][k] * rx[k][j]).sum::<f64>();
        }
    }
    r
}

#[test]
fn similarities_have_distortion_one() {
    for s in [0.1, 1.0, 7.0] {
        let (f, _) = inverse_mean_ratio(&rotation_scaled(s), 3, 0.0).expect("positive");
        assert!((f - 1.0).abs() < 1e-13, "3D s = {s}: {f}");
        let t2 = [[0.6 * s, -0.8 * s, 0.0], [0.8 * s, 0.6 * s, 0.0], [0.0; 3]];
        let (f, _) = inverse_mean_ratio(&t2, 2, 0.0).expect("positive");
        assert!((f - 1.0).abs() < 1e-13, "2D s = {s}: {f}");
    }
}

#[test]
fn a_stretch_has_the_exact_distortion() {
    // T = diag(2, 1, 1): |T|² = 6, det T = 2, f = 6 / (3 · 2^{2/3}) = 2^{1/3}.
    let t = [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (f, _) = inverse_mean_ratio(&t, 3, 0.0).expect("positive");
    assert!((f - 2f64.cbrt()).abs() < 1e-14);
    // With δ: h(2) = (2 + √(4 + 4δ²)) / 2.
    let delta: f64 = 0.3;
    let h = (2.0 + (4.0 + 4.0 * delta * delta).sqrt()) / 2.0;
    let (f, _) = inverse_mean_ratio(&t, 3, delta).expect("regularised");
    assert!((f - 6.0 / (3.0 * h.powf(2.0 / 3.0))).abs() < 1e-14);
}

#[test]
fn the_barrier_refuses_inverted_maps_without_regularisation() {
    let t = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    assert!(inverse_mean_ratio(&t, 3, 0.0).is_none());
    let flat = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
    assert!(inverse_mean_ratio(&flat, 3, 0.0).is_none());
    // Regularised: finite, and larger the more inverted.
    let a = inverse_mean_ratio(&t, 3, 1e-2).expect("finite").0;
    let worse = [[-2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let b = inverse_mean_ratio(&worse, 3, 1e-2).expect("finite").0;
    assert!(a.is_finite() && b > a, "{a} {b}");
}

/// Maps T with their dimension and δ: positive and negative det T, 2D and 3D, with and
/// without regularisation.
fn difference_cases() -> [(Mat, usize, f64); 4] {
    [
        (
            [[1.2, 0.3, -0.1], [0.2, 0.9, 0.4], [-0.3, 0.1, 1.1]],
            3,
            0.0,
        ),
        (
            [[1.2, 0.3, -0.1], [0.2, -0.9, 0.4], [-0.3, 0.1, 1.1]],
            3,
            0.05,
        ),
        ([[0.7, 0.2, 0.0], [-0.4, 1.3, 0.0], [0.0; 3]], 2, 0.0),
        ([[0.7, 0.2, 0.0], [0.4, -1.3, 0.0], [0.0; 3]], 2, 0.1),
    ]
}

#[test]
fn the_derivative_matches_central_differences() {
    for (t, dim, delta) in difference_cases() {
        let (_, grad) = inverse_mean_ratio(&t, dim, delta).expect("finite");
        let h = 1e-6;
        for r in 0..dim {
            for c in 0..dim {
                let (mut plus, mut minus) = (t, t);
                plus[r][c] += h;
                minus[r][c] -= h;
                let fp = inverse_mean_ratio(&plus, dim, delta).expect("finite").0;
                let fm = inverse_mean_ratio(&minus, dim, delta).expect("finite").0;
                let fd = (fp - fm) / (2.0 * h);
                assert!(
                    (fd - grad[r][c]).abs() < 1e-7 * (1.0 + fd.abs()),
                    "dim {dim} δ {delta} [{r}][{c}]: {fd} vs {}",
                    grad[r][c]
                );
            }
        }
    }
}

#[test]
fn the_second_derivative_matches_central_differences_of_the_first() {
    use crate::energy::inverse_mean_ratio_second;
    for (t, dim, delta) in difference_cases() {
        let (f, grad, hess) = inverse_mean_ratio_second(&t, dim, delta).expect("finite");
        let (f1, grad1) = inverse_mean_ratio(&t, dim, delta).expect("finite");
        assert_eq!((f, grad), (f1, grad1));
        let h = 1e-6;
        for r in 0..dim {
            for c in 0..dim {
                let (mut plus, mut minus) = (t, t);
                plus[r][c] += h;
                minus[r][c] -= h;
                let gp = inverse_mean_ratio(&plus, dim, delta).expect("finite").1;
                let gm = inverse_mean_ratio(&minus, dim, delta).expect("finite").1;
                for a in 0..dim {
                    for b in 0..dim {
                        let fd = (gp[a][b] - gm[a][b]) / (2.0 * h);
                        let exact = hess[3 * a + b][3 * r + c];
                        assert!(
                            (fd - exact).abs() < 1e-6 * (1.0 + fd.abs()),
                            "dim {dim} δ {delta} [{a}{b}][{r}{c}]: {fd} vs {exact}"
                        );
                    }
                }
            }
        }
    }
}
