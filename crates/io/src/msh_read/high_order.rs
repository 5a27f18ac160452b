//! The high-order reader ([`read_high_order_msh`], [`parse_high_order_msh`]): complete
//! Lagrange elements of one order, their nodes renumbered from Gmsh's order into hocurve's
//! and assembled into a [`HighOrderMesh`], with errors that name the file's elements.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use hocurve_mesh::{Element, HighOrderElement, HighOrderMesh, MeshError, PhysicalGroup, Shape};
use hocurve_nodes::NodeFamily;

use super::failure::{fail, R};
use super::parser::{take_dim, ElementRecord, Parser};
use super::physicals::physical_groups;
use crate::error::{IoError, Location};
use crate::ordering::gmsh_permutation;

/// Reads a Gmsh mesh of complete Lagrange elements of any order (MSH 4.1 or 2.2, ASCII or
/// binary, as written by [`crate::write_msh`] or by Gmsh) for quality assessment.
///
/// - Elements: lines, triangles, quadrilaterals, tetrahedra, hexahedra and prisms, complete
///   (Gmsh types `MSH_LIN_2` … `MSH_LIN_11`, `MSH_TRI_3` … `MSH_TRI_66`, `MSH_QUA_4` …
///   `MSH_QUA_121`, `MSH_TET_4` … `MSH_TET_286`, `MSH_HEX_8` … `MSH_HEX_1000`, `MSH_PRI_6` …
///   `MSH_PRI_550`: orders 1 to 10, 9 for hexahedra and prisms), their nodes renumbered
///   from Gmsh's order into hocurve's canonical order ([`crate::ordering`]) on
///   [`NodeFamily::Equispaced`] reference nodes.
/// - Cells: the elements of the top dimension, 3 if there are volume elements, else 2 (2D
///   meshes are expected in the plane z = 0). Facets: the elements one dimension lower
///   whose corners are a face (3D) or edge (2D) of the cells; the others, and all
///   lower-dimensional elements and points, are ignored (a [`HighOrderMesh`] holds only
///   cells and their facets).
/// - Errors, naming the file and the line (byte in binary files) or element: elements of
///   different orders, incomplete (serendipity) elements such as Gmsh types 16 (8-node
///   quadrilateral), 17 (20-node hexahedron) and 18 (15-node prism), pyramids, unknown
///   types, missing nodes, elements that do not share their edge and face nodes.
///
/// Nodes are renumbered as by [`HighOrderMesh::from_cells`] (vertices first; nodes no cell
/// uses are dropped); cells and facets keep their order in the file.
pub fn read_high_order_msh(path: &Path) -> Result<HighOrderMesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    parse_high_order_msh(&bytes, path)
}

/// [`read_high_order_msh`] from bytes already in memory; `path` only names the file in
/// errors.
pub fn parse_high_order_msh(bytes: &[u8], path: &Path) -> Result<HighOrderMesh, IoError> {
    let malformed = |location: Location, message: String| IoError::Malformed {
        path: path.to_path_buf(),
        location,
        message,
    };
    let mut parser = Parser::new(bytes, true);
    let raw = parser
        .read_sections()
        .and_then(|()| parser.finish_high_order())
        .map_err(|e| malformed(e.location, e.message))?;
    let p = raw.order;
    let mut permutations: HashMap<Shape, Vec<usize>> = HashMap::new();
    let mut canonical = |list: &[Element]| -> Result<Vec<HighOrderElement>, MeshError> {
        list.iter()
            .map(|e| {
                let perm = match permutations.entry(e.kind) {
                    std::collections::hash_map::Entry::Occupied(o) => o.into_mut(),
                    std::collections::hash_map::Entry::Vacant(v) => {
                        v.insert(gmsh_permutation(e.kind, p))
                    }
                };
                let mut nodes = vec![0; e.vertices.len()];
                for (&k, &n) in perm.iter().zip(&e.vertices) {
                    nodes[k] = n;
                }
                Ok(HighOrderElement {
                    kind: e.kind,
                    nodes,
                    entity: e.entity,
                })
            })
            .collect()
    };
    let as_mesh_error = |source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    };
    let cells = canonical(&raw.cells).map_err(as_mesh_error)?;
    let facets = canonical(&raw.facets).map_err(as_mesh_error)?;
    let built = HighOrderMesh::from_cells(
        raw.dim,
        p,
        NodeFamily::Equispaced,
        &raw.nodes,
        &cells,
        &facets,
    );
    let mut mesh = built.map_err(|source| {
        // Name the element and nodes as the file does.
        let node_tag = |i: usize| raw.node_tags.get(i).copied().unwrap_or(i as u64);
        let records = |what: &str| {
            if what == "cell" {
                &raw.cell_records
            } else {
                &raw.facet_records
            }
        };
        match source {
            MeshError::NonConformingNode {
                what,
                index,
                node,
                other,
                ..
            } => match records(what).get(index) {
                Some(r) => malformed(
                    r.location,
                    format!(
                        "element {} has node {} where a neighbouring element has node {} at a \
                         different position: the elements do not share their edge or face nodes",
                        r.tag,
                        node_tag(node),
                        node_tag(other)
                    ),
                ),
                None => as_mesh_error(source),
            },
            // The check ran on renumbered corners: the element is named by its record,
            // not by the tags in `source`.
            MeshError::RepeatedVertex { what, index, .. } => match records(what).get(index) {
                Some(r) => malformed(
                    r.location,
                    format!("element {} uses a node twice (collapsed element)", r.tag),
                ),
                None => as_mesh_error(source),
            },
            other => as_mesh_error(other),
        }
    })?;
    mesh.physical_groups = raw.physical_groups;
    mesh.entity_physicals = raw.entity_physicals;
    Ok(mesh)
}

/// What the high-order reader collected, before renumbering.
struct GmshElements {
    dim: usize,
    order: usize,
    physical_groups: Vec<PhysicalGroup>,
    entity_physicals: BTreeMap<(usize, i32), Vec<i32>>,
    /// All nodes, in file order.
    nodes: Vec<[f64; 3]>,
    /// Their tags.
    node_tags: Vec<u64>,
    /// Elements with all their nodes (indices into `nodes`) in Gmsh's order.
    cells: Vec<Element>,
    cell_records: Vec<ElementRecord>,
    facets: Vec<Element>,
    facet_records: Vec<ElementRecord>,
}

impl Parser<'_> {
    /// The high-order reader's result: cells of the top dimension (3 if the file has
    /// volume elements, else 2), facets one dimension lower, all of one order, their nodes
    /// in Gmsh's order.
    fn finish_high_order(mut self) -> R<GmshElements> {
        let dim = self.cell_dimension(
            [3, 2],
            "the file has no surface or volume elements (hocurve meshes are 2D or 3D)",
        )?;
        let mut take = |d: usize| {
            (
                take_dim(&mut self.by_dim, d),
                take_dim(&mut self.element_records, d),
            )
        };
        let (cells, cell_records) = take(dim);
        let (facets, facet_records) = take(dim - 1);
        let Some(first) = cell_records.first().copied() else {
            return fail(Location::EndOfFile, "the file has no cells");
        };
        for r in cell_records.iter().chain(&facet_records) {
            if r.order != first.order {
                return fail(
                    r.location,
                    format!(
                        "mixed element orders: element {} is of order {} but element {} ({}) \
                         is of order {}; a hocurve mesh has a single order",
                        r.tag, r.order, first.tag, first.location, first.order
                    ),
                );
            }
        }
        Ok(GmshElements {
            dim,
            order: first.order,
            physical_groups: physical_groups(self.names, &self.entity_physicals),
            entity_physicals: self.entity_physicals,
            nodes: self.vertices,
            node_tags: self.node_tags,
            cells,
            cell_records,
            facets,
            facet_records,
        })
    }
}
