//! Unique edges and faces of a mesh, the cells around them, and the boundary.
//!
//! Every edge is stored once with its vertices sorted (the canonical direction runs from
//! the lower vertex id to the higher); every face of a 3D mesh once with a canonical vertex
//! order ([`canonical_face`]). Edge and face ids are given in order of first appearance
//! when scanning cells in order, so the numbering is deterministic.

use rayon::prelude::*;

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

/// Key of a face: its sorted vertex ids, padded.
pub(crate) fn face_key(vertices: &[u32]) -> [u32; 4] {
    let mut key = [u32::MAX; 4];
    key[..vertices.len()].copy_from_slice(vertices);
    key[..vertices.len()].sort_unstable();
    key
}

/// Marks a key met only once.
const NO_OCCURRENCE: u32 = u32::MAX;

/// Ids of keys numbered by first occurrence.
struct FirstAppearance {
    /// The id of each occurrence's key.
    id: Vec<u32>,
    /// Each id's first occurrence.
    first: Vec<u32>,
    /// Each id's second occurrence ([`NO_OCCURRENCE`] if none).
    second: Vec<u32>,
    /// The earliest third occurrence of any key (a facet of more than two cells).
    overfull: Option<u32>,
}

impl FirstAppearance {
    /// `keyed[o] = (key, o)` for occurrences o = 0, 1, …
    fn number<K: Ord + Copy + Send>(mut keyed: Vec<(K, u32)>) -> Self {
        let n = keyed.len();
        // Equal keys become runs, ordered by occurrence within.
        keyed.par_sort_unstable();
        // rep[o]: the first occurrence of o's key; second[o] for first occurrences.
        let mut rep = vec![0u32; n];
        let mut second_of = vec![NO_OCCURRENCE; n];
        let mut overfull: Option<u32> = None;
        let mut i = 0;
        while i < n {
            let mut j = i + 1;
            while j < n && keyed[j].0 == keyed[i].0 {
                j += 1;
            }
            let first = keyed[i].1;
            for &(_, o) in &keyed[i..j] {
                rep[o as usize] = first;
            }
            if j - i >= 2 {
                second_of[first as usize] = keyed[i + 1].1;
            }
            if j - i >= 3 {
                let third = keyed[i + 2].1;
                overfull = Some(overfull.map_or(third, |o| o.min(third)));
            }
            i = j;
        }
        drop(keyed);
        // In occurrence order, first occurrences take the next id; the others their first
        // occurrence's, numbered already (rep[o] < o). rep becomes the ids in place.
        let (mut first, mut second) = (Vec::new(), Vec::new());
        for o in 0..n {
            let r = rep[o] as usize;
            if r == o {
                rep[o] = first.len() as u32;
                first.push(o as u32);
                second.push(second_of[o]);
            } else {
                rep[o] = rep[r];
            }
        }
        FirstAppearance {
            id: rep,
            first,
            second,
            overfull,
        }
    }
}

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
    ///
    /// Every (cell, local edge) and (cell, local face) is an occurrence of a key (its sorted
    /// vertices); the occurrences are sorted by key in parallel, and each key's id is its
    /// rank by first occurrence — the numbering a scan of the cells in order would give,
    /// whatever the thread count.
    pub fn new(mesh: &LinearMesh) -> Result<Self, MeshError> {
        let cells = &mesh.cells;
        let offsets = |count: fn(&crate::Element) -> usize| {
            let mut offsets = Vec::with_capacity(cells.len() + 1);
            offsets.push(0usize);
            for cell in cells {
                offsets.push(offsets[offsets.len() - 1] + count(cell));
            }
            offsets
        };
        let edge_offsets = offsets(|cell| cell.kind.edges().len());
        let face_offsets = offsets(|cell| cell.kind.faces().len());
        let too_many = |n: usize| {
            u32::try_from(n).map_err(|_| MeshError::TooLarge {
                what: "cell edges or faces",
                count: n,
            })
        };
        too_many(edge_offsets[cells.len()])?;
        too_many(face_offsets[cells.len()])?;
        let edge_keys: Vec<(u64, u32)> = cells
            .par_iter()
            .zip(&edge_offsets[..cells.len()])
            .flat_map_iter(|(cell, &first)| {
                let v = &cell.vertices;
                cell.kind
                    .edges()
                    .iter()
                    .enumerate()
                    .map(move |(i, &[a, b])| {
                        let (lo, hi) = (v[a].min(v[b]), v[a].max(v[b]));
                        ((u64::from(lo) << 32) | u64::from(hi), (first + i) as u32)
                    })
            })
            .collect();
        let edges = FirstAppearance::number(edge_keys);
        let face_keys: Vec<([u32; 4], u32)> = cells
            .par_iter()
            .zip(&face_offsets[..cells.len()])
            .flat_map_iter(|(cell, &first)| {
                let v = &cell.vertices;
                cell.kind.faces().iter().enumerate().map(move |(i, face)| {
                    let verts: Vec<u32> = face.iter().map(|&k| v[k]).collect();
                    (face_key(&verts), (first + i) as u32)
                })
            })
            .collect();
        let faces = FirstAppearance::number(face_keys);
        // The cell and local index of an occurrence.
        let locate = |offsets: &[usize], occurrence: u32| {
            let o = occurrence as usize;
            let c = offsets.partition_point(|&s| s <= o) - 1;
            (c, o - offsets[c])
        };
        let facets = if mesh.dim == 2 {
            (&edges, &edge_offsets)
        } else {
            (&faces, &face_offsets)
        };
        if let Some(third) = facets.0.overfull {
            let (c, local) = locate(facets.1, third);
            let v = &cells[c].vertices;
            let vertices: Vec<u32> = if mesh.dim == 2 {
                let [a, b] = cells[c].kind.edges()[local];
                let key = [v[a].min(v[b]), v[a].max(v[b])];
                key.to_vec()
            } else {
                cells[c].kind.faces()[local].iter().map(|&k| v[k]).collect()
            };
            let vertex_tags = vertices
                .iter()
                .map(|&v| mesh.vertex_tag(v as usize))
                .collect();
            return Err(MeshError::NonManifold {
                vertices,
                vertex_tags,
            });
        }
        let unique_edges: Vec<[u32; 2]> = edges
            .first
            .par_iter()
            .map(|&o| {
                let (c, local) = locate(&edge_offsets, o);
                let v = &cells[c].vertices;
                let [a, b] = cells[c].kind.edges()[local];
                [v[a].min(v[b]), v[a].max(v[b])]
            })
            .collect();
        let unique_faces: Vec<Vec<u32>> = faces
            .first
            .par_iter()
            .map(|&o| {
                let (c, local) = locate(&face_offsets, o);
                let v = &cells[c].vertices;
                let verts: Vec<u32> = cells[c].kind.faces()[local].iter().map(|&k| v[k]).collect();
                canonical_face(&verts)
            })
            .collect();
        let mut face_rows = Jagged::new();
        for face in unique_faces {
            face_rows.push_row(face);
        }
        let facet_cells = facets
            .0
            .first
            .par_iter()
            .zip(&facets.0.second)
            .map(|(&first, &second)| {
                let cell = |o: u32| locate(facets.1, o).0 as u32;
                [
                    cell(first),
                    if second == NO_OCCURRENCE {
                        NO_CELL
                    } else {
                        cell(second)
                    },
                ]
            })
            .collect();
        Ok(Topology {
            edges: unique_edges,
            faces: face_rows,
            cell_edges: Jagged::from_parts(edge_offsets, edges.id),
            cell_faces: Jagged::from_parts(face_offsets, faces.id),
            facet_cells,
        })
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
