use super::*;

#[test]
fn gll_unit_points_are_symmetric_and_include_ends() {
    for p in 1..=12 {
        let x = gll_unit(p);
        assert_eq!(x.len(), p + 1);
        for i in 0..=p {
            assert!((x[i] + x[p - i] - 1.0).abs() < 1e-15);
        }
    }
    let x = gll_unit(4); // GLL n = 5 on [−1,1]: 0, ±√(3/7), ±1
    assert!((x[1] - 0.5 * (1.0 - (3.0f64 / 7.0).sqrt())).abs() < 1e-15);
}

#[test]
fn warp_blend_triangle_edges_are_gll_and_points_stay_inside() {
    for p in 1..=12 {
        let v = gll_unit(p);
        for j in 0..=p as i64 {
            for i in 0..=p as i64 - j {
                let [x, y] = warp_blend_triangle(p, [i, j]);
                assert!(x >= -1e-14 && y >= -1e-14 && x + y <= 1.0 + 1e-14);
                if j == 0 {
                    assert!(
                        (x - v[i as usize]).abs() < 1e-13 && y.abs() < 1e-13,
                        "p={p}"
                    );
                }
            }
        }
    }
}

/// Every symmetry of the simplex permutes the barycentric lattice indices; the node set
/// must be permuted the same way.
#[test]
fn simplex_sets_are_symmetric() {
    let perms3 = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for p in 1..=10usize {
        let pi = p as i64;
        for j in 0..=pi {
            for i in 0..=pi - j {
                let b = [pi - i - j, i, j];
                for f in [warp_blend_triangle, blyth_pozrikidis_triangle] {
                    let x = f(p, [i, j]);
                    let lam = [1.0 - x[0] - x[1], x[0], x[1]];
                    for s in perms3 {
                        let y = f(p, [b[s[1]], b[s[2]]]);
                        let mu = [1.0 - y[0] - y[1], y[0], y[1]];
                        for k in 0..3 {
                            assert!((mu[k] - lam[s[k]]).abs() < 1e-13, "p={p}");
                        }
                    }
                }
            }
        }
    }
    // Tet interior: all 24 permutations of the four barycentrics.
    for p in 4..=9usize {
        let pi = p as i64;
        for k in 1..pi {
            for j in 1..pi - k {
                for i in 1..pi - j - k {
                    let b = [pi - i - j - k, i, j, k];
                    for f in [warp_blend_tet, blyth_pozrikidis_tet] {
                        let x = f(p, [i, j, k]);
                        let lam = [1.0 - x[0] - x[1] - x[2], x[0], x[1], x[2]];
                        assert!(lam.iter().all(|&l| l > 0.0), "outside: p={p}");
                        for s in permutations4() {
                            let y = f(p, [b[s[1]], b[s[2]], b[s[3]]]);
                            let mu = [1.0 - y[0] - y[1] - y[2], y[0], y[1], y[2]];
                            for q in 0..4 {
                                assert!((mu[q] - lam[s[q]]).abs() < 1e-12, "p={p} {s:?}");
                            }
                        }
                    }
                }
            }
        }
    }
}

fn permutations4() -> Vec<[usize; 4]> {
    let mut out = Vec::new();
    for a in 0..4 {
        for b in 0..4 {
            for c in 0..4 {
                for d in 0..4 {
                    let s = [a, b, c, d];
                    if (0..4).all(|x| s.contains(&x)) {
                        out.push(s);
                    }
                }
            }
        }
    }
    out
}
