//! Single-element meshes for the tests: the reference element of a type, its order-p nodes
//! moved by a known map (the meshes of several elements are hocurve-testmeshes').

use hocurve_mesh::{Element, HighOrderMesh, LinearMesh, Shape};
use hocurve_nodes::NodeFamily;

/// The reference element of `kind` at order `order` (equispaced nodes), every node x moved
/// to `map(x)`.
pub fn single_element(
    kind: Shape,
    order: usize,
    map: impl Fn([f64; 3]) -> [f64; 3],
) -> HighOrderMesh {
    single_element_of_family(kind, order, NodeFamily::Equispaced, map)
}

/// As [`single_element`] with nodes of `family`.
pub fn single_element_of_family(
    kind: Shape,
    order: usize,
    family: NodeFamily,
    map: impl Fn([f64; 3]) -> [f64; 3],
) -> HighOrderMesh {
    let shape = kind;
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

/// A deterministic pseudo-random number in [0, 1) from a seed (splitmix64).
pub fn hash01(seed: u64) -> f64 {
    let mut z = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}
