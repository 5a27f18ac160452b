use super::*;
use hocurve_nodes::ReferenceNodes;

#[test]
fn reference_stiffness_of_the_linear_triangle() {
    // Φ₀ = 1 − ξ − η, Φ₁ = ξ, Φ₂ = η; area 1/2: S_ξξ = ½ [[1,−1,0],[−1,1,0],[0,0,0]],
    // S_ξη[i][j] = ½ ∂ξΦᵢ ∂ηΦⱼ = ½ [[1,0,−1],[−1,0,1],[0,0,0]].
    let r = ReferenceStiffness::new(Shape::Tri, 1, NodeFamily::Equispaced).unwrap();
    let s = r.simplex_stiffness.as_ref().unwrap();
    let xx = [0.5, -0.5, 0.0, -0.5, 0.5, 0.0, 0.0, 0.0, 0.0];
    let xy = [0.5, 0.0, -0.5, -0.5, 0.0, 0.5, 0.0, 0.0, 0.0];
    for k in 0..9 {
        assert!((s[0][k] - xx[k]).abs() < 1e-15);
        assert!((s[1][k] - xy[k]).abs() < 1e-15);
        // S_ηξ = S_ξηᵀ.
        assert!((s[2][3 * (k % 3) + k / 3] - xy[k]).abs() < 1e-15);
    }
}

#[test]
fn reference_stiffness_rows_sum_to_zero_and_traces_match_volume_integrals() {
    // Σⱼ Φⱼ = 1 ⇒ rows of every S_αβ sum to 0; and Σᵢⱼ ξ-weighted sums give ∫ 1:
    // with xᵢ the nodes, Σᵢⱼ ξᵢ,α S_αα[i][j] ξⱼ,α = ∫ (∂ξ_α/∂ξ_α)² = |T|.
    for (shape, volume) in [(Shape::Tri, 0.5), (Shape::Tet, 1.0 / 6.0)] {
        for p in 1..=5 {
            let r = ReferenceStiffness::new(shape, p, NodeFamily::Fekete).unwrap();
            let nodes = ReferenceNodes::new(shape, p, NodeFamily::Fekete);
            let s = r.simplex_stiffness.as_ref().unwrap();
            let n = r.len;
            for (ab, m) in s.iter().enumerate() {
                for i in 0..n {
                    let row: f64 = m[i * n..(i + 1) * n].iter().sum();
                    assert!(row.abs() < 1e-11, "{shape:?} p={p} S{ab} row {i}: {row}");
                }
            }
            for a in 0..r.dim {
                let m = &s[a * r.dim + a];
                let mut total = 0.0;
                for i in 0..n {
                    for j in 0..n {
                        total += nodes.points()[i][a] * m[i * n + j] * nodes.points()[j][a];
                    }
                }
                assert!((total - volume).abs() < 1e-11, "{shape:?} p={p}: {total}");
            }
        }
    }
}

#[test]
fn a_prism_is_affine_when_its_top_is_a_translate_of_its_bottom() {
    let reference = ReferenceStiffness::new(Shape::Prism, 2, NodeFamily::Fekete).unwrap();
    let element = ReferenceElement::shared(Shape::Prism, 2, NodeFamily::Fekete).unwrap();
    // x = A ξ + b: affine, with a shear.
    let map = |xi: [f64; 3]| {
        [
            1.0 + 2.0 * xi[0] + 0.3 * xi[2],
            -1.0 + 0.5 * xi[0] + 1.5 * xi[1] + 0.1 * xi[2],
            0.7 * xi[2],
        ]
    };
    let coords: Vec<[f64; 3]> = element.nodes().points().iter().map(|&xi| map(xi)).collect();
    assert!(reference.is_affine_prism(&coords));
    // The top triangle scaled (a boundary-layer prism on a curved wall): not affine.
    let mut scaled = coords.clone();
    for v in 3..6 {
        scaled[v][0] *= 1.01;
    }
    assert!(!reference.is_affine_prism(&scaled));
    // A curved edge: not affine.
    let mut curved = coords.clone();
    curved[6][1] += 1e-3;
    assert!(!reference.is_affine_prism(&curved));
    // Not a prism.
    let tet = ReferenceStiffness::new(Shape::Tet, 2, NodeFamily::Fekete).unwrap();
    assert!(!tet.is_affine_prism(&coords[..10]));
}
