use super::*;
use crate::{LagrangeBasis, QuadratureRule};

/// log |det V| (the determinant itself overflows for tets at p ≥ 8).
fn abs_det_vandermonde(set: &ReferenceNodes) -> f64 {
    let basis = OrthonormalBasis::new(set.shape(), set.order());
    let lu = basis.vandermonde(set.points()).lu();
    lu.u().diagonal().iter().map(|u| u.abs().ln()).sum()
}

/// Lebesgue constant max_x Σ|Φᵢ(x)| estimated on the points of a high-degree quadrature
/// rule plus the nodes of a fine equispaced set (both cover the element densely).
fn lebesgue_constant(set: &ReferenceNodes) -> f64 {
    let basis = LagrangeBasis::new(set).unwrap();
    let fine = ReferenceNodes::new(set.shape(), 20, NodeFamily::Equispaced);
    let rule = QuadratureRule::new(set.shape(), 30);
    let mut values = vec![0.0; basis.len()];
    fine.points()
        .iter()
        .chain(&rule.points)
        .map(|x| {
            basis.eval(*x, &mut values);
            values.iter().map(|v| v.abs()).sum::<f64>()
        })
        .fold(0.0, f64::max)
}

#[test]
fn fekete_maximises_the_vandermonde_determinant() {
    for (shape, max_p) in [(Shape::Tri, 10), (Shape::Tet, 8)] {
        for p in 3..=max_p {
            let start = std::time::Instant::now();
            let fekete = ReferenceNodes::new(shape, p, NodeFamily::Fekete);
            let elapsed = start.elapsed();
            let det = abs_det_vandermonde(&fekete);
            let mut line = format!("{shape:?} p={p}: log|det V| fekete {det:.4} ({elapsed:.2?})");
            for other in [
                NodeFamily::WarpBlend,
                NodeFamily::GaussLobatto,
                NodeFamily::Equispaced,
            ] {
                let d = abs_det_vandermonde(&ReferenceNodes::new(shape, p, other));
                line += &format!(", {other} {d:.4}");
                // Equal only when there is nothing to optimise (a single central node).
                assert!(det >= d - 1e-10, "{shape:?} p={p}: {other} beats Fekete");
            }
            eprintln!("{line}");
        }
    }
}

/// Cost of the optimisation at the largest orders (run with `--ignored --nocapture`).
#[test]
#[ignore]
fn fekete_timing_up_to_max_order() {
    for shape in [Shape::Tri, Shape::Tet] {
        for p in 1..=NodeFamily::Fekete.max_order() {
            let start = std::time::Instant::now();
            let set = ReferenceNodes::new(shape, p, NodeFamily::Fekete);
            eprintln!(
                "{shape:?} p={p}: {} nodes in {:.2?}",
                set.len(),
                start.elapsed()
            );
        }
    }
}

#[test]
fn fekete_lebesgue_constant_beats_equispaced_from_p4() {
    for (shape, max_p) in [(Shape::Tri, 9), (Shape::Tet, 7)] {
        for p in 4..=max_p {
            let fekete = lebesgue_constant(&ReferenceNodes::new(shape, p, NodeFamily::Fekete));
            let equi = lebesgue_constant(&ReferenceNodes::new(shape, p, NodeFamily::Equispaced));
            eprintln!("{shape:?} p={p}: Lebesgue fekete {fekete:.3} equispaced {equi:.3}");
            assert!(fekete < equi, "{shape:?} p={p}");
        }
    }
}

#[test]
fn fekete_nodes_are_inside_and_symmetric() {
    for (shape, max_p) in [(Shape::Tri, 10), (Shape::Tet, 8)] {
        let dim = shape.dim();
        for p in 1..=max_p {
            let set = ReferenceNodes::new(shape, p, NodeFamily::Fekete);
            let pi = p as i64;
            let bary_of = |x: &[f64; 3]| -> Vec<f64> {
                std::iter::once(1.0 - x[..dim].iter().sum::<f64>())
                    .chain(x[..dim].iter().copied())
                    .collect()
            };
            for (x, l) in set.points().iter().zip(set.lattice()) {
                let lam = bary_of(x);
                assert!(lam.iter().all(|&v| v > -1e-14), "{shape:?} p={p} outside");
                // Every permutation of the barycentric lattice indices is a node whose
                // coordinates are the same permutation of these.
                let b: Vec<i64> = std::iter::once(pi - l[..dim].iter().sum::<i64>())
                    .chain(l[..dim].iter().copied())
                    .collect();
                for perm in permutations(dim + 1) {
                    let mut image = [0i64; 3];
                    for c in 0..dim {
                        image[c] = b[perm[c + 1]];
                    }
                    let k = set.index_of_lattice(image).unwrap();
                    let mu = bary_of(&set.points()[k]);
                    for c in 0..=dim {
                        assert!((mu[c] - lam[perm[c]]).abs() < 1e-12, "{shape:?} p={p}");
                    }
                }
            }
        }
    }
}

fn permutations(n: usize) -> Vec<Vec<usize>> {
    if n == 1 {
        return vec![vec![0]];
    }
    let mut out = Vec::new();
    for rest in permutations(n - 1) {
        for pos in 0..n {
            let mut v = rest.clone();
            v.insert(pos, n - 1);
            out.push(v);
        }
    }
    out
}

/// The sets the solver works on stay well conditioned to p = 10: the Lebesgue constant
/// (how much interpolation can amplify errors in nodal values: the face set's decides how
/// far boundary interpolants stray from the geometry between nodes, the volume set's how
/// the resampling to the written equispaced nodes amplifies rounding) and the Vandermonde
/// condition number (the basis' own rounding) grow slowly for Fekete nodes, while the
/// equispaced ones blow up.
#[test]
fn fekete_sets_are_well_conditioned_to_p10() {
    for shape in [Shape::Tri, Shape::Tet] {
        for p in [2, 4, 6, 8, 10] {
            let fekete = ReferenceNodes::new(shape, p, NodeFamily::Fekete);
            let equi = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
            let (lf, le) = (lebesgue_constant(&fekete), lebesgue_constant(&equi));
            let cond = LagrangeBasis::new(&fekete).unwrap().condition_number();
            let cond_equi = LagrangeBasis::new(&equi).unwrap().condition_number();
            eprintln!("{shape:?} p={p}: Lebesgue fekete {lf:.3} equispaced {le:.3}; cond(V) fekete {cond:.3e} equispaced {cond_equi:.3e}");
            // Measured (p = 2, 4, 6, 8, 10): triangle 1.66 2.70 4.17 5.48 7.16, tetrahedron
            // 2.00 4.14 8.89 15.6 32.1 (equispaced 68.9 and 125 at p = 10); cond(V) at
            // p = 10: 23.7 and 203. Bounds 25 % above.
            let (lebesgue_bound, cond_bound) = match shape {
                Shape::Tri => ([2.1, 3.4, 5.2, 6.9, 9.0][p / 2 - 1], 30.0),
                _ => ([2.5, 5.2, 11.1, 19.5, 40.2][p / 2 - 1], 254.0),
            };
            assert!(lf <= lebesgue_bound, "{shape:?} p={p}: Lebesgue {lf}");
            assert!(cond <= cond_bound, "{shape:?} p={p}: cond {cond}");
            if p >= 4 {
                assert!(lf < le, "{shape:?} p={p}: {lf} vs equispaced {le}");
            }
            if p == 10 {
                assert!(le > 3.0 * lf, "{shape:?}: equispaced {le} vs {lf}");
            }
        }
    }
}
