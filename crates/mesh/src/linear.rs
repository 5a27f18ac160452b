//! The linear (straight-sided) mesh as read from a file.

use std::collections::BTreeMap;

use crate::{MeshError, Shape};

/// One element of a linear mesh: a cell or a boundary facet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Element {
    /// Element type.
    pub kind: Shape,
    /// Vertex ids (0-based indices into [`LinearMesh::vertices`]), in Gmsh/VTK linear order.
    pub vertices: Vec<u32>,
    /// Tag of the geometric entity (Gmsh "elementary" tag) the element was meshed on.
    pub entity: i32,
}

/// A named physical group (Gmsh `$PhysicalNames`); `name` is empty when the file gave none.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct PhysicalGroup {
    /// Dimension of the group's entities.
    pub dim: usize,
    /// Physical tag.
    pub tag: i32,
    /// Name.
    pub name: String,
}

/// A straight-sided mesh: vertices, cells of the mesh dimension, and the facets of the next
/// lower dimension that the file declared (boundary curves in 2D, surfaces in 3D) with their
/// entity and physical tags.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinearMesh {
    /// Mesh dimension, 2 or 3.
    pub dim: usize,
    /// Vertex coordinates (z = 0 in 2D).
    pub vertices: Vec<[f64; 3]>,
    /// Cells (dimension `dim`).
    pub cells: Vec<Element>,
    /// Facets (dimension `dim − 1`) declared in the file, usually the boundary.
    pub facets: Vec<Element>,
    /// Physical groups, sorted by (dim, tag).
    pub physical_groups: Vec<PhysicalGroup>,
    /// Physical tags of each geometric entity, keyed by (dim, entity tag).
    pub entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
    /// The file's tag of each vertex (Gmsh node tags), for messages; empty: 1-based
    /// positions.
    pub vertex_tags: Vec<u64>,
    /// The file's tag of each cell (Gmsh element tags); empty: 1-based positions.
    pub cell_tags: Vec<u64>,
    /// The file's tag of each facet (Gmsh element tags, one numbering with the cells');
    /// empty: 1-based positions.
    pub facet_tags: Vec<u64>,
}

impl LinearMesh {
    /// Physical tags of a cell or facet of dimension `dim` on geometric entity `entity`.
    pub fn physical_tags(&self, dim: usize, entity: i32) -> &[i32] {
        self.entity_physicals
            .get(&(dim, entity))
            .map(Vec::as_slice)
            .unwrap_or(&[])
    }

    /// The file's tag of cell `index` (Gmsh element tag), for messages: from
    /// [`Self::cell_tags`], else the 1-based position.
    pub fn cell_tag(&self, index: usize) -> u64 {
        self.cell_tags
            .get(index)
            .copied()
            .unwrap_or(index as u64 + 1)
    }

    /// The file's tag of facet `index` (Gmsh element tag), for messages; see
    /// [`Self::cell_tag`].
    pub fn facet_tag(&self, index: usize) -> u64 {
        self.facet_tags
            .get(index)
            .copied()
            .unwrap_or(index as u64 + 1)
    }

    /// The file's tag of vertex `index` (Gmsh node tag), for messages; see
    /// [`Self::cell_tag`].
    pub fn vertex_tag(&self, index: usize) -> u64 {
        self.vertex_tags
            .get(index)
            .copied()
            .unwrap_or(index as u64 + 1)
    }

    /// The mesh without the vertices that no cell uses (a stray point, or the nodes of
    /// entities saved without elements), renumbered, and the tags of those left out.
    /// Unused vertices would get unknowns with no stiffness in the elastic solve.
    pub fn without_unused_vertices(&self) -> (LinearMesh, Vec<u64>) {
        let mut used = vec![false; self.vertices.len()];
        for cell in &self.cells {
            for &v in &cell.vertices {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
        }
        if used.iter().all(|&u| u) {
            return (self.clone(), Vec::new());
        }
        let mut new_id = vec![u32::MAX; self.vertices.len()];
        let mut mesh = LinearMesh {
            vertices: Vec::new(),
            vertex_tags: Vec::new(),
            ..self.clone()
        };
        let mut unused = Vec::new();
        for (v, &u) in used.iter().enumerate() {
            if u {
                new_id[v] = mesh.vertices.len() as u32;
                mesh.vertices.push(self.vertices[v]);
                if !self.vertex_tags.is_empty() {
                    mesh.vertex_tags.push(self.vertex_tag(v));
                }
            } else {
                unused.push(self.vertex_tag(v));
            }
        }
        // Facets on unused vertices belong to no cell: they are dropped with them (and
        // their tags with them).
        let kept: Vec<bool> = self
            .facets
            .iter()
            .map(|f| {
                f.vertices
                    .iter()
                    .all(|&v| used.get(v as usize) == Some(&true))
            })
            .collect();
        if !self.facet_tags.is_empty() {
            mesh.facet_tags = (0..self.facets.len())
                .filter(|&f| kept[f])
                .map(|f| self.facet_tag(f))
                .collect();
        }
        let mut keep = kept.iter();
        mesh.facets.retain(|_| keep.next() == Some(&true));
        for e in mesh.cells.iter_mut().chain(mesh.facets.iter_mut()) {
            for v in &mut e.vertices {
                *v = new_id[*v as usize];
            }
        }
        (mesh, unused)
    }

    /// The physical group with the given name, if any.
    pub fn physical_group(&self, name: &str) -> Option<&PhysicalGroup> {
        self.physical_groups.iter().find(|g| g.name == name)
    }

    /// Checks what the rest of hocurve relies on: a 2D or 3D mesh with cells of its
    /// dimension only, supported element types, vertex ids in range and not repeated within
    /// an element, facets one dimension lower.
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.dim != 2 && self.dim != 3 {
            return Err(MeshError::UnsupportedDimension(self.dim));
        }
        if self.cells.is_empty() {
            return Err(MeshError::NoCells { dim: self.dim });
        }
        let n = self.vertices.len();
        for (what, list, dim) in [
            ("cell", &self.cells, self.dim),
            ("facet", &self.facets, self.dim - 1),
        ] {
            let tag = |i: usize| {
                if what == "cell" {
                    self.cell_tag(i)
                } else {
                    self.facet_tag(i)
                }
            };
            for (i, e) in list.iter().enumerate() {
                if e.kind.dim() != dim {
                    return Err(MeshError::WrongDimension {
                        what,
                        index: i,
                        tag: tag(i),
                        kind: e.kind,
                        expected: dim,
                    });
                }
                if e.vertices.len() != e.kind.num_vertices() {
                    return Err(MeshError::WrongVertexCount {
                        what,
                        index: i,
                        tag: tag(i),
                        kind: e.kind,
                        found: e.vertices.len(),
                    });
                }
                for (k, &v) in e.vertices.iter().enumerate() {
                    if v as usize >= n {
                        return Err(MeshError::VertexOutOfRange {
                            what,
                            index: i,
                            tag: tag(i),
                            vertex: v as usize,
                            count: n,
                        });
                    }
                    if e.vertices[..k].contains(&v) {
                        return Err(MeshError::RepeatedVertex {
                            what,
                            index: i,
                            tag: tag(i),
                            vertex: v as usize,
                            vertex_tag: self.vertex_tag(v as usize),
                        });
                    }
                }
            }
        }
        for (i, v) in self.vertices.iter().enumerate() {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(MeshError::NonFiniteVertex {
                    index: i,
                    tag: self.vertex_tag(i),
                });
            }
        }
        Ok(())
    }

    /// Rejects a 2D mesh whose cells do not lie in one plane z = const (a surface mesh of a
    /// CAD part in 3D): the 2D pipeline works in the xy-plane, z riding along unchanged.
    pub fn check_planar(&self) -> Result<(), MeshError> {
        if self.dim != 2 {
            return Ok(());
        }
        // The 2D pipeline works in the xy-plane; z rides along unchanged.
        let used = self.cells.iter().flat_map(|c| c.vertices.iter().copied());
        let (mut low, mut high) = ((f64::INFINITY, 0), (f64::NEG_INFINITY, 0));
        for v in used {
            let z = self.vertices[v as usize][2];
            if z < low.0 {
                low = (z, v);
            }
            if z > high.0 {
                high = (z, v);
            }
        }
        let extent = |d: usize| {
            let (lo, hi) = self
                .vertices
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x[d]), hi.max(x[d]))
                });
            hi - lo
        };
        let size = extent(0).hypot(extent(1)).hypot(extent(2));
        if high.0 - low.0 > 1e-9 * size {
            return Err(MeshError::NotPlanar {
                low: low.0,
                low_tag: self.vertex_tag(low.1 as usize),
                high: high.0,
                high_tag: self.vertex_tag(high.1 as usize),
            });
        }
        Ok(())
    }

    /// Rejects inverted or degenerate cells: in 3D, a cell whose Jacobian determinant at
    /// any vertex is not positive; in 2D (where a mesh may be numbered clockwise or
    /// counter-clockwise in the xy-plane), a degenerate cell, or one whose orientation
    /// differs from the first cell's ([`MeshError::MixedOrientation`]). At a vertex of every supported shape the Jacobian is
    /// the determinant of the edge vectors leaving that vertex (relative to the reference
    /// element's), so this is exact for straight-sided cells; it assumes [`Self::validate`]
    /// passed.
    pub fn check_orientation(&self) -> Result<(), MeshError> {
        self.check_planar()?;
        let mut reference_sign = 0.0;
        let turn = |sign: f64| {
            if sign > 0.0 {
                "counter-clockwise"
            } else {
                "clockwise"
            }
        };
        for (c, cell) in self.cells.iter().enumerate() {
            let shape = cell.kind;
            let physical: Vec<[f64; 3]> = cell
                .vertices
                .iter()
                .map(|&v| self.vertices[v as usize])
                .collect();
            let jacobians = corner_jacobians(shape, &physical);
            // A whole 2D cell turning the other way is numbered differently, not inverted.
            if self.dim == 2
                && reference_sign != 0.0
                && jacobians.iter().all(|&j| j * reference_sign < 0.0)
            {
                return Err(MeshError::MixedOrientation {
                    index: c,
                    tag: self.cell_tag(c),
                    first_tag: self.cell_tag(0),
                    this: turn(-reference_sign),
                    first: turn(reference_sign),
                });
            }
            for (vertex, jacobian) in jacobians.into_iter().enumerate() {
                let sign = if self.dim == 2 {
                    if reference_sign == 0.0 {
                        reference_sign = jacobian.signum();
                    }
                    reference_sign
                } else {
                    1.0
                };
                if jacobian * sign <= 0.0 || jacobian.is_nan() {
                    return Err(MeshError::InvertedCell {
                        index: c,
                        tag: self.cell_tag(c),
                        vertex_tag: self.vertex_tag(cell.vertices[vertex] as usize),
                        vertex,
                        jacobian,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Jacobian determinant of the straight map at each vertex, divided by the reference
/// element's: the determinant of the edge vectors leaving the vertex (2D: the z component
/// of their cross product).
pub(crate) fn corner_jacobians(shape: hocurve_nodes::Shape, x: &[[f64; 3]]) -> Vec<f64> {
    let reference = shape.vertices();
    let edges = shape.edges();
    let dim = shape.dim();
    (0..reference.len())
        .map(|v| {
            let neighbours: Vec<usize> = edges
                .iter()
                .filter_map(|&[a, b]| match (a == v, b == v) {
                    (true, _) => Some(b),
                    (_, true) => Some(a),
                    _ => None,
                })
                .collect();
            let vectors = |pts: &[[f64; 3]]| -> Vec<[f64; 3]> {
                neighbours
                    .iter()
                    .map(|&n| {
                        [
                            pts[n][0] - pts[v][0],
                            pts[n][1] - pts[v][1],
                            pts[n][2] - pts[v][2],
                        ]
                    })
                    .collect()
            };
            let det = |e: &[[f64; 3]]| {
                if dim == 2 {
                    e[0][0] * e[1][1] - e[0][1] * e[1][0]
                } else {
                    e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1])
                        - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0])
                        + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])
                }
            };
            det(&vectors(x)) / det(&vectors(reference))
        })
        .collect()
}

#[cfg(test)]
#[path = "tests/linear.rs"]
mod tests;
