//! Nodal sets of order p on the reference shapes, in hocurve's canonical local order.
//!
//! A nodal set is assembled entity by entity — vertices, the interior nodes of every local
//! edge (from its first vertex to its second), of every local face (in the face's own
//! frame: first vertex at the origin, second along ξ, last along η) and of the cell — from
//! the 1D, triangle, quadrilateral, ... interior sets of one [`NodeFamily`]. Because every
//! face of a 3D element carries exactly the 2D set of the same family, and every edge the 1D
//! set, neighbouring elements agree on their shared nodes.
//!
//! Each node also carries its *lattice index*: the integer coordinates `p·ξ` of the node it
//! corresponds to in the equispaced set. Every family lists its nodes in the same lattice
//! order, so the node orderings of file formats (which are defined on the equispaced
//! lattice) can be matched exactly, with integers.

use crate::fekete::fekete_interior;
use crate::warp_blend::{
    blyth_pozrikidis_tet, blyth_pozrikidis_triangle, gll_unit, warp_blend_tet, warp_blend_triangle,
};
use crate::{NodesError, Shape};

/// A family of nodal distributions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum NodeFamily {
    /// Equally spaced nodes ξ = lattice / p. Fine up to p ≈ 5; interpolation degrades beyond.
    #[default]
    Equispaced,
    /// Gauss–Lobatto–Legendre points on every edge and tensor GLL on quadrilaterals and
    /// hexahedra; inside simplices the Blyth–Pozrikidis formula built from them.
    GaussLobatto,
    /// Warburton's warp & blend nodes on simplices (GLL on edges), tensor GLL elsewhere.
    WarpBlend,
    /// Fekete points: on triangles and tetrahedra the interior nodes maximising the
    /// Vandermonde determinant with GLL edges (and Fekete triangle faces); on quadrilaterals
    /// and hexahedra tensor GLL, which are their Fekete points.
    Fekete,
}

impl NodeFamily {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            NodeFamily::Equispaced => "equispaced",
            NodeFamily::GaussLobatto => "gll",
            NodeFamily::WarpBlend => "warp-blend",
            NodeFamily::Fekete => "fekete",
        }
    }

    /// All families.
    pub const ALL: [NodeFamily; 4] = [
        NodeFamily::Equispaced,
        NodeFamily::GaussLobatto,
        NodeFamily::WarpBlend,
        NodeFamily::Fekete,
    ];

    /// Largest order this family provides.
    pub fn max_order(self) -> usize {
        match self {
            NodeFamily::Equispaced | NodeFamily::GaussLobatto | NodeFamily::WarpBlend => 20,
            NodeFamily::Fekete => 10,
        }
    }

    /// Checks that `order` is available in this family.
    pub fn check_order(self, order: usize) -> Result<(), NodesError> {
        if order == 0 || order > self.max_order() {
            return Err(NodesError::UnsupportedOrder {
                order,
                family: self.name(),
                max: self.max_order(),
            });
        }
        Ok(())
    }

    /// Interior nodes of the `shape` (none on its boundary), in lattice order, each with its
    /// lattice index. For `Line` these are the p − 1 interior points of [0, 1] in increasing
    /// order.
    pub fn interior_nodes(self, shape: Shape, order: usize) -> Vec<([f64; 3], [i64; 3])> {
        let lattice = interior_lattice(shape, order as i64);
        let p = order;
        if self == NodeFamily::Equispaced {
            let pf = p as f64;
            return lattice
                .into_iter()
                .map(|l| ([l[0] as f64 / pf, l[1] as f64 / pf, l[2] as f64 / pf], l))
                .collect();
        }
        if self == NodeFamily::Fekete && matches!(shape, Shape::Tri | Shape::Tet) {
            return fekete_interior(shape, p).as_ref().clone();
        }
        // Every other family has GLL points on lines and tensor products of them.
        let gll = gll_unit(p);
        let fekete_tri = if self == NodeFamily::Fekete && shape == Shape::Prism {
            Some(fekete_interior(Shape::Tri, p))
        } else {
            None
        };
        let tri = |l: [i64; 3]| -> [f64; 2] {
            if let Some(f) = &fekete_tri {
                // The prism's triangle layer: the Fekete triangle interior with this lattice.
                if let Some((x, _)) = f.iter().find(|(_, m)| m[..2] == l[..2]) {
                    return [x[0], x[1]];
                }
            }
            match self {
                NodeFamily::GaussLobatto => blyth_pozrikidis_triangle(p, [l[0], l[1]]),
                _ => warp_blend_triangle(p, [l[0], l[1]]),
            }
        };
        lattice
            .into_iter()
            .map(|l| {
                let g = |i: i64| gll[i as usize];
                let x = match shape {
                    Shape::Line => [g(l[0]), 0.0, 0.0],
                    Shape::Quad => [g(l[0]), g(l[1]), 0.0],
                    Shape::Hex => [g(l[0]), g(l[1]), g(l[2])],
                    Shape::Tri => {
                        let [x, y] = tri(l);
                        [x, y, 0.0]
                    }
                    Shape::Prism => {
                        let [x, y] = tri(l);
                        [x, y, g(l[2])]
                    }
                    Shape::Tet => match self {
                        NodeFamily::GaussLobatto => blyth_pozrikidis_tet(p, l),
                        _ => warp_blend_tet(p, l),
                    },
                };
                (x, l)
            })
            .collect()
    }
}

impl std::fmt::Display for NodeFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for NodeFamily {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        NodeFamily::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = NodeFamily::ALL.iter().map(|f| f.name()).collect();
                format!(
                    "unknown node family '{s}' (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

/// Lattice indices of the interior nodes of a shape, in the canonical lattice order:
/// the last coordinate varies slowest.
fn interior_lattice(shape: Shape, p: i64) -> Vec<[i64; 3]> {
    let mut out = Vec::new();
    match shape {
        Shape::Line => out.extend((1..p).map(|i| [i, 0, 0])),
        Shape::Tri => {
            for j in 1..p {
                for i in 1..p - j {
                    out.push([i, j, 0]);
                }
            }
        }
        Shape::Quad => {
            for j in 1..p {
                for i in 1..p {
                    out.push([i, j, 0]);
                }
            }
        }
        Shape::Tet => {
            for k in 1..p {
                for j in 1..p - k {
                    for i in 1..p - j - k {
                        out.push([i, j, k]);
                    }
                }
            }
        }
        Shape::Hex => {
            for k in 1..p {
                for j in 1..p {
                    for i in 1..p {
                        out.push([i, j, k]);
                    }
                }
            }
        }
        Shape::Prism => {
            for k in 1..p {
                for j in 1..p {
                    for i in 1..p - j {
                        out.push([i, j, k]);
                    }
                }
            }
        }
    }
    out
}

/// Which topological entity of the reference element a node belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NodeEntity {
    /// A vertex (local vertex index).
    Vertex(usize),
    /// The `index`-th interior node of local edge `edge`.
    Edge {
        /// Local edge index.
        edge: usize,
        /// Position among the edge's interior nodes.
        index: usize,
    },
    /// The `index`-th interior node of local face `face` (3D shapes only).
    Face {
        /// Local face index.
        face: usize,
        /// Position among the face's interior nodes.
        index: usize,
    },
    /// The `index`-th interior node of the element itself.
    Interior(usize),
}

/// The nodes of a complete order-p element of one shape and one family, in canonical order.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceNodes {
    shape: Shape,
    order: usize,
    family: NodeFamily,
    pub(crate) points: Vec<[f64; 3]>,
    lattice: Vec<[i64; 3]>,
    entities: Vec<NodeEntity>,
}

impl ReferenceNodes {
    /// Builds the set. Panics only if `order` is 0 or above the family's maximum; use
    /// [`ReferenceNodes::try_new`] for orders that come from a user.
    pub fn new(shape: Shape, order: usize, family: NodeFamily) -> Self {
        match Self::try_new(shape, order, family) {
            Ok(set) => set,
            Err(e) => panic!("{e}"),
        }
    }

    /// Builds the set, or says why the order is unavailable.
    pub fn try_new(shape: Shape, order: usize, family: NodeFamily) -> Result<Self, NodesError> {
        family.check_order(order)?;
        let interior = if shape.dim() > 1 {
            family.interior_nodes(shape, order)
        } else {
            Vec::new()
        };
        Ok(Self::assemble(shape, order, family, interior))
    }

    /// Assembles the set from the family's edge and face sets and the given cell-interior
    /// nodes (lattice order).
    pub(crate) fn assemble(
        shape: Shape,
        order: usize,
        family: NodeFamily,
        interior: Vec<([f64; 3], [i64; 3])>,
    ) -> Self {
        let p = order as i64;
        let vertices = shape.vertices();
        let vertex_lattice: Vec<[i64; 3]> = vertices
            .iter()
            .map(|v| [v[0] as i64 * p, v[1] as i64 * p, v[2] as i64 * p])
            .collect();
        let mut set = ReferenceNodes {
            shape,
            order,
            family,
            points: Vec::with_capacity(shape.num_nodes(order)),
            lattice: Vec::with_capacity(shape.num_nodes(order)),
            entities: Vec::with_capacity(shape.num_nodes(order)),
        };
        for (i, v) in vertices.iter().enumerate() {
            set.push(*v, vertex_lattice[i], NodeEntity::Vertex(i));
        }
        let line = family.interior_nodes(Shape::Line, order);
        for (e, &[a, b]) in shape.edges().iter().enumerate() {
            for (index, (t, l)) in line.iter().enumerate() {
                let point = affine(vertices[a], &[(vertices[b], t[0])]);
                let lat = lattice_combination(vertex_lattice[a], &[(vertex_lattice[b], l[0])], p);
                set.push(point, lat, NodeEntity::Edge { edge: e, index });
            }
        }
        for (f, face) in shape.faces().iter().enumerate() {
            let face_shape = Shape::face_shape(face.len());
            // The face frame: origin at its first vertex, ξ towards the second, η towards
            // the last (for a triangle the third, for a quadrilateral the fourth).
            let (o, a, b) = (face[0], face[1], face[face.len() - 1]);
            for (index, (x, l)) in family.interior_nodes(face_shape, order).iter().enumerate() {
                let point = affine(vertices[o], &[(vertices[a], x[0]), (vertices[b], x[1])]);
                let lat = lattice_combination(
                    vertex_lattice[o],
                    &[(vertex_lattice[a], l[0]), (vertex_lattice[b], l[1])],
                    p,
                );
                set.push(point, lat, NodeEntity::Face { face: f, index });
            }
        }
        for (index, (x, l)) in interior.into_iter().enumerate() {
            set.push(x, l, NodeEntity::Interior(index));
        }
        debug_assert_eq!(set.points.len(), shape.num_nodes(order));
        set
    }

    fn push(&mut self, point: [f64; 3], lattice: [i64; 3], entity: NodeEntity) {
        self.points.push(point);
        self.lattice.push(lattice);
        self.entities.push(entity);
    }

    /// The shape.
    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// The polynomial order p.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The node family.
    pub fn family(&self) -> NodeFamily {
        self.family
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false: every element has its vertices.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Reference coordinates ξ of the nodes, canonical order.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Lattice indices `p·ξ` of the corresponding equispaced nodes, canonical order.
    pub fn lattice(&self) -> &[[i64; 3]] {
        &self.lattice
    }

    /// The entity each node belongs to, canonical order.
    pub fn entities(&self) -> &[NodeEntity] {
        &self.entities
    }

    /// Index of the node with lattice index `l`, if any.
    pub fn index_of_lattice(&self, l: [i64; 3]) -> Option<usize> {
        self.lattice.iter().position(|&m| m == l)
    }
}

/// `origin + Σ t_k (v_k − origin)`.
fn affine(origin: [f64; 3], terms: &[([f64; 3], f64)]) -> [f64; 3] {
    let mut x = origin;
    for (v, t) in terms {
        for d in 0..3 {
            x[d] += t * (v[d] - origin[d]);
        }
    }
    x
}

/// Lattice version of [`affine`]: `origin + Σ m_k (v_k − origin) / p`, exact in integers
/// because vertex lattice coordinates are 0 or p.
fn lattice_combination(origin: [i64; 3], terms: &[([i64; 3], i64)], p: i64) -> [i64; 3] {
    let mut x = origin;
    for (v, m) in terms {
        for d in 0..3 {
            x[d] += m * (v[d] - origin[d]) / p;
        }
    }
    x
}

#[cfg(test)]
#[path = "tests/nodal_sets.rs"]
mod tests;
