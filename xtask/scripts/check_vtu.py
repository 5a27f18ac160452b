#!/usr/bin/env python3
"""Check .vtu files written by hocurve with VTK's own reader and shape functions.

    target/pyenv/bin/python xtask/scripts/check_vtu.py [--curved] [--manifest FILE] a.vtu ...

For every cell, VTK's Lagrange (or linear) cell class evaluates the Jacobian
determinant at Gauss points from its own shape-function derivatives
(`InterpolateDerivs`) and the cell's points. The checks:
- the file reads without VTK errors or warnings;
- det J > 0 at every point of every cell (2D cells: the z component of the
  normal, the mesh lying in the xy plane);
- unless --curved: det J is constant per cell (relative spread < 1e-9) and
  the cell's map is the straight-sided (vertex-interpolating) map, so a point
  put in the wrong place by a node-ordering bug is caught;
- a point-data array "coordinates", if present, equals the points; a cell-data
  array "cell id", if present, is 0, 1, 2, ...;
- with --manifest (lines "file<TAB>measure"), the summed volume (3D) or area
  (2D) matches the expected one to 1e-9 relative.

Prints one line per file (cells, cell types, measure); exits 1 on any failure.
"""

import argparse
import os
import sys

import numpy as np
import vtk

SPREAD_TOL = 1e-9
POSITION_TOL = 1e-9
MEASURE_TOL = 1e-9

# VTK cell type -> (dimension, shape)
SHAPES = {
    3: (1, "line"), 68: (1, "line"),
    5: (2, "tri"), 69: (2, "tri"),
    9: (2, "quad"), 70: (2, "quad"),
    10: (3, "tet"), 71: (3, "tet"),
    12: (3, "hex"), 72: (3, "hex"),
    13: (3, "wedge"), 73: (3, "wedge"),
}
# Vertices of the reference cells in VTK's parametric coordinates (all in [0, 1]).
VERTICES = {
    "line": [(0, 0, 0), (1, 0, 0)],
    "tri": [(0, 0, 0), (1, 0, 0), (0, 1, 0)],
    "quad": [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
    "tet": [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
    "hex": [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
            (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
    "wedge": [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1)],
}


def vertex_functions(shape, xi):
    """Straight-sided (vertex) shape functions at xi, VTK vertex order."""
    x, y, z = xi
    if shape == "line":
        return [1 - x, x]
    if shape == "tri":
        return [1 - x - y, x, y]
    if shape == "quad":
        return [(1 - x) * (1 - y), x * (1 - y), x * y, (1 - x) * y]
    if shape == "tet":
        return [1 - x - y - z, x, y, z]
    if shape == "hex":
        return [(1 - x if vx == 0 else x) * (1 - y if vy == 0 else y) * (1 - z if vz == 0 else z)
                for vx, vy, vz in VERTICES["hex"]]
    if shape == "wedge":
        t = [1 - x - y, x, y]
        return [t[i] * (1 - z) for i in range(3)] + [t[i] * z for i in range(3)]
    raise ValueError(shape)


def quadrature(shape, n):
    """Points and weights on VTK's reference cell, exact for degree 2n - 1 (collapsed
    Gauss-Legendre on simplices)."""
    g, w = np.polynomial.legendre.leggauss(n)
    g = (g + 1) / 2
    w = w / 2
    pts, wts = [], []
    if shape == "line":
        return [(a, 0.0, 0.0) for a in g], list(w)
    if shape == "quad":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                pts.append((a, b, 0.0))
                wts.append(wa * wb)
    elif shape == "hex":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                for c, wc in zip(g, w):
                    pts.append((a, b, c))
                    wts.append(wa * wb * wc)
    elif shape == "tri":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                pts.append((a, (1 - a) * b, 0.0))
                wts.append(wa * wb * (1 - a))
    elif shape == "tet":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                for c, wc in zip(g, w):
                    pts.append((a, (1 - a) * b, (1 - a) * (1 - b) * c))
                    wts.append(wa * wb * wc * (1 - a) ** 2 * (1 - b))
    elif shape == "wedge":
        for a, wa in zip(g, w):
            for b, wb in zip(g, w):
                for c, wc in zip(g, w):
                    pts.append((a, (1 - a) * b, c))
                    wts.append(wa * wb * wc * (1 - a))
    return pts, wts


def read_grid(path):
    """Reads a .vtu file; returns the grid and whatever VTK printed as errors/warnings."""
    window = vtk.vtkStringOutputWindow()
    vtk.vtkOutputWindow.SetInstance(window)
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput(), window.GetOutput().strip()


_LAYOUT = {}


def derivative_layout(cell, dim, n):
    """How `InterpolateDerivs` lays out dN_i/dxi_j for this cell class: "blocked"
    (index j*n + i, VTK's documented layout, used by most cells) or "interleaved"
    (i*dim + j: vtkLagrangeQuadrilateral and vtkLagrangeHexahedron, VTK 9.3 to 9.7).
    Decided by differentiating the parametric coordinates themselves, which must give
    the identity."""
    key = (cell.GetCellType(), n)
    if key not in _LAYOUT:
        pc = cell.GetParametricCoords()
        xi = np.array([pc[k] for k in range(3 * n)]).reshape(n, 3)[:, :dim]
        derivs = [0.0] * (dim * n)
        cell.InterpolateDerivs([0.21, 0.33, 0.17], derivs)
        a = np.array(derivs)
        found = None
        for name, d in (("blocked", a.reshape(dim, n)), ("interleaved", a.reshape(n, dim).T)):
            if np.allclose(xi.T @ d.T, np.eye(dim), atol=1e-9):
                found = name
                break
        if found is None:
            raise SystemExit(f"cannot make sense of InterpolateDerivs of {cell.GetClassName()}")
        _LAYOUT[key] = found
    return _LAYOUT[key]


def array(data, name):
    a = data.GetArray(name)
    if a is None:
        return None
    n, c = a.GetNumberOfTuples(), a.GetNumberOfComponents()
    return np.array([a.GetComponent(i, j) for i in range(n) for j in range(c)]).reshape(n, c)


def check_file(path, curved, constant=True):
    grid, messages = read_grid(path)
    fails = []
    if messages:
        fails.append(f"VTK reported: {messages[:500]}")
    ncells = grid.GetNumberOfCells()
    npts = grid.GetNumberOfPoints()
    if ncells == 0 or npts == 0:
        fails.append("no cells or no points read")
    points = np.array([grid.GetPoint(i) for i in range(npts)])

    coords = array(grid.GetPointData(), "coordinates")
    if coords is not None and not np.array_equal(coords, points):
        fails.append("point data 'coordinates' differs from the points")
    ids = array(grid.GetCellData(), "cell id")
    if ids is not None and not np.array_equal(ids[:, 0], np.arange(ncells)):
        fails.append("cell data 'cell id' is not 0, 1, 2, ...")

    measure = 0.0
    types = {}
    for c in range(ncells):
        cell = grid.GetCell(c)
        ctype = cell.GetCellType()
        if ctype not in SHAPES:
            fails.append(f"cell {c}: unexpected cell type {ctype}")
            continue
        dim, shape = SHAPES[ctype]
        types[ctype] = types.get(ctype, 0) + 1
        n = cell.GetNumberOfPoints()
        x = np.array([cell.GetPoints().GetPoint(i) for i in range(n)])
        nv = len(VERTICES[shape])
        pts, wts = quadrature(shape, 6 if curved else 3)
        dets = []
        layout = derivative_layout(cell, dim, n)
        derivs = [0.0] * (n * dim)
        weights = [0.0] * n
        for xi, wt in zip(pts, wts):
            cell.InterpolateDerivs(xi, derivs)
            if layout == "blocked":
                d = np.array(derivs).reshape(dim, n)  # d[j, i] = dN_i / dxi_j
            else:
                d = np.array(derivs).reshape(n, dim).T
            jac = x.T @ d.T  # 3 x dim
            if dim == 3:
                det = np.linalg.det(jac)
            elif dim == 2:
                det = np.cross(jac[:, 0], jac[:, 1])[2]
            else:
                det = np.linalg.norm(jac[:, 0])
            dets.append(det)
            measure += det * wt
            if not curved:
                cell.InterpolateFunctions(xi, weights)
                at = np.array(weights) @ x
                straight = np.array(vertex_functions(shape, xi)) @ x[:nv]
                scale = max(1.0, np.abs(points).max())
                if np.abs(at - straight).max() > POSITION_TOL * scale:
                    fails.append(f"cell {c} (type {ctype}): map at {xi} is {at}, "
                                 f"straight-sided map gives {straight}")
                    break
        dets = np.array(dets)
        if dets.min() <= 0:
            fails.append(f"cell {c} (type {ctype}, {n} points): det J min {dets.min():.3e} <= 0")
        elif not curved and constant:
            spread = (dets.max() - dets.min()) / np.abs(dets).max()
            if spread > SPREAD_TOL:
                fails.append(f"cell {c} (type {ctype}, {n} points): det J not constant "
                             f"(relative spread {spread:.2e})")
        if len(fails) > 20:
            break
    return ncells, types, measure, fails


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--curved", action="store_true",
                    help="only require det J > 0 (cells may be curved)")
    ap.add_argument("--no-constant", action="store_true",
                    help="straight-sided but not affine (bilinear quads, trilinear hexes): "
                         "do not require det J constant")
    ap.add_argument("--manifest", help="TSV lines 'file<TAB>expected measure'")
    args = ap.parse_args()
    expected = {}
    if args.manifest:
        with open(args.manifest) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    name, value = line.rstrip("\n").split("\t")
                    expected[name] = float(value)
    failed = 0
    for path in args.files:
        ncells, types, measure, fails = check_file(path, args.curved, not args.no_constant)
        name = os.path.basename(path)
        if name in expected:
            want = expected[name]
            if abs(measure - want) > MEASURE_TOL * abs(want):
                fails.append(f"measure {float(measure)!r} differs from expected {want!r}")
        status = "FAIL" if fails else "ok"
        kinds = " ".join(f"{t}x{k}" for t, k in sorted(types.items()))
        print(f"{status} {path}: {ncells} cells ({kinds}), measure {measure:.12g}")
        for f in fails:
            print(f"    {f}")
        failed += bool(fails)
    print(f"{len(args.files) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
