//! Gmsh element types: which ones the readers take (first-order ones for the linear reader,
//! complete Lagrange elements of any order for the high-order reader) and, for the others,
//! what they are, so that the error can name them.

use hocurve_mesh::Shape;

use crate::ordering::gmsh_type_shape;

/// The element type of a block of elements: its type, order and number of nodes.
#[derive(Debug, Clone, Copy)]
pub(super) struct BlockKind {
    pub(super) kind: Shape,
    pub(super) order: usize,
    pub(super) nodes: usize,
}

impl BlockKind {
    /// A first-order element of type `kind`.
    pub(super) fn linear(kind: Shape) -> Self {
        BlockKind {
            kind,
            order: 1,
            nodes: kind.num_vertices(),
        }
    }
}

/// What Gmsh element type `t` is for the high-order reader: a complete Lagrange element of
/// any order Gmsh defines, a point (`None`), or an error saying why it cannot be read.
pub(super) fn high_order_kind(t: i64) -> Result<Option<BlockKind>, String> {
    if t == 15 {
        return Ok(None);
    }
    if let Some((shape, order)) = i32::try_from(t).ok().and_then(gmsh_type_shape) {
        return Ok(Some(BlockKind {
            kind: shape,
            order,
            nodes: shape.num_nodes(order),
        }));
    }
    let pyramid = "pyramid elements are not supported; hocurve handles lines, triangles, \
                   quadrilaterals, tetrahedra, hexahedra and prisms";
    if t == 7 {
        return Err(format!("element type 7 (5-node pyramid): {pyramid}"));
    }
    if let Some(&(_, shape, order, nodes)) = HIGH_ORDER.iter().find(|e| e.0 == t) {
        let what = format!(
            "element type {t} ({nodes}-node {} order {shape})",
            ordinal(order)
        );
        return Err(if shape == "pyramid" {
            format!("{what}: {pyramid}")
        } else {
            format!("{what}: incomplete (serendipity) elements are not supported (save complete elements: Mesh.SecondOrderIncomplete = 0)")
        });
    }
    Err(describe_unsupported(t))
}

/// What Gmsh element type `t` is, as far as hocurve cares.
pub(super) fn element_kind(t: i64) -> Result<Option<Shape>, String> {
    Ok(Some(match t {
        1 => Shape::Line,
        2 => Shape::Tri,
        3 => Shape::Quad,
        4 => Shape::Tet,
        5 => Shape::Hex,
        6 => Shape::Prism,
        7 => {
            return Err(
                "pyramid elements are not supported (Gmsh element type 7); hocurve \
                        handles triangles, quadrilaterals, tetrahedra, hexahedra and prisms"
                    .into(),
            )
        }
        15 => return Ok(None),
        _ => return Err(describe_unsupported(t)),
    }))
}

/// Gmsh element types of order ≥ 2: (type, shape, order, number of nodes).
const HIGH_ORDER: &[(i64, &str, u8, u16)] = &[
    (8, "line", 2, 3),
    (9, "triangle", 2, 6),
    (10, "quadrilateral", 2, 9),
    (11, "tetrahedron", 2, 10),
    (12, "hexahedron", 2, 27),
    (13, "prism", 2, 18),
    (14, "pyramid", 2, 14),
    (16, "quadrilateral", 2, 8),
    (17, "hexahedron", 2, 20),
    (18, "prism", 2, 15),
    (19, "pyramid", 2, 13),
    (20, "triangle", 3, 9),
    (21, "triangle", 3, 10),
    (22, "triangle", 4, 12),
    (23, "triangle", 4, 15),
    (24, "triangle", 5, 15),
    (25, "triangle", 5, 21),
    (26, "line", 3, 4),
    (27, "line", 4, 5),
    (28, "line", 5, 6),
    (29, "tetrahedron", 3, 20),
    (30, "tetrahedron", 4, 35),
    (31, "tetrahedron", 5, 56),
    (32, "tetrahedron", 4, 22),
    (33, "tetrahedron", 5, 28),
    (36, "quadrilateral", 3, 16),
    (37, "quadrilateral", 4, 25),
    (38, "quadrilateral", 5, 36),
    (39, "quadrilateral", 3, 12),
    (40, "quadrilateral", 4, 16),
    (41, "quadrilateral", 5, 20),
    (42, "triangle", 6, 28),
    (43, "triangle", 7, 36),
    (44, "triangle", 8, 45),
    (45, "triangle", 9, 55),
    (46, "triangle", 10, 66),
    (47, "quadrilateral", 6, 49),
    (48, "quadrilateral", 7, 64),
    (49, "quadrilateral", 8, 81),
    (50, "quadrilateral", 9, 100),
    (51, "quadrilateral", 10, 121),
    (52, "triangle", 6, 18),
    (53, "triangle", 7, 21),
    (54, "triangle", 8, 24),
    (55, "triangle", 9, 27),
    (56, "triangle", 10, 30),
    (57, "quadrilateral", 6, 24),
    (58, "quadrilateral", 7, 28),
    (59, "quadrilateral", 8, 32),
    (60, "quadrilateral", 9, 36),
    (61, "quadrilateral", 10, 40),
    (62, "line", 6, 7),
    (63, "line", 7, 8),
    (64, "line", 8, 9),
    (65, "line", 9, 10),
    (66, "line", 10, 11),
    (71, "tetrahedron", 6, 84),
    (72, "tetrahedron", 7, 120),
    (73, "tetrahedron", 8, 165),
    (74, "tetrahedron", 9, 220),
    (75, "tetrahedron", 10, 286),
    (79, "tetrahedron", 6, 34),
    (80, "tetrahedron", 7, 40),
    (81, "tetrahedron", 8, 46),
    (82, "tetrahedron", 9, 52),
    (83, "tetrahedron", 10, 58),
    (90, "prism", 3, 40),
    (91, "prism", 4, 75),
    (92, "hexahedron", 3, 64),
    (93, "hexahedron", 4, 125),
    (94, "hexahedron", 5, 216),
    (95, "hexahedron", 6, 343),
    (96, "hexahedron", 7, 512),
    (97, "hexahedron", 8, 729),
    (98, "hexahedron", 9, 1000),
    (99, "hexahedron", 3, 32),
    (100, "hexahedron", 4, 44),
    (101, "hexahedron", 5, 56),
    (102, "hexahedron", 6, 68),
    (103, "hexahedron", 7, 80),
    (104, "hexahedron", 8, 92),
    (105, "hexahedron", 9, 104),
    (106, "prism", 5, 126),
    (107, "prism", 6, 196),
    (108, "prism", 7, 288),
    (109, "prism", 8, 405),
    (110, "prism", 9, 550),
    (111, "prism", 3, 24),
    (112, "prism", 4, 33),
    (113, "prism", 5, 42),
    (114, "prism", 6, 51),
    (115, "prism", 7, 60),
    (116, "prism", 8, 69),
    (117, "prism", 9, 78),
    (118, "pyramid", 3, 30),
    (119, "pyramid", 4, 55),
    (120, "pyramid", 5, 91),
    (121, "pyramid", 6, 140),
    (122, "pyramid", 7, 204),
    (123, "pyramid", 8, 285),
    (124, "pyramid", 9, 385),
    (125, "pyramid", 3, 21),
    (126, "pyramid", 4, 29),
    (127, "pyramid", 5, 37),
    (128, "pyramid", 6, 45),
    (129, "pyramid", 7, 53),
    (130, "pyramid", 8, 61),
    (131, "pyramid", 9, 69),
    (137, "tetrahedron", 3, 16),
];

/// Gmsh element types that are neither first order nor high order Lagrange elements.
const OTHER_TYPES: &[(i64, &str)] = &[
    (34, "polygon"),
    (35, "polyhedron"),
    (67, "line border element"),
    (68, "triangle border element"),
    (69, "polygon border element"),
    (70, "line child element"),
    (84, "1-node line"),
    (85, "1-node triangle"),
    (86, "1-node quadrilateral"),
    (87, "1-node tetrahedron"),
    (88, "1-node hexahedron"),
    (89, "1-node prism"),
    (132, "1-node pyramid"),
    (133, "XFEM point"),
    (134, "XFEM line"),
    (135, "XFEM triangle"),
    (136, "XFEM tetrahedron"),
];

/// The English ordinal of an element order from 2 to 10.
fn ordinal(order: u8) -> &'static str {
    match order {
        2 => "second",
        3 => "third",
        4 => "fourth",
        5 => "fifth",
        6 => "sixth",
        7 => "seventh",
        8 => "eighth",
        9 => "ninth",
        _ => "tenth",
    }
}

/// Why Gmsh element type `t` is not read: a high-order element (for the linear reader), an
/// element of another kind, or an unknown type.
fn describe_unsupported(t: i64) -> String {
    if let Some(&(_, shape, order, nodes)) = HIGH_ORDER.iter().find(|e| e.0 == t) {
        return format!(
            "element type {t} ({nodes}-node {} order {shape}) is a high-order element; hocurve \
             reads linear meshes (Mesh.ElementOrder = 1)",
            ordinal(order)
        );
    }
    if let Some(&(_, what)) = OTHER_TYPES.iter().find(|e| e.0 == t) {
        return format!("element type {t} ({what}) is not supported");
    }
    format!("unknown element type {t}")
}
