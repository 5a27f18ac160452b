//! Single-element meshes for the tests: the reference element of a type, its order-p nodes
//! moved by a known map.

use hocurve_mesh::{Element, ElementType, HighOrderMesh, LinearMesh};
use hocurve_nodes::NodeFamily;

/// The reference element of `kind` at order `order` (equispaced nodes), every node x moved
/// to `map(x)`.
pub fn single_element(
    kind: ElementType,
    order: usize,
    map: impl Fn([f64; 3]) -> [f64; 3],
) -> HighOrderMesh {
    single_element_of_family(kind, order, NodeFamily::Equispaced, map)
}

/// As [`single_element`] with nodes of `family`.
pub fn single_element_of_family(
    kind: ElementType,
    order: usize,
    family: NodeFamily,
    map: impl Fn([f64; 3]) -> [f64; 3],
) -> HighOrderMesh {
    let Ok(shape) = kind.shape() else {
        panic!("no reference shape for {kind}");
    };
    let mesh = LinearMesh {
        dim: shape.dim(),
        vertices: shape.vertices().to_vec(),
        cells: vec![Element {
            kind,
            vertices: (0..shape.num_vertices() as u32).collect(),
            entity: 1,
        }],
        ..Default::default()
    };
    let mut ho = match HighOrderMesh::from_linear(&mesh, order, family) {
        Ok(ho) => ho,
        Err(e) => panic!("{e}"),
    };
    for x in &mut ho.nodes {
        *x = map(*x);
    }
    ho
}

/// The unit cube cut into n³ cubes of 6 tetrahedra each (Kuhn's subdivision along the main
/// diagonal, conforming), positively oriented.
pub fn box_tets(n: usize) -> LinearMesh {
    let id = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let h = 1.0 / n as f64;
    let mut vertices = Vec::with_capacity((n + 1).pow(3));
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                vertices.push([i as f64 * h, j as f64 * h, k as f64 * h]);
            }
        }
    }
    let permutations = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut cells = Vec::with_capacity(6 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for perm in &permutations {
                    let mut c = [i, j, k];
                    let mut tet = vec![id(c[0], c[1], c[2])];
                    for &axis in perm {
                        c[axis] += 1;
                        tet.push(id(c[0], c[1], c[2]));
                    }
                    // An odd permutation gives a negatively oriented path: swap two.
                    let odd = matches!(perm, [0, 2, 1] | [1, 0, 2] | [2, 1, 0]);
                    if odd {
                        tet.swap(2, 3);
                    }
                    cells.push(Element {
                        kind: ElementType::Tet,
                        vertices: tet,
                        entity: 1,
                    });
                }
            }
        }
    }
    LinearMesh {
        dim: 3,
        vertices,
        cells,
        ..Default::default()
    }
}

/// A deterministic pseudo-random number in [0, 1) from a seed (splitmix64).
pub fn hash01(seed: u64) -> f64 {
    let mut z = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}
