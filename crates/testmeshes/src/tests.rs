use super::*;

const FILLS: [Fill; 6] = [
    Fill::Tet(Kuhn::Paired),
    Fill::Tet(Kuhn::Lexicographic),
    Fill::Tet(Kuhn::LexicographicMiddleSwapped),
    Fill::Hex,
    Fill::Prism,
    Fill::HexPrism,
];

#[test]
fn every_fill_is_a_valid_mesh_of_the_unit_cube() {
    for fill in FILLS {
        for n in 1..=3 {
            for perturb in [0.0, 0.2] {
                let mesh = unit_cube(n, fill, perturb);
                // from_linear validates the mesh and checks that every cell is positive.
                let ho = high_order(&mesh, 1, NodeFamily::Equispaced);
                assert_eq!(ho.nodes.len(), (n + 1).pow(3));
                let per_cube = match fill {
                    Fill::Tet(_) => 6,
                    Fill::Hex => 1,
                    Fill::Prism => 2,
                    Fill::HexPrism => 0,
                };
                if per_cube > 0 {
                    assert_eq!(mesh.cells.len(), per_cube * n.pow(3), "{fill:?}");
                }
            }
        }
    }
}

#[test]
fn the_kuhn_listings_hold_the_same_tetrahedra() {
    let sorted = |kuhn| {
        let mut tets: Vec<Vec<u32>> = unit_cube(2, Fill::Tet(kuhn), 0.2)
            .cells
            .into_iter()
            .map(|c| {
                let mut v = c.vertices;
                v.sort_unstable();
                v
            })
            .collect();
        tets.sort();
        tets
    };
    let paired = sorted(Kuhn::Paired);
    assert_eq!(paired, sorted(Kuhn::Lexicographic));
    assert_eq!(paired, sorted(Kuhn::LexicographicMiddleSwapped));
}

#[test]
fn only_interior_vertices_move_and_within_their_range() {
    let n = 4;
    let h = 1.0 / n as f64;
    let straight = unit_cube(n, Fill::Hex, 0.0);
    let moved = unit_cube(n, Fill::Hex, 0.3);
    let mut interior_moved = 0;
    for (a, b) in straight.vertices.iter().zip(&moved.vertices) {
        let on_boundary = a.iter().any(|&x| x == 0.0 || x == 1.0);
        for d in 0..3 {
            let shift = b[d] - a[d];
            // (−3, 1) · amplitude · h, to rounding (x + δ − x is δ only to an ulp of x).
            assert!(
                -0.9 * h - 1e-15 < shift && shift < 0.3 * h + 1e-15,
                "{shift}"
            );
            if on_boundary {
                assert_eq!(shift, 0.0);
            } else if shift != 0.0 {
                interior_moved += 1;
            }
        }
    }
    assert_eq!(interior_moved, 3 * (n - 1).pow(3));
    let square = unit_square(n, Shape::Quad, 0.3);
    assert!(square.vertices.iter().all(|x| x[2] == 0.0));
    assert_eq!(square.vertices[..=n], straight.vertices[..=n]);
}
