//! Edge splitting of simplex meshes: the repair of input cells that no curving can make
//! valid.
//!
//! A tetrahedron with two faces on one smooth curved surface (or a triangle with two edges
//! on one smooth curve) has det J = 0 along their common edge once both are curved onto the
//! geometry: both faces become tangent to the surface there, so the corner between them
//! opens to 180°. Splitting the opposite edge at its midpoint gives two cells with one such
//! face each, whose corner stays near the straight cell's.

use crate::linear::corner_jacobians;
use crate::{Element, LinearMesh, Shape};

impl LinearMesh {
    /// Splits each edge (a pair of vertex ids) at its midpoint: every triangle or
    /// tetrahedron holding both ends, cell or facet, becomes two with the new vertex in
    /// place of one end and of the other (orientation is kept: the new vertex lies on the
    /// segment). The first half keeps the element's position and tag, the second is appended
    /// with a new tag past the largest (as is the new vertex).
    /// Edges held by a quadrilateral, hexahedron or prism cannot be split conformingly and
    /// are skipped, as are edges that no longer exist (split by an earlier pair). Returns the
    /// new mesh and the number of edges split.
    pub fn split_edges(&self, edges: &[[u32; 2]]) -> (LinearMesh, usize) {
        let at_midpoints: Vec<([u32; 2], Option<[f64; 3]>)> =
            edges.iter().map(|&e| (e, None)).collect();
        self.split_edges_at(&at_midpoints)
    }

    /// [`split_edges`](Self::split_edges) with the new vertex of each edge at the given
    /// position (`None`: the midpoint) — a boundary edge's midpoint moved onto the surface
    /// the edge lies on. The caller checks that the position keeps the split cells valid.
    pub fn split_edges_at(&self, edges: &[([u32; 2], Option<[f64; 3]>)]) -> (LinearMesh, usize) {
        let mut splitter = EdgeSplitter::new(self);
        for &(edge, position) in edges {
            splitter.split(edge, position, |_, _, _| true);
        }
        (splitter.mesh, splitter.split)
    }

    /// [`split_edges_at`](Self::split_edges_at), each split kept only if the mesh stays the
    /// right way round: the same as splitting the edges one at a time and keeping each result
    /// that passes [`check_orientation`](LinearMesh::check_orientation), without a pass over
    /// the whole mesh per edge — in 3D, on a mesh that passes it, only the cells a split makes
    /// can fail (every corner Jacobian positive), so only those are checked.
    pub fn split_edges_keeping_orientation(
        &self,
        edges: &[([u32; 2], Option<[f64; 3]>)],
    ) -> (LinearMesh, usize) {
        if self.dim != 3 || self.check_orientation().is_err() {
            // (2D orientation is relative to the first cell, and a planar check rides
            // along: the whole check after each split.)
            let mut mesh = self.clone();
            let mut count = 0;
            for edge in edges {
                let (next, n) = mesh.split_edges_at(std::slice::from_ref(edge));
                if n > 0 && next.check_orientation().is_ok() {
                    mesh = next;
                    count += n;
                }
            }
            return (mesh, count);
        }
        let mut splitter = EdgeSplitter::new(self);
        for &(edge, position) in edges {
            splitter.split(edge, position, |mesh, cells, point| {
                let m = mesh.vertices.len() as u32;
                cells.iter().all(|(kind, vertices)| {
                    let physical: Vec<[f64; 3]> = vertices
                        .iter()
                        .map(|&v| {
                            if v == m {
                                point
                            } else {
                                mesh.vertices[v as usize]
                            }
                        })
                        .collect();
                    corner_jacobians(*kind, &physical)
                        .iter()
                        .all(|&j| j > 0.0 && !j.is_nan())
                })
            });
        }
        (splitter.mesh, splitter.split)
    }

    /// Splits each listed quadrilateral (cell index, corner 0..4) into two triangles along
    /// the diagonal from that corner: (c, c+1, c+2) keeps the cell's position and tag,
    /// (c, c+2, c+3) is appended with a new tag past the largest. Curved, a quadrilateral
    /// whose two edges at a corner lie on one smooth curve opens that corner to 180° (det J
    /// = 0 there); each triangle keeps one of those edges. The diagonal is inside the cell,
    /// so the mesh stays conforming. Entries that are not quadrilaterals are skipped; returns
    /// the new mesh and the number of cells split.
    pub fn split_quadrilaterals(&self, corners: &[(usize, usize)]) -> (LinearMesh, usize) {
        let mut mesh = self.clone();
        let mut added = Vec::new();
        for &(cell, corner) in corners {
            let Some(e) = mesh.cells.get_mut(cell) else {
                continue;
            };
            if e.kind != Shape::Quad || e.vertices.len() != 4 {
                continue;
            }
            let v = |k: usize| e.vertices[(corner + k) % 4];
            let (first, second) = (vec![v(0), v(1), v(2)], vec![v(0), v(2), v(3)]);
            e.kind = Shape::Tri;
            e.vertices = first;
            added.push(Element {
                kind: Shape::Tri,
                vertices: second,
                entity: e.entity,
            });
        }
        let count = added.len() as u64;
        if !mesh.cell_tags.is_empty() {
            let next = mesh
                .cell_tags
                .iter()
                .chain(&mesh.facet_tags)
                .max()
                .map_or(1, |t| t + 1);
            mesh.cell_tags.extend(next..next + count);
        }
        mesh.cells.extend(added);
        (mesh, count as usize)
    }
}

/// A mesh whose edges are split one after another, with which cells and facets hold each
/// vertex (ascending) kept up to date: finding an edge's holders by scanning every element
/// made the splitting of many edges of a large mesh quadratic.
struct EdgeSplitter {
    mesh: LinearMesh,
    incidence: [Vec<Vec<usize>>; 2],
    next_vertex_tag: u64,
    next_element_tag: u64,
    split: usize,
}

impl EdgeSplitter {
    fn new(mesh: &LinearMesh) -> Self {
        let n = mesh.vertices.len();
        // New vertices and cells get tags past the file's largest; cells and facets share
        // Gmsh's element numbering, so new tags follow both.
        Self {
            incidence: [incidence_of(&mesh.cells, n), incidence_of(&mesh.facets, n)],
            next_vertex_tag: mesh.vertex_tags.iter().max().map_or(1, |t| t + 1),
            next_element_tag: mesh
                .cell_tags
                .iter()
                .chain(&mesh.facet_tags)
                .max()
                .map_or(1, |t| t + 1),
            mesh: mesh.clone(),
            split: 0,
        }
    }

    /// Splits the edge `a`–`b` at `position` (`None`: its midpoint) when simplices hold it
    /// and `keep` takes the cells the split would make (shape and vertices, the new vertex
    /// numbered `mesh.vertices.len()`, at the point given). Returns whether it split.
    fn split(
        &mut self,
        [a, b]: [u32; 2],
        position: Option<[f64; 3]>,
        keep: impl Fn(&LinearMesh, &[(Shape, Vec<u32>)], [f64; 3]) -> bool,
    ) -> bool {
        let mesh = &mut self.mesh;
        let incidence = &mut self.incidence;
        let holders = [0, 1].map(|k| common(&incidence[k], a, b));
        let lists = [&mesh.cells, &mesh.facets];
        let any = holders.iter().any(|h| !h.is_empty());
        let simplices_only = (0..2).all(|k| {
            holders[k]
                .iter()
                .all(|&i| matches!(lists[k][i].kind, Shape::Tri | Shape::Tet | Shape::Line))
        });
        if a == b || !any || !simplices_only {
            return false;
        }
        let (pa, pb) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
        let point = position.unwrap_or([
            0.5 * (pa[0] + pb[0]),
            0.5 * (pa[1] + pb[1]),
            0.5 * (pa[2] + pb[2]),
        ]);
        let m = mesh.vertices.len() as u32;
        let replaced = |vertices: &[u32], from: u32| -> Vec<u32> {
            vertices
                .iter()
                .map(|&v| if v == from { m } else { v })
                .collect()
        };
        let made: Vec<(Shape, Vec<u32>)> = holders[0]
            .iter()
            .flat_map(|&i| {
                let cell = &mesh.cells[i];
                [
                    (cell.kind, replaced(&cell.vertices, b)),
                    (cell.kind, replaced(&cell.vertices, a)),
                ]
            })
            .collect();
        if !keep(mesh, &made, point) {
            return false;
        }
        mesh.vertices.push(point);
        let mut added = [0u64; 2];
        for (k, list) in [&mut mesh.cells, &mut mesh.facets].into_iter().enumerate() {
            let inc = &mut incidence[k];
            inc.push(Vec::new());
            let before = list.len();
            for &i in &holders[k] {
                let mut other = list[i].clone();
                other.vertices = replaced(&other.vertices, a);
                list[i].vertices = replaced(&list[i].vertices, b);
                inc[b as usize].retain(|&x| x != i);
                inc[m as usize].push(i);
                list.push(other);
            }
            for (j, e) in list.iter().enumerate().skip(before) {
                for &v in &e.vertices {
                    if inc[v as usize].last() != Some(&j) {
                        inc[v as usize].push(j);
                    }
                }
            }
            added[k] = (list.len() - before) as u64;
        }
        if !mesh.vertex_tags.is_empty() {
            mesh.vertex_tags.push(self.next_vertex_tag);
            self.next_vertex_tag += 1;
        }
        for (tags, added) in [
            (&mut mesh.cell_tags, added[0]),
            (&mut mesh.facet_tags, added[1]),
        ] {
            if !tags.is_empty() {
                tags.extend(self.next_element_tag..self.next_element_tag + added);
                self.next_element_tag += added;
            }
        }
        self.split += 1;
        true
    }
}

/// For every vertex of `count`, the ascending indices of the elements holding it.
fn incidence_of(elements: &[Element], count: usize) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); count];
    for (i, e) in elements.iter().enumerate() {
        for &v in &e.vertices {
            if let Some(list) = out.get_mut(v as usize) {
                if list.last() != Some(&i) {
                    list.push(i);
                }
            }
        }
    }
    out
}

/// The elements holding both `a` and `b` (none when either is not a vertex), ascending.
fn common(incidence: &[Vec<usize>], a: u32, b: u32) -> Vec<usize> {
    let (Some(x), Some(y)) = (incidence.get(a as usize), incidence.get(b as usize)) else {
        return Vec::new();
    };
    let (mut i, mut j, mut out) = (0, 0, Vec::new());
    while i < x.len() && j < y.len() {
        match x[i].cmp(&y[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                out.push(x[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out
}

#[cfg(test)]
#[path = "tests/split.rs"]
mod tests;
