//! Edge splitting of simplex meshes: the repair of input cells that no curving can make
//! valid.
//!
//! A tetrahedron with two faces on one smooth curved surface (or a triangle with two edges
//! on one smooth curve) has det J = 0 along their common edge once both are curved onto the
//! geometry: both faces become tangent to the surface there, so the corner between them
//! opens to 180°. Splitting the opposite edge at its midpoint gives two cells with one such
//! face each, whose corner stays near the straight cell's.

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
        let mut mesh = self.clone();
        let n = mesh.vertices.len();
        // Which cells and facets hold each vertex (ascending), kept up to date as edges
        // split: finding an edge's holders by scanning every element made the splitting of
        // many rim edges on a large mesh quadratic.
        let mut incidence = [incidence_of(&mesh.cells, n), incidence_of(&mesh.facets, n)];
        // New vertices and cells get tags past the file's largest; cells and facets share
        // Gmsh's element numbering, so new tags follow both.
        let mut next_vertex_tag = mesh.vertex_tags.iter().max().map_or(1, |t| t + 1);
        let mut next_element_tag = mesh
            .cell_tags
            .iter()
            .chain(&mesh.facet_tags)
            .max()
            .map_or(1, |t| t + 1);
        let mut split = 0;
        for &([a, b], position) in edges {
            let holders = [0, 1].map(|k| common(&incidence[k], a, b));
            let lists = [&mesh.cells, &mesh.facets];
            let any = holders.iter().any(|h| !h.is_empty());
            let simplices_only = (0..2).all(|k| {
                holders[k]
                    .iter()
                    .all(|&i| matches!(lists[k][i].kind, Shape::Tri | Shape::Tet | Shape::Line))
            });
            if a == b || !any || !simplices_only {
                continue;
            }
            let (pa, pb) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
            let m = mesh.vertices.len() as u32;
            mesh.vertices.push(position.unwrap_or([
                0.5 * (pa[0] + pb[0]),
                0.5 * (pa[1] + pb[1]),
                0.5 * (pa[2] + pb[2]),
            ]));
            let mut added = [0u64; 2];
            for (k, list) in [&mut mesh.cells, &mut mesh.facets].into_iter().enumerate() {
                let inc = &mut incidence[k];
                inc.push(Vec::new());
                let before = list.len();
                for &i in &holders[k] {
                    let mut other = list[i].clone();
                    for v in &mut list[i].vertices {
                        if *v == b {
                            *v = m;
                        }
                    }
                    for v in &mut other.vertices {
                        if *v == a {
                            *v = m;
                        }
                    }
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
                mesh.vertex_tags.push(next_vertex_tag);
                next_vertex_tag += 1;
            }
            for (tags, added) in [
                (&mut mesh.cell_tags, added[0]),
                (&mut mesh.facet_tags, added[1]),
            ] {
                if !tags.is_empty() {
                    tags.extend(next_element_tag..next_element_tag + added);
                    next_element_tag += added;
                }
            }
            split += 1;
        }
        (mesh, split)
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
