//! VTK cell types: which shape and order each one is, and the permutation of its points
//! into hocurve's canonical order.

use hocurve_nodes::Shape;

use crate::ordering::vtk_permutation;

/// How a cell type's points map to a shape and order.
#[derive(Debug, Clone, Copy)]
pub(super) enum CellKind {
    /// A shape of fixed order (linear and quadratic types).
    Fixed(Shape, usize),
    /// A Lagrange cell: the order follows from the point count.
    Lagrange(Shape),
    /// Vertex cells: ignored.
    Point,
}

pub(super) fn cell_kind(t: i64) -> Result<CellKind, String> {
    Ok(match t {
        1 | 2 => CellKind::Point,
        3 => CellKind::Fixed(Shape::Line, 1),
        5 => CellKind::Fixed(Shape::Tri, 1),
        9 => CellKind::Fixed(Shape::Quad, 1),
        10 => CellKind::Fixed(Shape::Tet, 1),
        12 => CellKind::Fixed(Shape::Hex, 1),
        13 => CellKind::Fixed(Shape::Prism, 1),
        21 => CellKind::Fixed(Shape::Line, 2),
        22 => CellKind::Fixed(Shape::Tri, 2),
        24 => CellKind::Fixed(Shape::Tet, 2),
        28 => CellKind::Fixed(Shape::Quad, 2),
        29 => CellKind::Fixed(Shape::Hex, 2),
        32 => CellKind::Fixed(Shape::Prism, 2),
        68 => CellKind::Lagrange(Shape::Line),
        69 => CellKind::Lagrange(Shape::Tri),
        70 => CellKind::Lagrange(Shape::Quad),
        71 => CellKind::Lagrange(Shape::Tet),
        72 => CellKind::Lagrange(Shape::Hex),
        73 => CellKind::Lagrange(Shape::Prism),
        23 | 25 | 26 | 30 | 31 | 33 => {
            let name = match t {
                23 => "VTK_QUADRATIC_QUAD, 8 points",
                25 => "VTK_QUADRATIC_HEXAHEDRON, 20 points",
                26 => "VTK_QUADRATIC_WEDGE, 15 points",
                30 => "VTK_QUADRATIC_LINEAR_QUAD, 6 points",
                31 => "VTK_QUADRATIC_LINEAR_WEDGE, 12 points",
                _ => "VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON, 24 points",
            };
            return Err(format!(
                "cell type {t} ({name}): incomplete (serendipity) elements are not supported"
            ));
        }
        14 | 27 | 37 | 66 | 74 | 81 => {
            return Err(format!(
                "cell type {t} is a pyramid: pyramid elements are not supported"
            ))
        }
        75..=80 => {
            return Err(format!(
                "cell type {t} is a Bézier cell: only Lagrange cells are supported"
            ))
        }
        4 | 6 | 7 | 8 | 11 | 42 => {
            let name = match t {
                4 => "VTK_POLY_LINE",
                6 => "VTK_TRIANGLE_STRIP",
                7 => "VTK_POLYGON",
                8 => "VTK_PIXEL",
                11 => "VTK_VOXEL",
                _ => "VTK_POLYHEDRON",
            };
            return Err(format!("cell type {t} ({name}) is not supported"));
        }
        _ => return Err(format!("unknown or unsupported VTK cell type {t}")),
    })
}

/// The point order of a VTK cell as a permutation into hocurve's canonical order.
/// `old_hex`: a Lagrange hexahedron of a file older than version 2.1, whose vertical edges
/// 10 and 11 were (3, 7) and (2, 6) instead of (2, 6) and (3, 7).
pub(super) fn vtk_order(shape: Shape, order: usize, old_hex: bool) -> Vec<usize> {
    let mut perm = vtk_permutation(shape, order);
    if old_hex {
        let n = order - 1;
        let (a, b) = (8 + 10 * n, 8 + 11 * n);
        let (first, second) = perm.split_at_mut(b);
        first[a..b].swap_with_slice(&mut second[..n]);
    }
    perm
}
