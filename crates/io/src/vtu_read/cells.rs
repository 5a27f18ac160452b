//! Assembles the cells of all pieces: points, connectivity, cell types and orders, with
//! the points of each cell reordered; the top-dimension cells and their facets.

use std::collections::HashMap;

use hocurve_mesh::{HighOrderElement, Shape};
use hocurve_nodes::NodeFamily;

use crate::xml::XmlElement;

use super::cell_types::{cell_kind, vtk_order, CellKind};
use super::failure::{fail, Fail, R};
use super::file::VtkFile;

/// What the cells of a file give, ready for [`HighOrderMesh::from_cells`].
pub(super) struct Cells {
    pub(super) dim: usize,
    pub(super) order: usize,
    pub(super) points: Vec<[f64; 3]>,
    pub(super) cells: Vec<HighOrderElement>,
    /// File index (over all pieces) of each cell.
    pub(super) cell_ids: Vec<usize>,
    pub(super) facets: Vec<HighOrderElement>,
}

impl VtkFile<'_, '_> {
    pub(super) fn read_cells(&self) -> R<Cells> {
        let mut points: Vec<[f64; 3]> = Vec::new();
        // (file cell index, shape, order, points in canonical order)
        let mut elements: Vec<(usize, Shape, usize, Vec<u32>)> = Vec::new();
        let mut permutations: HashMap<(Shape, usize, bool), Vec<usize>> = HashMap::new();
        let mut cell_base = 0usize;
        let pieces: Vec<&XmlElement> = self.grid.children_named("Piece").collect();
        if pieces.is_empty() {
            return fail(self.grid, "<UnstructuredGrid> has no <Piece>");
        }
        for piece in pieces {
            let count = |name: &str| -> R<usize> {
                match piece.attribute(name).map(|v| v.trim().parse::<usize>()) {
                    Some(Ok(n)) => Ok(n),
                    Some(Err(_)) => fail(piece, format!("<Piece> {name} is not a count")),
                    None => fail(piece, format!("<Piece> has no {name}")),
                }
            };
            let num_points = count("NumberOfPoints")?;
            let num_cells = count("NumberOfCells")?;
            let point_base = points.len();
            let Some(point_array) = piece.child("Points").and_then(|p| p.child("DataArray")) else {
                return fail(piece, "<Piece> has no <Points> <DataArray>");
            };
            let components = point_array
                .attribute("NumberOfComponents")
                .map_or(Ok(1), |c| c.trim().parse::<usize>())
                .or_else(|_| fail(point_array, "NumberOfComponents is not a count"))?;
            if components != 3 {
                return fail(
                    point_array,
                    format!("points have {components} components, expected 3"),
                );
            }
            let coords = self.floats(point_array, num_points.saturating_mul(3))?;
            points.extend(coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));

            let Some(cells) = piece.child("Cells") else {
                return fail(piece, "<Piece> has no <Cells>");
            };
            let array = |name: &str| -> R<&XmlElement> {
                cells
                    .children_named("DataArray")
                    .find(|a| a.attribute("Name") == Some(name))
                    .map_or_else(
                        || fail(cells, format!("<Cells> has no DataArray named {name}")),
                        Ok,
                    )
            };
            let offsets_array = array("offsets")?;
            let mut offsets = self.integers(offsets_array, None)?;
            // Either the end of each cell, or (VTK ≥ 9 internal layout) a leading 0 too.
            if offsets.len() == num_cells + 1 && offsets.first() == Some(&0) {
                offsets.remove(0);
            }
            if offsets.len() != num_cells {
                return fail(
                    offsets_array,
                    format!("offsets has {} values for {num_cells} cells", offsets.len()),
                );
            }
            let types_array = array("types")?;
            let types = self.integers(types_array, Some(num_cells))?;
            let connectivity_array = array("connectivity")?;
            let total = offsets.last().copied().unwrap_or(0);
            let total = usize::try_from(total)
                .or_else(|_| fail(offsets_array, format!("negative offset {total}")))?;
            let connectivity = self.integers(connectivity_array, Some(total))?;
            let degrees = match piece.child("CellData").and_then(|d| {
                d.children_named("DataArray")
                    .find(|a| a.attribute("Name") == Some("HigherOrderDegrees"))
            }) {
                Some(a) => Some((a, self.integers(a, Some(num_cells.saturating_mul(3)))?)),
                None => None,
            };

            let mut start = 0usize;
            for (i, (&end, &t)) in offsets.iter().zip(&types).enumerate() {
                let id = cell_base + i;
                let end = match usize::try_from(end) {
                    Ok(e) if e >= start && e <= connectivity.len() => e,
                    _ => {
                        return fail(
                            offsets_array,
                            format!(
                                "offset {end} of cell {id} is out of order or beyond the {} \
                                 connectivity entries",
                                connectivity.len()
                            ),
                        )
                    }
                };
                let ids = &connectivity[start..end];
                start = end;
                let kind =
                    cell_kind(t).or_else(|m| fail(types_array, format!("cell {id}: {m}")))?;
                let (shape, order) = match kind {
                    CellKind::Point => continue,
                    CellKind::Fixed(shape, order) => (shape, order),
                    CellKind::Lagrange(shape) => {
                        let Some(order) = (1..=NodeFamily::Equispaced.max_order())
                            .find(|&p| shape.num_nodes(p) == ids.len())
                        else {
                            return fail(
                                connectivity_array,
                                format!(
                                    "Lagrange {} cell {id} has {} points, which is no complete \
                                     order (orders up to {} are supported)",
                                    shape.name(),
                                    ids.len(),
                                    NodeFamily::Equispaced.max_order()
                                ),
                            );
                        };
                        (shape, order)
                    }
                };
                if ids.len() != shape.num_nodes(order) {
                    return fail(
                        connectivity_array,
                        format!(
                            "cell {id} (type {t}) has {} points, expected {}",
                            ids.len(),
                            shape.num_nodes(order)
                        ),
                    );
                }
                if let (Some((array, d)), CellKind::Lagrange(_)) = (&degrees, kind) {
                    let given = &d[3 * i..3 * i + 3];
                    if given[..shape.dim()].iter().any(|&g| g != order as i64) {
                        return fail(
                            array,
                            format!(
                                "HigherOrderDegrees of cell {id} are {given:?}, but its {} \
                                 points make a complete order-{order} {}: only isotropic \
                                 complete cells are supported",
                                ids.len(),
                                shape.name()
                            ),
                        );
                    }
                }
                let old_hex = shape == Shape::Hex && order >= 2 && self.version < (2, 1);
                let perm = permutations
                    .entry((shape, order, old_hex))
                    .or_insert_with(|| vtk_order(shape, order, old_hex));
                let mut nodes = vec![0u32; ids.len()];
                for (&k, &v) in perm.iter().zip(ids) {
                    let global = usize::try_from(v)
                        .ok()
                        .filter(|&v| v < num_points)
                        .and_then(|v| u32::try_from(point_base + v).ok());
                    let Some(global) = global else {
                        return fail(
                            connectivity_array,
                            format!(
                                "cell {id} references point {v}, but the piece has {num_points} points"
                            ),
                        );
                    };
                    nodes[k] = global;
                }
                elements.push((id, shape, order, nodes));
            }
            cell_base += num_cells;
        }

        let dim = if elements.iter().any(|e| e.1.dim() == 3) {
            3
        } else if elements.iter().any(|e| e.1.dim() == 2) {
            2
        } else {
            return fail(
                self.root,
                "the file has no 2D or 3D cells (hocurve meshes are 2D or 3D)",
            );
        };
        let mut order = None;
        let mut out = Cells {
            dim,
            order: 1,
            points,
            cells: Vec::new(),
            cell_ids: Vec::new(),
            facets: Vec::new(),
        };
        for (id, shape, p, nodes) in elements {
            if shape.dim() + 1 < dim {
                continue;
            }
            match order {
                None => order = Some((p, id)),
                Some((q, first)) if q != p => {
                    return Err(Fail {
                        offset: Some(self.grid.offset),
                        message: format!(
                            "mixed element orders: cell {id} is of order {p} but cell {first} \
                             is of order {q}; a hocurve mesh has a single order"
                        ),
                    })
                }
                Some(_) => {}
            }
            let element = HighOrderElement {
                kind: shape,
                nodes,
                entity: 0,
            };
            if shape.dim() == dim {
                out.cells.push(element);
                out.cell_ids.push(id);
            } else {
                out.facets.push(element);
            }
        }
        out.order = order.map_or(1, |(p, _)| p);
        Ok(out)
    }
}
