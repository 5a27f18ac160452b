//! Unique edges and faces of a mesh, the cells around them, and the boundary.
//!
//! Every edge is stored once with its vertices sorted (the canonical direction runs from
//! the lower vertex id to the higher); every face of a 3D mesh once with a canonical vertex
//! order ([`canonical_face`]). Edge and face ids are given in order of first appearance
//! when scanning cells in order, so the numbering is deterministic.

use std::collections::HashMap;

use crate::{Jagged, LinearMesh, MeshError};

/// Marks a missing second cell of a boundary face.
pub const NO_CELL: u32 = u32::MAX;

/// The canonical vertex order of a face given by its vertex ids (counter-clockwise or
/// not): a triangle's vertices sorted ascending; a quadrilateral's starting at its lowest
/// vertex, followed by the lower of that vertex's two neighbours, then around the cycle.
/// Interior face nodes are laid out in this frame (origin first, ξ towards the second
/// vertex, η towards the last), so both cells sharing a face agree on them.
pub fn canonical_face(vertices: &[u32]) -> Vec<u32> {
    match vertices.len() {
        3 => {
            let mut v = vertices.to_vec();
            v.sort_unstable();
            v
        }
        n => {
            let start = (0..n).min_by_key(|&i| vertices[i]).unwrap_or(0);
            let next = vertices[(start + 1) % n];
            let prev = vertices[(start + n - 1) % n];
            if next < prev {
                (0..n).map(|k| vertices[(start + k) % n]).collect()
            } else {
                (0..n).map(|k| vertices[(start + n - k) % n]).collect()
            }
        }
    }
}

/// Key of a face in hash maps: its sorted vertex ids, padded.
pub(crate) fn face_key(vertices: &[u32]) -> [u32; 4] {
    let mut key = [u32::MAX; 4];
    key[..vertices.len()].copy_from_slice(vertices);
    key[..vertices.len()].sort_unstable();
    key
}

/// A multiplicative hasher for keys made of vertex ids (FxHash's mixing step): the default
/// SipHash cost more than everything else in building the topology of a large mesh. Ids are
/// given in order of first appearance, so the hash does not change the result.
#[derive(Default)]
struct VertexIdHasher(u64);

impl std::hash::Hasher for VertexIdHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(4) {
            let mut word = [0u8; 4];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u32(u32::from_le_bytes(word));
        }
    }

    fn write_u32(&mut self, value: u32) {
        self.0 = (self.0.rotate_left(5) ^ u64::from(value)).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn write_usize(&mut self, value: usize) {
        self.0 = (self.0.rotate_left(5) ^ value as u64).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
}

type VertexIdMap<K> = HashMap<K, u32, std::hash::BuildHasherDefault<VertexIdHasher>>;

/// Edges and faces of a mesh and their incidence with cells, read through accessors (u32
/// ids) so that the storage can change without its users.
#[derive(Debug, Clone, Default)]
pub struct Topology {
    /// Unique edges, vertices sorted ascending.
    pub(crate) edges: Vec<[u32; 2]>,
    /// Unique faces of a 3D mesh in canonical vertex order (empty in 2D, where the cells
    /// themselves are the faces).
    pub(crate) faces: Jagged<u32>,
    /// Global edge id of each local edge of each cell (local order of `Shape::edges`).
    pub(crate) cell_edges: Jagged<u32>,
    /// Global face id of each local face of each cell (local order of `Shape::faces`).
    pub(crate) cell_faces: Jagged<u32>,
    /// The cells on either side of each facet — faces in 3D, edges in 2D; the second is
    /// [`NO_CELL`] on the boundary.
    pub(crate) facet_cells: Vec<[u32; 2]>,
}

impl Topology {
    /// Builds the topology of a validated mesh. Fails if more than two cells share a facet.
    pub fn new(mesh: &LinearMesh) -> Result<Self, MeshError> {
        let mut topo = Topology::default();
        // Tetrahedral meshes have about 1.2 edges and 2 faces per cell.
        let cells = mesh.cells.len();
        let mut edge_ids: VertexIdMap<[u32; 2]> = VertexIdMap::default();
        edge_ids.reserve(cells + cells / 2);
        let mut face_ids: VertexIdMap<[u32; 4]> = VertexIdMap::default();
        if mesh.dim == 3 {
            face_ids.reserve(2 * cells + cells / 4);
        }
        let mut face_cells: Vec<[u32; 2]> = Vec::new();
        let mut edge_cells: Vec<[u32; 2]> = Vec::new();
        let mut overfull: Option<Vec<u32>> = None;
        let mut attach = |slots: &mut Vec<[u32; 2]>, id: u32, cell: u32, verts: &[u32]| {
            let s = &mut slots[id as usize];
            if s[0] == NO_CELL {
                s[0] = cell;
            } else if s[1] == NO_CELL {
                s[1] = cell;
            } else if overfull.is_none() {
                overfull = Some(verts.to_vec());
            }
        };
        for (c, cell) in mesh.cells.iter().enumerate() {
            let shape = cell.kind;
            let v = &cell.vertices;
            let mut row = Vec::with_capacity(shape.edges().len());
            for &[a, b] in shape.edges() {
                let key = if v[a] < v[b] {
                    [v[a], v[b]]
                } else {
                    [v[b], v[a]]
                };
                let next = topo.edges.len() as u32;
                let id = *edge_ids.entry(key).or_insert(next);
                if id == next {
                    topo.edges.push(key);
                    edge_cells.push([NO_CELL; 2]);
                }
                if mesh.dim == 2 {
                    attach(&mut edge_cells, id, c as u32, &key);
                }
                row.push(id);
            }
            topo.cell_edges.push_row(row);
            let mut row = Vec::with_capacity(shape.faces().len());
            for face in shape.faces() {
                let verts: Vec<u32> = face.iter().map(|&i| v[i]).collect();
                let key = face_key(&verts);
                let next = face_cells.len() as u32;
                let id = *face_ids.entry(key).or_insert(next);
                if id == next {
                    topo.faces.push_row(canonical_face(&verts));
                    face_cells.push([NO_CELL; 2]);
                }
                attach(&mut face_cells, id, c as u32, &verts);
                row.push(id);
            }
            topo.cell_faces.push_row(row);
        }
        if let Some(vertices) = overfull {
            let vertex_tags = vertices
                .iter()
                .map(|&v| mesh.vertex_tag(v as usize))
                .collect();
            return Err(MeshError::NonManifold {
                vertices,
                vertex_tags,
            });
        }
        topo.facet_cells = if mesh.dim == 2 {
            edge_cells
        } else {
            face_cells
        };
        Ok(topo)
    }

    /// The unique edges, vertices sorted ascending (edge id = position).
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// The unique faces of a 3D mesh, canonical vertex order (none in 2D).
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.faces.rows()
    }

    /// Number of unique faces (0 in 2D).
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// Vertices of face `f` in canonical order.
    pub fn face(&self, f: usize) -> &[u32] {
        self.faces.row(f)
    }

    /// Global edge ids of cell `c`'s edges, in the local order of `Shape::edges`.
    pub fn cell_edges(&self, c: usize) -> &[u32] {
        self.cell_edges.row(c)
    }

    /// Global face ids of cell `c`'s faces, in the local order of `Shape::faces` (3D).
    pub fn cell_faces(&self, c: usize) -> &[u32] {
        self.cell_faces.row(c)
    }

    /// The cells on either side of facet `f` (face in 3D, edge in 2D); the second is
    /// [`NO_CELL`] on the boundary.
    pub fn facet_cells(&self, f: usize) -> [u32; 2] {
        self.facet_cells[f]
    }

    /// Ids of the boundary facets (faces in 3D, edges in 2D): those with one cell.
    pub fn boundary_facets(&self) -> impl Iterator<Item = usize> + '_ {
        self.facet_cells
            .iter()
            .enumerate()
            .filter(|(_, c)| c[1] == NO_CELL)
            .map(|(i, _)| i)
    }

    /// The global edge with vertices `a`, `b` (either order), if it exists. Linear search:
    /// for tests and rare lookups only.
    pub fn find_edge(&self, a: u32, b: u32) -> Option<usize> {
        let key = if a < b { [a, b] } else { [b, a] };
        self.edges.iter().position(|&e| e == key)
    }
}

#[cfg(test)]
#[path = "tests/topology.rs"]
mod tests;
