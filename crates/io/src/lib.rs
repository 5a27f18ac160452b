//! File formats for hocurve: Gmsh MSH in (4.1 and 2.2, ASCII and binary); high-order Gmsh
//! MSH 4.1 and VTK XML `.vtu` Lagrange cells out.
