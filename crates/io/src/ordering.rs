//! Node orderings of the complete high-order elements of Gmsh and VTK.
//!
//! Both formats define their node order on the equispaced lattice of the element, so an
//! ordering is given here as the list of *lattice indices* (`p·ξ`, integer coordinates in
//! hocurve's reference element, see [`hocurve_nodes::ReferenceNodes::lattice`]) of the
//! format's nodes, in the format's order. Matching lattice indices exactly (integers) gives
//! the permutation between a format and hocurve's canonical order, whatever node family the
//! mesh uses.
//!
//! The orderings are computed by rules, for any order, and are checked in the tests
//! against `crates/io/tests/data/orderings_{gmsh,vtk}.json`, which
//! `xtask/scripts/dump_orderings.py` reads out of the real Gmsh and VTK libraries.
//!
//! # Gmsh (complete elements, all shapes)
//! Vertices; the interior nodes of each edge of Gmsh's edge list, from its first vertex to
//! its second; for 3D shapes the interior nodes of each face of Gmsh's face list, ordered as
//! a Gmsh element of order p − 3 (triangle) or p − 2 (quadrilateral) placed on the face with
//! its origin at the face's first vertex, its ξ axis towards the second and its η axis
//! towards the third (triangle) or the last (quadrilateral) vertex; then the interior,
//! again recursively as a Gmsh element of the same shape of order p − 4 (tetrahedron) or
//! p − 2 (hexahedron), shifted by one lattice step. The prism is the exception: its interior
//! is not a recursive prism but the product of the order p − 3 Gmsh triangle (outer loop)
//! with the order p − 2 Gmsh *line* (inner loop) — whose order is endpoints first, so the
//! layers come as k = 1, p − 1, 2, 3, …, p − 2.
//!
//! # VTK (Lagrange cells, types 68–73)
//! Curve: endpoints, then the interior. Triangle: recursive like Gmsh's (vertices, edges
//! 0→1, 1→2, 2→0, then the interior as a triangle of order p − 3). Tetrahedron: vertices,
//! edges (0,1), (1,2), (2,0), (0,3), (1,3), (2,3); faces (0,1,3), (2,3,1), (0,3,2),
//! (0,2,1), each as a recursive triangle from the first listed vertex; interior as a
//! tetrahedron of order p − 4. Quadrilateral and hexahedron: every edge and every face runs
//! along increasing parametric axes (so edge 2 of a quadrilateral goes from vertex 3 to 2,
//! and the vertical hexahedron edges are (0,4), (1,5), (2,6), (3,7) — the order of VTK ≥ 9
//! and of `.vtu` files of version ≥ 2.1; older files swapped the last two), faces ordered
//! x = 0, x = 1, y = 0, y = 1, z = 0, z = 1 and tensor-ordered (lower axis fastest), the
//! interior tensor-ordered x fastest. Wedge: vertices; edges (0,1), (1,2), (2,0), (3,4),
//! (4,5), (5,3), (0,3), (1,4), (2,5); the triangular faces bottom then top, *row by row*
//! (not recursively); the quadrilateral faces y = 0 (from vertex 0 towards 1), x + y = 1
//! (from 1 towards 2) and x = 0 (from 2 towards 0), each with the horizontal index fastest;
//! then the interior layer by layer, each layer row by row.

use std::collections::HashMap;

use hocurve_nodes::{NodeFamily, ReferenceNodes, Shape};

/// A lattice index.
type Lat = [i64; 3];

// ---------------------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------------------

/// Lattice positions of the vertices of `shape` at order `p`.
fn vertex_lattice(shape: Shape, p: i64) -> Vec<Lat> {
    shape
        .vertices()
        .iter()
        .map(|v| [v[0] as i64 * p, v[1] as i64 * p, v[2] as i64 * p])
        .collect()
}

/// `o + (u − o)·a/p + (v − o)·b/p`: the point (a, b) of a face's own lattice placed on the
/// face with origin `o`, ξ towards `u` and η towards `v`. Exact, since the corners of a
/// face are lattice points with coordinates 0 or p.
fn on_face(o: Lat, u: Lat, v: Lat, p: i64, a: i64, b: i64) -> Lat {
    let mut x = o;
    for d in 0..3 {
        x[d] += (u[d] - o[d]) / p * a + (v[d] - o[d]) / p * b;
    }
    x
}

/// Appends the interior nodes of each edge, from its first vertex to its second.
fn push_edges(out: &mut Vec<Lat>, verts: &[Lat], edges: &[[usize; 2]], p: i64) {
    for &[a, b] in edges {
        for i in 1..p {
            out.push(on_face(verts[a], verts[b], verts[a], p, i, 0));
        }
    }
}

/// Appends face-local points `pts` (lattice of order `p`) placed on the face (o, u, v).
fn push_face(out: &mut Vec<Lat>, o: Lat, u: Lat, v: Lat, p: i64, pts: &[[i64; 2]]) {
    out.extend(pts.iter().map(|&[a, b]| on_face(o, u, v, p, a, b)));
}

/// Shifts 2D points by (1, 1).
fn shift2(pts: Vec<[i64; 2]>) -> Vec<[i64; 2]> {
    pts.into_iter().map(|[a, b]| [a + 1, b + 1]).collect()
}

/// Shifts 3D points by (1, 1, 1).
fn shift3(pts: Vec<Lat>) -> Vec<Lat> {
    pts.into_iter()
        .map(|[a, b, c]| [a + 1, b + 1, c + 1])
        .collect()
}

fn to2(pts: Vec<Lat>) -> Vec<[i64; 2]> {
    pts.into_iter().map(|[a, b, _]| [a, b]).collect()
}

/// Line of order q, endpoints first (Gmsh and VTK alike): 0, q, 1, 2, …, q − 1.
fn line_endpoints_first(q: i64) -> Vec<i64> {
    if q == 0 {
        return vec![0];
    }
    let mut out = vec![0, q];
    out.extend(1..q);
    out
}

/// Triangle edges of Gmsh (`edges_tri`) and VTK alike.
const TRI_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// The recursive triangle of order q shared by Gmsh and VTK: vertices, edges 0→1, 1→2, 2→0,
/// then the interior as the same triangle of order q − 3 shifted by (1, 1).
fn recursive_triangle(q: i64) -> Vec<[i64; 2]> {
    if q == 0 {
        return vec![[0, 0]];
    }
    let verts = vertex_lattice(Shape::Tri, q);
    let mut out = verts.clone();
    push_edges(&mut out, &verts, &TRI_EDGES, q);
    let mut out = to2(out);
    if q >= 3 {
        out.extend(shift2(recursive_triangle(q - 3)));
    }
    out
}

/// Interior nodes of a triangle of order q row by row (ξ fastest): VTK's wedge faces.
fn triangle_rows(q: i64) -> Vec<[i64; 2]> {
    let mut out = Vec::new();
    for j in 1..q {
        for i in 1..q - j {
            out.push([i, j]);
        }
    }
    out
}

/// Interior nodes of a quadrilateral of order q in tensor order (ξ fastest).
fn quad_tensor_interior(q: i64) -> Vec<[i64; 2]> {
    let mut out = Vec::new();
    for j in 1..q {
        for i in 1..q {
            out.push([i, j]);
        }
    }
    out
}

// ---------------------------------------------------------------------------------------
// Gmsh
// ---------------------------------------------------------------------------------------

// Gmsh's local edges and faces (MElement: edges_tri, edges_quad, edges_tetra, faces_tetra,
// edges_hexa, faces_hexa, edges_prism, faces_prism). Spelled out here rather than taken
// from `Shape` so that the file format cannot change if hocurve's own tables do.
const GMSH_QUAD_EDGES: [[usize; 2]; 4] = [[0, 1], [1, 2], [2, 3], [3, 0]];
const GMSH_TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [3, 0], [3, 2], [3, 1]];
const GMSH_TET_FACES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [3, 1, 2]];
const GMSH_HEX_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [0, 3],
    [0, 4],
    [1, 2],
    [1, 5],
    [2, 3],
    [2, 6],
    [3, 7],
    [4, 5],
    [4, 7],
    [5, 6],
    [6, 7],
];
const GMSH_HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [0, 1, 5, 4],
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [4, 5, 6, 7],
];
const GMSH_PRISM_EDGES: [[usize; 2]; 9] = [
    [0, 1],
    [0, 2],
    [0, 3],
    [1, 2],
    [1, 4],
    [2, 5],
    [3, 4],
    [3, 5],
    [4, 5],
];
const GMSH_PRISM_TRI_FACES: [[usize; 3]; 2] = [[0, 2, 1], [3, 4, 5]];
const GMSH_PRISM_QUAD_FACES: [[usize; 4]; 3] = [[0, 1, 4, 3], [0, 3, 5, 2], [1, 2, 5, 4]];

fn gmsh_triangle(q: i64) -> Vec<[i64; 2]> {
    recursive_triangle(q)
}

fn gmsh_quad(q: i64) -> Vec<[i64; 2]> {
    if q == 0 {
        return vec![[0, 0]];
    }
    let verts = vertex_lattice(Shape::Quad, q);
    let mut out = verts.clone();
    push_edges(&mut out, &verts, &GMSH_QUAD_EDGES, q);
    let mut out = to2(out);
    if q >= 2 {
        out.extend(shift2(gmsh_quad(q - 2)));
    }
    out
}

fn gmsh_tet(q: i64) -> Vec<Lat> {
    if q == 0 {
        return vec![[0, 0, 0]];
    }
    let v = vertex_lattice(Shape::Tet, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &GMSH_TET_EDGES, q);
    if q >= 3 {
        let face = shift2(gmsh_triangle(q - 3));
        for [a, b, c] in GMSH_TET_FACES {
            push_face(&mut out, v[a], v[b], v[c], q, &face);
        }
    }
    if q >= 4 {
        out.extend(shift3(gmsh_tet(q - 4)));
    }
    out
}

fn gmsh_hex(q: i64) -> Vec<Lat> {
    if q == 0 {
        return vec![[0, 0, 0]];
    }
    let v = vertex_lattice(Shape::Hex, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &GMSH_HEX_EDGES, q);
    if q >= 2 {
        let face = shift2(gmsh_quad(q - 2));
        for [a, b, _, d] in GMSH_HEX_FACES {
            push_face(&mut out, v[a], v[b], v[d], q, &face);
        }
        out.extend(shift3(gmsh_hex(q - 2)));
    }
    out
}

fn gmsh_prism(q: i64) -> Vec<Lat> {
    let v = vertex_lattice(Shape::Prism, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &GMSH_PRISM_EDGES, q);
    // Faces in Gmsh's order: the two triangles, then the three quadrilaterals.
    if q >= 3 {
        let face = shift2(gmsh_triangle(q - 3));
        for [a, b, c] in GMSH_PRISM_TRI_FACES {
            push_face(&mut out, v[a], v[b], v[c], q, &face);
        }
    }
    if q >= 2 {
        let face = shift2(gmsh_quad(q - 2));
        for [a, b, _, d] in GMSH_PRISM_QUAD_FACES {
            push_face(&mut out, v[a], v[b], v[d], q, &face);
        }
    }
    if q >= 3 {
        // Triangle (outer) × Gmsh line (inner, endpoints first).
        let layers = line_endpoints_first(q - 2);
        for [a, b] in gmsh_triangle(q - 3) {
            for &k in &layers {
                out.push([a + 1, b + 1, k + 1]);
            }
        }
    }
    out
}

/// Lattice indices (`p·ξ` in hocurve's reference coordinates) of the nodes of Gmsh's
/// complete order-`p` element of `shape`, in Gmsh's node order (the order of `.msh` files
/// and of `gmsh.model.mesh.getElementProperties`). Any `p ≥ 1`.
pub fn gmsh_lattice(shape: Shape, p: usize) -> Vec<[i64; 3]> {
    assert!(p >= 1, "element order must be at least 1");
    let q = p as i64;
    let lift = |pts: Vec<[i64; 2]>| pts.into_iter().map(|[a, b]| [a, b, 0]).collect();
    match shape {
        Shape::Line => line_endpoints_first(q)
            .into_iter()
            .map(|i| [i, 0, 0])
            .collect(),
        Shape::Tri => lift(gmsh_triangle(q)),
        Shape::Quad => lift(gmsh_quad(q)),
        Shape::Tet => gmsh_tet(q),
        Shape::Hex => gmsh_hex(q),
        Shape::Prism => gmsh_prism(q),
    }
}

// ---------------------------------------------------------------------------------------
// VTK
// ---------------------------------------------------------------------------------------

const VTK_QUAD_EDGES: [[usize; 2]; 4] = [[0, 1], [1, 2], [3, 2], [0, 3]];
const VTK_TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
/// Faces as (origin, ξ end, η end) of the recursive triangle placed on them.
const VTK_TET_FACES: [[usize; 3]; 4] = [[0, 1, 3], [2, 3, 1], [0, 3, 2], [0, 2, 1]];
const VTK_HEX_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [3, 2],
    [0, 3],
    [4, 5],
    [5, 6],
    [7, 6],
    [4, 7],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];
/// Faces x = 0, x = 1, y = 0, y = 1, z = 0, z = 1 as (origin, ξ end, η end).
const VTK_HEX_FACES: [[usize; 3]; 6] = [
    [0, 3, 4],
    [1, 2, 5],
    [0, 1, 4],
    [3, 2, 7],
    [0, 1, 3],
    [4, 5, 7],
];
const VTK_WEDGE_EDGES: [[usize; 2]; 9] = [
    [0, 1],
    [1, 2],
    [2, 0],
    [3, 4],
    [4, 5],
    [5, 3],
    [0, 3],
    [1, 4],
    [2, 5],
];
/// Triangle faces (bottom, top) as (origin, ξ end, η end).
const VTK_WEDGE_TRI_FACES: [[usize; 3]; 2] = [[0, 1, 2], [3, 4, 5]];
/// Quadrilateral faces y = 0, x + y = 1, x = 0 as (origin, ξ end, η end).
const VTK_WEDGE_QUAD_FACES: [[usize; 3]; 3] = [[0, 1, 3], [1, 2, 4], [2, 0, 5]];

fn vtk_tet(q: i64) -> Vec<Lat> {
    if q == 0 {
        return vec![[0, 0, 0]];
    }
    let v = vertex_lattice(Shape::Tet, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &VTK_TET_EDGES, q);
    if q >= 3 {
        let face = shift2(recursive_triangle(q - 3));
        for [a, b, c] in VTK_TET_FACES {
            push_face(&mut out, v[a], v[b], v[c], q, &face);
        }
    }
    if q >= 4 {
        out.extend(shift3(vtk_tet(q - 4)));
    }
    out
}

fn vtk_quad(q: i64) -> Vec<Lat> {
    let v = vertex_lattice(Shape::Quad, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &VTK_QUAD_EDGES, q);
    out.extend(quad_tensor_interior(q).into_iter().map(|[a, b]| [a, b, 0]));
    out
}

fn vtk_hex(q: i64) -> Vec<Lat> {
    let v = vertex_lattice(Shape::Hex, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &VTK_HEX_EDGES, q);
    let face = quad_tensor_interior(q);
    for [a, b, c] in VTK_HEX_FACES {
        push_face(&mut out, v[a], v[b], v[c], q, &face);
    }
    for k in 1..q {
        for j in 1..q {
            for i in 1..q {
                out.push([i, j, k]);
            }
        }
    }
    out
}

fn vtk_wedge(q: i64) -> Vec<Lat> {
    let v = vertex_lattice(Shape::Prism, q);
    let mut out = v.clone();
    push_edges(&mut out, &v, &VTK_WEDGE_EDGES, q);
    let tri = triangle_rows(q);
    for [a, b, c] in VTK_WEDGE_TRI_FACES {
        push_face(&mut out, v[a], v[b], v[c], q, &tri);
    }
    let quad = quad_tensor_interior(q);
    for [a, b, c] in VTK_WEDGE_QUAD_FACES {
        push_face(&mut out, v[a], v[b], v[c], q, &quad);
    }
    for k in 1..q {
        out.extend(tri.iter().map(|&[i, j]| [i, j, k]));
    }
    out
}

/// Lattice indices (`p·ξ` in hocurve's reference coordinates) of the points of VTK's
/// Lagrange cell of order `p` of `shape` (`VTK_LAGRANGE_CURVE` 68, `_TRIANGLE` 69,
/// `_QUADRILATERAL` 70, `_TETRAHEDRON` 71, `_HEXAHEDRON` 72, `_WEDGE` 73), in VTK's point
/// order, as VTK ≥ 9.7 and `.vtu` files of version ≥ 2.1 define it. Any `p ≥ 1`. At
/// `p = 1` this is also the order of VTK's linear cells (3, 5, 9, 10, 12, 13).
pub fn vtk_lattice(shape: Shape, p: usize) -> Vec<[i64; 3]> {
    assert!(p >= 1, "element order must be at least 1");
    let q = p as i64;
    match shape {
        Shape::Line => line_endpoints_first(q)
            .into_iter()
            .map(|i| [i, 0, 0])
            .collect(),
        Shape::Tri => recursive_triangle(q)
            .into_iter()
            .map(|[a, b]| [a, b, 0])
            .collect(),
        Shape::Quad => vtk_quad(q),
        Shape::Tet => vtk_tet(q),
        Shape::Hex => vtk_hex(q),
        Shape::Prism => vtk_wedge(q),
    }
}

// ---------------------------------------------------------------------------------------
// Permutations and type numbers
// ---------------------------------------------------------------------------------------

/// `perm[k]` = index in hocurve's canonical order of the node with lattice index
/// `lattice[k]`.
fn permutation_of(shape: Shape, p: usize, lattice: &[[i64; 3]]) -> Vec<usize> {
    // Every node family lists its nodes in the same lattice order, so the equispaced set
    // gives the canonical lattice order for all of them.
    let reference = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
    let index: HashMap<[i64; 3], usize> = reference
        .lattice()
        .iter()
        .enumerate()
        .map(|(i, &l)| (l, i))
        .collect();
    assert_eq!(lattice.len(), reference.len(), "{shape:?} p={p}");
    lattice
        .iter()
        .map(|l| match index.get(l) {
            Some(&i) => i,
            None => panic!("{shape:?} p={p}: lattice index {l:?} is not a node"),
        })
        .collect()
}

/// Permutation from Gmsh's node order to hocurve's: `perm[k]` is the index, in hocurve's
/// canonical order of `shape` at order `p`, of the k-th node of Gmsh's element. To write an
/// element, emit `nodes[perm[k]]` for k = 0, 1, …; to read one, set
/// `nodes[perm[k]] = file[k]`.
///
/// Panics if `p` is 0 or above the largest order hocurve supports
/// ([`NodeFamily::max_order`]).
pub fn gmsh_permutation(shape: Shape, p: usize) -> Vec<usize> {
    permutation_of(shape, p, &gmsh_lattice(shape, p))
}

/// Permutation from VTK's Lagrange point order to hocurve's, like [`gmsh_permutation`].
pub fn vtk_permutation(shape: Shape, p: usize) -> Vec<usize> {
    permutation_of(shape, p, &vtk_lattice(shape, p))
}

/// The inverse of a permutation: `inv[perm[k]] = k`.
pub fn invert_permutation(perm: &[usize]) -> Vec<usize> {
    let mut inv = vec![usize::MAX; perm.len()];
    for (k, &i) in perm.iter().enumerate() {
        inv[i] = k;
    }
    inv
}

// Gmsh's element type numbers of the complete elements, order 1 first (GmshDefines.h:
// MSH_LIN_2 … MSH_LIN_11, MSH_TRI_3 … MSH_TRI_66, MSH_QUA_4 … MSH_QUA_121, MSH_TET_4 …
// MSH_TET_286, MSH_HEX_8 … MSH_HEX_1000, MSH_PRI_6 … MSH_PRI_550).
const GMSH_LINE_TYPES: [i32; 10] = [1, 8, 26, 27, 28, 62, 63, 64, 65, 66];
const GMSH_TRI_TYPES: [i32; 10] = [2, 9, 21, 23, 25, 42, 43, 44, 45, 46];
const GMSH_QUAD_TYPES: [i32; 10] = [3, 10, 36, 37, 38, 47, 48, 49, 50, 51];
const GMSH_TET_TYPES: [i32; 10] = [4, 11, 29, 30, 31, 71, 72, 73, 74, 75];
const GMSH_HEX_TYPES: [i32; 9] = [5, 12, 92, 93, 94, 95, 96, 97, 98];
const GMSH_PRISM_TYPES: [i32; 9] = [6, 13, 90, 91, 106, 107, 108, 109, 110];

fn gmsh_types(shape: Shape) -> &'static [i32] {
    match shape {
        Shape::Line => &GMSH_LINE_TYPES,
        Shape::Tri => &GMSH_TRI_TYPES,
        Shape::Quad => &GMSH_QUAD_TYPES,
        Shape::Tet => &GMSH_TET_TYPES,
        Shape::Hex => &GMSH_HEX_TYPES,
        Shape::Prism => &GMSH_PRISM_TYPES,
    }
}

/// Gmsh's element type number of the complete order-`p` element of `shape`, or `None` where
/// Gmsh has none (order 0, lines/triangles/quadrilaterals/tetrahedra above 10, hexahedra and
/// prisms above 9).
pub fn gmsh_element_type(shape: Shape, p: usize) -> Option<i32> {
    p.checked_sub(1)
        .and_then(|i| gmsh_types(shape).get(i).copied())
}

/// Largest order of `shape` that Gmsh has a complete element type for.
pub fn gmsh_max_order(shape: Shape) -> usize {
    gmsh_types(shape).len()
}

/// The shape and order of a complete Gmsh element type, or `None` for other types (points,
/// pyramids, incomplete/serendipity elements, polygons, …).
pub fn gmsh_type_shape(element_type: i32) -> Option<(Shape, usize)> {
    Shape::ALL.into_iter().find_map(|shape| {
        gmsh_types(shape)
            .iter()
            .position(|&t| t == element_type)
            .map(|i| (shape, i + 1))
    })
}

/// VTK cell type for an element of `shape` and order `p`: the linear types (`VTK_LINE` 3,
/// `VTK_TRIANGLE` 5, `VTK_QUAD` 9, `VTK_TETRA` 10, `VTK_HEXAHEDRON` 12, `VTK_WEDGE` 13) at
/// `p = 1`, the Lagrange types 68–73 above. Both use the point order of [`vtk_lattice`].
pub fn vtk_cell_type(shape: Shape, p: usize) -> u8 {
    match (shape, p) {
        (Shape::Line, 1) => 3,
        (Shape::Tri, 1) => 5,
        (Shape::Quad, 1) => 9,
        (Shape::Tet, 1) => 10,
        (Shape::Hex, 1) => 12,
        (Shape::Prism, 1) => 13,
        (Shape::Line, _) => 68,
        (Shape::Tri, _) => 69,
        (Shape::Quad, _) => 70,
        (Shape::Tet, _) => 71,
        (Shape::Hex, _) => 72,
        (Shape::Prism, _) => 73,
    }
}

#[cfg(test)]
#[path = "tests/ordering.rs"]
mod tests;
