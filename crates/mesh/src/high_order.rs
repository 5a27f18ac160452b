//! The high-order mesh: p-th order nodes shared exactly between neighbouring cells.
//!
//! Global nodes are numbered vertices first, then the interior nodes of each edge, of each
//! face (3D), of each cell ([`NodeLayout`]). The position of a shared node is computed once,
//! from the edge's or face's canonical frame (see [`crate::canonical_face`]), so both cells
//! sharing it get the same node id and bitwise the same coordinates whatever their local
//! orientation; each cell then finds its local nodes in that frame through an exact
//! integer map of lattice indices.

use std::collections::btree_map::Entry;
use std::collections::{BTreeMap, HashMap};

use std::sync::Arc;

use hocurve_nodes::{NodeEntity, NodeFamily, ReferenceElement, Shape};
use rayon::prelude::*;

use crate::topology::face_key;
use crate::{LinearMesh, MeshError, PhysicalGroup, Topology};

/// An element of a high-order mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HighOrderElement {
    /// Element type (its shape).
    pub kind: Shape,
    /// Global node ids in hocurve's canonical local order of the shape
    /// (see [`hocurve_nodes::ReferenceNodes`]).
    pub nodes: Vec<u32>,
    /// Geometric entity tag, as in the linear mesh.
    pub entity: i32,
}

/// Where each entity's nodes start in the global numbering: the vertices first, then the
/// interior nodes of each edge, each face and each cell, entity by entity. Built with the
/// mesh and read through accessors, so that its storage can change without its users.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct NodeLayout {
    /// Number of vertices V (nodes `0..V`).
    pub(crate) num_vertices: usize,
    /// Number of unique edges E; edge e owns nodes `V + e(p−1) ..`.
    pub(crate) num_edges: usize,
    /// First node of each face's interior (3D; `len = F + 1`, the last entry ends the range).
    pub(crate) face_first_node: Vec<u32>,
    /// First node of each cell's interior (`len = C + 1`).
    pub(crate) cell_first_node: Vec<u32>,
}

impl NodeLayout {
    /// Number of vertices V: nodes `0..V` are the vertices.
    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }

    /// Number of unique edges E.
    pub fn num_edges(&self) -> usize {
        self.num_edges
    }

    /// First interior node of edge `e`: V + e(p − 1).
    pub fn edge_first_node(&self, e: usize, order: usize) -> usize {
        self.num_vertices + e * (order - 1)
    }

    /// First interior node of each face (3D), then the end of the last face's range:
    /// face f owns nodes `first[f]..first[f + 1]`.
    pub fn face_first_nodes(&self) -> &[u32] {
        &self.face_first_node
    }

    /// First interior node of each cell, then the end of the last cell's range.
    pub fn cell_first_nodes(&self) -> &[u32] {
        &self.cell_first_node
    }
}

/// A mesh of order p: straight-sided when built from a linear mesh, curved after hocurve
/// has moved its nodes.
#[derive(Debug, Clone)]
pub struct HighOrderMesh {
    /// Mesh dimension (2 or 3).
    pub dim: usize,
    /// Polynomial order p.
    pub order: usize,
    /// Node family of the reference elements the nodes were placed from.
    pub family: NodeFamily,
    /// Node coordinates.
    pub nodes: Vec<[f64; 3]>,
    /// Cells, same order as the linear mesh's.
    pub cells: Vec<HighOrderElement>,
    /// Facets declared in the file, same order as the linear mesh's, at order p.
    pub facets: Vec<HighOrderElement>,
    /// Topology facet (face in 3D, edge in 2D) of each declared facet.
    pub facet_ids: Vec<u32>,
    /// Physical groups, as in the linear mesh.
    pub physical_groups: Vec<PhysicalGroup>,
    /// Physical tags of each geometric entity, as in the linear mesh.
    pub entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
    /// Edges and faces of the underlying linear mesh ([`HighOrderMesh::topology`]).
    pub(crate) topology: Topology,
    /// Global node numbering ([`HighOrderMesh::layout`]).
    pub(crate) layout: NodeLayout,
}

impl HighOrderMesh {
    /// Edges and faces of the underlying linear mesh, and which cells share them.
    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// Where each vertex, edge, face and cell's nodes sit in the global numbering.
    pub fn layout(&self) -> &NodeLayout {
        &self.layout
    }

    /// Removes the facets that were found from the cells rather than read from the file
    /// ([`crate::Element::is_undeclared_facet`]: curved like the others, their nodes stay in
    /// the cells, but the file written gets no elements it did not have) and returns how
    /// many.
    pub fn drop_undeclared_facets(&mut self) -> usize {
        let before = self.facets.len();
        let mut ids = self.facet_ids.iter();
        let mut kept_ids = Vec::with_capacity(before);
        self.facets.retain(|f| {
            let id = ids.next();
            let keep = !crate::undeclared::is_undeclared_entity(f.entity);
            if keep {
                kept_ids.extend(id);
            }
            keep
        });
        self.facet_ids = kept_ids;
        before - self.facets.len()
    }

    /// Places the straight-sided order-`order` nodes of `family` on every element of `mesh`.
    pub fn from_linear(
        mesh: &LinearMesh,
        order: usize,
        family: NodeFamily,
    ) -> Result<Self, MeshError> {
        mesh.validate()?;
        mesh.check_orientation()?;
        Self::straight_sided(mesh, order, family)
    }

    /// [`HighOrderMesh::from_linear`] without the orientation check, for a validated `mesh`
    /// (used by [`HighOrderMesh::from_cells`], which must accept tangled meshes read back
    /// for quality assessment).
    pub(crate) fn straight_sided(
        mesh: &LinearMesh,
        order: usize,
        family: NodeFamily,
    ) -> Result<Self, MeshError> {
        family.check_order(order)?;
        Self::straight_sided_on(mesh, Topology::new(mesh)?, order, family)
    }

    /// [`HighOrderMesh::straight_sided`] with the topology of `mesh` given.
    fn straight_sided_on(
        mesh: &LinearMesh,
        topology: Topology,
        order: usize,
        family: NodeFamily,
    ) -> Result<Self, MeshError> {
        family.check_order(order)?;
        let p = order;

        // Node numbering and counts.
        let num_vertices = mesh.vertices.len();
        let num_edges = topology.edges.len();
        let mut next = num_vertices + num_edges * (p - 1);
        let mut face_first_node = Vec::with_capacity(topology.faces.len() + 1);
        for face in topology.faces.rows() {
            face_first_node.push(next as u32);
            next += Shape::face_shape(face.len()).num_interior_nodes(p);
        }
        face_first_node.push(next as u32);
        let mut cell_first_node = Vec::with_capacity(mesh.cells.len() + 1);
        for cell in &mesh.cells {
            cell_first_node.push(next as u32);
            next += cell.kind.num_interior_nodes(p);
        }
        cell_first_node.push(next as u32);
        if next > u32::MAX as usize {
            return Err(MeshError::UnsupportedDimension(mesh.dim)); // unreachable in practice
        }
        let layout = NodeLayout {
            num_vertices,
            num_edges,
            face_first_node,
            cell_first_node,
        };

        let mut references: BTreeMap<Shape, Arc<ReferenceElement>> = BTreeMap::new();
        for shape in mesh.cells.iter().chain(&mesh.facets).map(|c| c.kind) {
            if let Entry::Vacant(slot) = references.entry(shape) {
                slot.insert(ReferenceElement::shared(shape, p, family)?);
            }
        }
        let corner_ids: Vec<(Shape, &[u32])> = mesh
            .cells
            .iter()
            .map(|c| (c.kind, c.vertices.as_slice()))
            .collect();
        let nodes = straight_positions(
            &mesh.vertices,
            &topology,
            &corner_ids,
            p,
            family,
            &references,
        );
        drop(corner_ids);
        debug_assert_eq!(nodes.len(), next);

        // Connectivity in canonical local order.
        let faces = FaceFrames::new(p, family);
        let cells = mesh
            .cells
            .par_iter()
            .enumerate()
            .map(|(c, cell)| {
                let shape = cell.kind;
                let reference = references[&shape].nodes();
                let cell_edges = topology.cell_edges.row(c);
                let cell_faces = topology.cell_faces.row(c);
                let v = &cell.vertices;
                let mut ids = Vec::with_capacity(reference.len());
                for entity in reference.entities() {
                    let id = match *entity {
                        NodeEntity::Vertex(i) => v[i] as usize,
                        NodeEntity::Edge { edge, index } => {
                            let [a, b] = shape.edges()[edge];
                            edge_node(&layout, p, cell_edges[edge] as usize, v[a] > v[b], index)
                        }
                        NodeEntity::Face { face, index } => {
                            let f = cell_faces[face] as usize;
                            let corners = shape.faces()[face];
                            let mut local = [0u32; 4];
                            for (l, &i) in local.iter_mut().zip(corners) {
                                *l = v[i];
                            }
                            let map = faces
                                .interior_map(&local[..corners.len()], topology.faces.row(f))
                                .ok_or(MeshError::MismatchedFace {
                                    what: "cell",
                                    index: c,
                                })?;
                            layout.face_first_node[f] as usize + map[index]
                        }
                        NodeEntity::Interior(index) => layout.cell_first_node[c] as usize + index,
                    };
                    ids.push(id as u32);
                }
                Ok(HighOrderElement {
                    kind: cell.kind,
                    nodes: ids,
                    entity: cell.entity,
                })
            })
            .collect::<Result<Vec<_>, MeshError>>()?;

        // Declared facets: find their edge (2D) or face (3D), then lay out their nodes. Only
        // the facets' own edges and faces are looked up.
        let mut wanted_edges: HashMap<[u32; 2], u32> = HashMap::new();
        let mut wanted_faces: HashMap<[u32; 4], u32> = HashMap::new();
        for facet in &mesh.facets {
            let v = &facet.vertices;
            for &[a, b] in facet.kind.edges() {
                let key = [v[a].min(v[b]), v[a].max(v[b])];
                wanted_edges.insert(key, u32::MAX);
            }
            if mesh.dim == 3 {
                wanted_faces.insert(face_key(v), u32::MAX);
            }
        }
        if !wanted_edges.is_empty() {
            for (i, e) in topology.edges.iter().enumerate() {
                if let Some(id) = wanted_edges.get_mut(e) {
                    *id = i as u32;
                }
            }
        }
        if !wanted_faces.is_empty() {
            for (i, f) in topology.faces.rows().enumerate() {
                if let Some(id) = wanted_faces.get_mut(&face_key(f)) {
                    *id = i as u32;
                }
            }
        }
        let found = |id: Option<&u32>| id.copied().filter(|&i| i != u32::MAX);
        let find_edge =
            |a: u32, b: u32| found(wanted_edges.get(&if a < b { [a, b] } else { [b, a] }));
        let mut facets = Vec::with_capacity(mesh.facets.len());
        let mut facet_ids = Vec::with_capacity(mesh.facets.len());
        for (k, facet) in mesh.facets.iter().enumerate() {
            let not_found = || MeshError::FacetNotInMesh {
                index: k,
                tag: mesh.facet_tag(k),
                vertices: facet.vertices.clone(),
                vertex_tags: facet
                    .vertices
                    .iter()
                    .map(|&v| mesh.vertex_tag(v as usize))
                    .collect(),
            };
            let shape = facet.kind;
            let v = &facet.vertices;
            let facet_id = if mesh.dim == 2 {
                find_edge(v[0], v[1]).ok_or_else(not_found)?
            } else {
                found(wanted_faces.get(&face_key(v))).ok_or_else(not_found)?
            };
            let reference = references[&shape].nodes();
            let mut ids = Vec::with_capacity(reference.len());
            for entity in reference.entities() {
                let id = match *entity {
                    NodeEntity::Vertex(i) => v[i] as usize,
                    NodeEntity::Edge { edge, index } => {
                        let [a, b] = shape.edges()[edge];
                        let e = find_edge(v[a], v[b]).ok_or_else(not_found)? as usize;
                        edge_node(&layout, p, e, v[a] > v[b], index)
                    }
                    NodeEntity::Interior(index) => {
                        let f = facet_id as usize;
                        let map = faces.interior_map(v, topology.faces.row(f)).ok_or(
                            MeshError::MismatchedFace {
                                what: "facet",
                                index: k,
                            },
                        )?;
                        layout.face_first_node[f] as usize + map[index]
                    }
                    NodeEntity::Face { .. } => unreachable!("facets are at most 2D"),
                };
                ids.push(id as u32);
            }
            facets.push(HighOrderElement {
                kind: facet.kind,
                nodes: ids,
                entity: facet.entity,
            });
            facet_ids.push(facet_id);
        }

        Ok(HighOrderMesh {
            dim: mesh.dim,
            order,
            family,
            nodes,
            cells,
            facets,
            facet_ids,
            physical_groups: mesh.physical_groups.clone(),
            entity_physicals: mesh.entity_physicals.clone(),
            topology,
            layout,
        })
    }

    /// The straight-sided mesh of another `order` (same node family) on this mesh's
    /// vertices, cells and facets: the vertices, edges, faces and cells keep their numbers,
    /// so a node's entity in one order's [`NodeLayout`] names the same entity in the other.
    /// The orders of a p-multigrid hierarchy are built this way. Curved edges are not
    /// carried over: only the vertex positions are used.
    pub fn straight_of_order(&self, order: usize) -> Result<HighOrderMesh, MeshError> {
        let vertices = &self.nodes[..self.layout.num_vertices.min(self.nodes.len())];
        self.straight_on(vertices, order, self.family)
    }

    /// The node positions of [`Self::straight_on`]`(vertices, order, family)` alone (no
    /// connectivity built): the straight-sided nodes a curved mesh's displacement is
    /// measured from.
    pub fn straight_positions_on(
        &self,
        vertices: &[[f64; 3]],
        order: usize,
        family: NodeFamily,
    ) -> Result<Vec<[f64; 3]>, MeshError> {
        if vertices.len() != self.layout.num_vertices {
            return Err(MeshError::VertexCount {
                expected: self.layout.num_vertices,
                found: vertices.len(),
            });
        }
        family.check_order(order)?;
        let mut references: BTreeMap<Shape, Arc<ReferenceElement>> = BTreeMap::new();
        let mut corner_ids = Vec::with_capacity(self.cells.len());
        for cell in &self.cells {
            let corners = cell.kind.num_vertices();
            if cell.nodes.len() < corners
                || cell.nodes[..corners]
                    .iter()
                    .any(|&v| v as usize >= vertices.len())
            {
                return Err(MeshError::VertexCount {
                    expected: self.layout.num_vertices,
                    found: vertices.len(),
                });
            }
            if let Entry::Vacant(slot) = references.entry(cell.kind) {
                slot.insert(ReferenceElement::shared(cell.kind, order, family)?);
            }
            corner_ids.push((cell.kind, &cell.nodes[..corners]));
        }
        Ok(straight_positions(
            vertices,
            &self.topology,
            &corner_ids,
            order,
            family,
            &references,
        ))
    }

    /// The straight-sided mesh of `order` and `family` on this mesh's cells and facets with
    /// the vertex positions `vertices` (one per vertex of this mesh, e.g. the linear mesh's
    /// before curving moved them), reusing this mesh's topology as
    /// [`Self::straight_of_order`] does.
    pub fn straight_on(
        &self,
        vertices: &[[f64; 3]],
        order: usize,
        family: NodeFamily,
    ) -> Result<HighOrderMesh, MeshError> {
        if vertices.len() != self.layout.num_vertices {
            return Err(MeshError::VertexCount {
                expected: self.layout.num_vertices,
                found: vertices.len(),
            });
        }
        let linear_element = |e: &HighOrderElement| -> Result<crate::Element, MeshError> {
            let corners = e.kind.num_vertices();
            Ok(crate::Element {
                kind: e.kind,
                vertices: e.nodes[..corners.min(e.nodes.len())].to_vec(),
                entity: e.entity,
            })
        };
        let linear = LinearMesh {
            dim: self.dim,
            vertices: vertices.to_vec(),
            cells: self
                .cells
                .iter()
                .map(linear_element)
                .collect::<Result<_, _>>()?,
            facets: self
                .facets
                .iter()
                .map(linear_element)
                .collect::<Result<_, _>>()?,
            physical_groups: self.physical_groups.clone(),
            entity_physicals: self.entity_physicals.clone(),
            vertex_tags: Vec::new(),
            cell_tags: Vec::new(),
            facet_tags: Vec::new(),
        };
        linear.validate()?;
        // Same vertices and cells: the same topology, not rebuilt (seconds at 1 M cells).
        Self::straight_sided_on(&linear, self.topology.clone(), order, family)
    }

    /// The length of the shortest mesh edge, vertex to vertex (straight); `None` without
    /// edges.
    pub fn shortest_edge(&self) -> Option<f64> {
        self.topology()
            .edges()
            .iter()
            .map(|&[a, b]| {
                let (x, y) = (self.nodes[a as usize], self.nodes[b as usize]);
                (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>().sqrt()
            })
            .min_by(f64::total_cmp)
    }

    /// Number of nodes the layout predicts: V + E(p−1) + Σ faces' interiors + Σ cells'
    /// interiors.
    pub fn expected_node_count(&self) -> usize {
        let p = self.order;
        let faces: usize = self
            .topology
            .faces
            .rows()
            .map(|f| Shape::face_shape(f.len()).num_interior_nodes(p))
            .sum();
        let cells: usize = self
            .cells
            .iter()
            .map(|c| c.kind.num_interior_nodes(p))
            .sum();
        self.layout.num_vertices + self.layout.num_edges * (p - 1) + faces + cells
    }

    /// The same mesh with its nodes moved to the reference positions of another `family`:
    /// each cell's polynomial map x(ξ) = Σ Φⱼ(ξ) xⱼ is evaluated at the new family's nodes,
    /// so the geometry is unchanged (exactly, up to rounding) and only the nodal
    /// representation changes. Formats that assume equispaced nodes (VTK Lagrange cells,
    /// Gmsh high-order elements) need `resampled(NodeFamily::Equispaced)`. Node numbering is
    /// family-independent (lattice order), so only coordinates change; a node shared by
    /// several cells is evaluated once, from the first cell that has it.
    pub fn resampled(&self, family: NodeFamily) -> Result<HighOrderMesh, MeshError> {
        let coords: Vec<f64> = self.nodes.iter().flatten().copied().collect();
        let moved = self.resampled_point_values(family, 3, &coords)?;
        let mut out = self.clone();
        out.family = family;
        out.nodes = moved.chunks_exact(3).map(|x| [x[0], x[1], x[2]]).collect();
        Ok(out)
    }

    /// The physical tags of an element of dimension `dim` on entity `entity`.
    pub fn physical_tags(&self, dim: usize, entity: i32) -> &[i32] {
        self.entity_physicals
            .get(&(dim, entity))
            .map(Vec::as_slice)
            .unwrap_or(&[])
    }
}

/// The straight-sided positions of the order-`p` nodes of `family` in [`NodeLayout`] order:
/// `vertices`, then each edge's, face's (canonical frame) and cell's interior nodes, cells
/// given by shape and corner vertex ids; `references` holds every cell shape's element.
fn straight_positions(
    vertices: &[[f64; 3]],
    topology: &Topology,
    cells: &[(Shape, &[u32])],
    p: usize,
    family: NodeFamily,
    references: &BTreeMap<Shape, Arc<ReferenceElement>>,
) -> Vec<[f64; 3]> {
    let line = family.interior_nodes(Shape::Line, p);
    let mut nodes = Vec::new();
    nodes.extend_from_slice(vertices);
    nodes.par_extend(topology.edges.par_iter().flat_map_iter(|&[a, b]| {
        let corners = [vertices[a as usize], vertices[b as usize]];
        line.iter()
            .map(move |(t, _)| straight_map(Shape::Line, &corners, *t))
    }));
    let tri_face = family.interior_nodes(Shape::Tri, p);
    let quad_face = family.interior_nodes(Shape::Quad, p);
    let face_rows: Vec<&[u32]> = topology.faces.rows().collect();
    nodes.par_extend(face_rows.par_iter().flat_map_iter(|face| {
        let corners: Vec<[f64; 3]> = face.iter().map(|&v| vertices[v as usize]).collect();
        let shape = Shape::face_shape(face.len());
        let set = if face.len() == 3 {
            &tri_face
        } else {
            &quad_face
        };
        set.iter()
            .map(move |(xi, _)| straight_map(shape, &corners, *xi))
    }));
    nodes.par_extend(cells.par_iter().flat_map_iter(|&(shape, ids)| {
        let reference = references[&shape].nodes();
        let corners: Vec<[f64; 3]> = ids.iter().map(|&v| vertices[v as usize]).collect();
        reference
            .points()
            .iter()
            .zip(reference.entities())
            .filter(|(_, entity)| matches!(entity, NodeEntity::Interior(_)))
            .map(move |(xi, _)| straight_map(shape, &corners, *xi))
    }));
    nodes
}

/// Global id of the `index`-th interior node of edge `e` as seen from an element whose local
/// edge runs against the canonical direction when `reversed`.
fn edge_node(layout: &NodeLayout, p: usize, e: usize, reversed: bool, index: usize) -> usize {
    let k = if reversed { p - 2 - index } else { index };
    layout.edge_first_node(e, p) + k
}

/// The straight-sided map x(ξ) = Σ Nᵢ(ξ) xᵢ of a shape with corner coordinates `corners`.
pub(crate) fn straight_map(shape: Shape, corners: &[[f64; 3]], xi: [f64; 3]) -> [f64; 3] {
    let (n, len) = shape.vertex_shape_functions(xi);
    let mut x = [0.0; 3];
    for (ni, c) in n[..len].iter().zip(corners) {
        for d in 0..3 {
            x[d] += ni * c[d];
        }
    }
    x
}

/// Maps between a face's interior nodes seen in a local frame and in its canonical frame,
/// one per orientation (a permutation of the face's vertices), all computed up front so
/// that cells are laid out in parallel.
struct FaceFrames {
    /// Indexed by [`FaceFrames::orientation`]; None for permutations that are no
    /// orientation (a quadrilateral's vertices out of cyclic order).
    tri: Vec<Option<Vec<usize>>>,
    quad: Vec<Option<Vec<usize>>>,
}

impl FaceFrames {
    fn new(p: usize, family: NodeFamily) -> Self {
        let p = p as i64;
        let lattice = |s| -> Vec<[i64; 3]> {
            family
                .interior_nodes(s, p as usize)
                .into_iter()
                .map(|(_, l)| l)
                .collect()
        };
        let index = |l: &[[i64; 3]]| -> HashMap<[i64; 2], usize> {
            l.iter()
                .enumerate()
                .map(|(i, m)| ([m[0], m[1]], i))
                .collect()
        };
        let (tri_lattice, quad_lattice) = (lattice(Shape::Tri), lattice(Shape::Quad));
        let (tri_index, quad_index) = (index(&tri_lattice), index(&quad_lattice));
        // sigma[r]: position in the canonical frame of local vertex r.
        let tri_map = |sigma: &[u8]| -> Option<Vec<usize>> {
            tri_lattice
                .iter()
                .map(|l| {
                    // Barycentric lattice coordinates over the local vertices, permuted.
                    let local_bary = [p - l[0] - l[1], l[0], l[1]];
                    let mut bary = [0; 3];
                    for r in 0..3 {
                        bary[sigma[r] as usize] = local_bary[r];
                    }
                    tri_index.get(&[bary[1], bary[2]]).copied()
                })
                .collect()
        };
        let quad_map = |sigma: &[u8]| -> Option<Vec<usize>> {
            let corner = [[0, 0], [p, 0], [p, p], [0, p]];
            let local_of = |canon_pos: u8| {
                sigma
                    .iter()
                    .position(|&s| s == canon_pos)
                    .map(|r| corner[r])
            };
            let (o, a, b) = (local_of(0)?, local_of(1)?, local_of(3)?);
            quad_lattice
                .iter()
                .map(|l| {
                    let d = [l[0] - o[0], l[1] - o[1]];
                    let i = (d[0] * (a[0] - o[0]) + d[1] * (a[1] - o[1])) / p;
                    let j = (d[0] * (b[0] - o[0]) + d[1] * (b[1] - o[1])) / p;
                    quad_index.get(&[i, j]).copied()
                })
                .collect()
        };
        let all = |n: usize, map: &dyn Fn(&[u8]) -> Option<Vec<usize>>| {
            (0..n.pow(n as u32))
                .map(|code| {
                    let sigma: Vec<u8> =
                        (0..n).map(|r| (code / n.pow(r as u32) % n) as u8).collect();
                    let mut seen = sigma.clone();
                    seen.sort_unstable();
                    seen.dedup();
                    (seen.len() == n).then(|| map(&sigma)).flatten()
                })
                .collect()
        };
        FaceFrames {
            tri: all(3, &tri_map),
            quad: all(4, &quad_map),
        }
    }

    /// For a face whose vertices are `local` in a local frame (origin `local[0]`, ξ towards
    /// `local[1]`, η towards the last) and `canonical` in the canonical frame, entry k is the
    /// canonical interior index of the local interior node k. None when the two are not
    /// the same face in some orientation.
    fn interior_map(&self, local: &[u32], canonical: &[u32]) -> Option<&[usize]> {
        let n = local.len();
        if canonical.len() != n {
            return None;
        }
        let mut code = 0;
        for (r, v) in local.iter().enumerate() {
            code += canonical.iter().position(|c| c == v)? * n.pow(r as u32);
        }
        let table = if n == 3 { &self.tri } else { &self.quad };
        table.get(code)?.as_deref()
    }
}

#[cfg(test)]
#[path = "tests/high_order.rs"]
mod tests;
