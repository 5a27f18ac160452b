#!/usr/bin/env python3
"""VTK reads the committed golden snapshots of the curved meshes and measures them.

    target/pyenv/bin/python xtask/scripts/check_snapshots.py SNAPSHOT_DIR OUT_DIR

For every `snapshots__<case>_vtu.snap` (tests/snapshots.rs) the .vtu text after
insta's header is written to OUT_DIR/<case>.vtu and read back with VTK's XML
reader (no errors or warnings allowed). With VTK's own Lagrange cells
(`InterpolateDerivs` at Gauss points of a collapsed Gauss-Legendre rule exact
for det J, whose degree is at most dim x p) the script computes det J at every
point of every cell and the total area/volume, and checks:
- det J > 0 everywhere (2D: the z component of the normal);
- the measure agrees with the one our own quadrature computed on the unrounded
  mesh (the `measure, our quadrature` line of `<case>_summary`) to 1e-8
  relative (the snapshot's coordinates are rounded to ~1e-9 x model size);
- it is as close to the exact measure (`measure, exact`) as ours is, up to the
  same 1e-8: for NACA0012 the disc of radius 10 minus the airfoil;
- for the sphere in a box at p = 4: |V - (216 - 4 pi / 3)| <= 1e-6 V.

Shape functions depend only on the reference cell, so their derivatives are
taken once per (cell type, point count) from VTK and applied to all cells.

Prints one line per snapshot; exits 1 on any failure.
"""

import math
import os
import re
import sys

import numpy as np
from vtk.util import numpy_support

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_vtu import SHAPES, derivative_layout, quadrature, read_grid  # noqa: E402

AGREEMENT_TOL = 1e-8
SPHERE_P4_TOL = 1e-6


def snapshot_body(path):
    """The snapshot text after insta's `---` header."""
    text = open(path, encoding="utf-8").read()
    if not text.startswith("---\n"):
        raise SystemExit(f"{path}: not an insta snapshot")
    end = text.index("\n---\n", 4)
    return text[end + 5:]


def summary_value(text, key):
    m = re.search(r"^" + re.escape(key) + r"\s+(\S+)", text, re.M)
    if not m:
        raise SystemExit(f"no '{key}' line in a summary snapshot")
    return float(m.group(1))


def order_of(ctype, npts):
    """Polynomial order of a complete Lagrange cell from its point count."""
    dim, shape = SHAPES[ctype]
    for p in range(1, 12):
        n = {"line": p + 1, "tri": (p + 1) * (p + 2) // 2, "quad": (p + 1) ** 2,
             "tet": (p + 1) * (p + 2) * (p + 3) // 6, "hex": (p + 1) ** 3,
             "wedge": (p + 1) ** 2 * (p + 2) // 2}[shape]
        if n == npts:
            return p
    raise SystemExit(f"cell type {ctype} with {npts} points is not a complete Lagrange cell")


def measure_grid(grid):
    """(total measure, smallest det J, cells) with VTK's shape functions."""
    npts = grid.GetNumberOfPoints()
    points = numpy_support.vtk_to_numpy(grid.GetPoints().GetData()).reshape(npts, 3)
    cells = grid.GetCells()
    conn = numpy_support.vtk_to_numpy(cells.GetConnectivityArray())
    offsets = numpy_support.vtk_to_numpy(cells.GetOffsetsArray())
    types = numpy_support.vtk_to_numpy(grid.GetCellTypesArray())
    total, worst = 0.0, math.inf
    for ctype in np.unique(types):
        ids = np.nonzero(types == ctype)[0]
        counts = offsets[ids + 1] - offsets[ids]
        for n in np.unique(counts):
            group = ids[counts == n]
            dim, shape = SHAPES[int(ctype)]
            p = order_of(int(ctype), int(n))
            # det J has degree <= dim (p - 1) on simplices (the collapsed rule's (1 - a)
            # factors add dim - 1) and <= dim p per variable on tensor cells; Gauss with m
            # points per direction is exact to degree 2m - 1
            if shape in ("tri", "tet"):
                m = (dim * (p - 1) + dim - 1) // 2 + 1
            else:
                m = (dim * p) // 2 + 1
            pts, wts = quadrature(shape, m)
            cell = grid.GetCell(int(group[0]))
            layout = derivative_layout(cell, dim, int(n))
            derivs = [0.0] * (dim * int(n))
            D = np.empty((len(pts), dim, int(n)))  # dN_i/dxi_j at each point
            for q, xi in enumerate(pts):
                cell.InterpolateDerivs(xi, derivs)
                a = np.array(derivs)
                D[q] = a.reshape(dim, int(n)) if layout == "blocked" else a.reshape(int(n), dim).T
            for chunk in range(0, len(group), 500):
                cells_here = group[chunk:chunk + 500]
                index = offsets[cells_here][:, None] + np.arange(int(n))[None, :]
                x = points[conn[index]]  # cells x n x 3
                jac = np.einsum("cid,qji->cqdj", x, D)  # cells x points x 3 x dim
                if dim == 3:
                    det = np.linalg.det(jac)
                elif dim == 2:
                    det = jac[..., 0, 0] * jac[..., 1, 1] - jac[..., 1, 0] * jac[..., 0, 1]
                else:
                    det = np.linalg.norm(jac[..., 0], axis=-1)
                worst = min(worst, float(det.min()))
                total += float((det * np.array(wts)).sum())
    return total, worst, grid.GetNumberOfCells()


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    snapdir, outdir = sys.argv[1], sys.argv[2]
    os.makedirs(outdir, exist_ok=True)
    names = sorted(f for f in os.listdir(snapdir) if f.endswith("_vtu.snap"))
    if not names:
        raise SystemExit(f"no *_vtu.snap in {snapdir}")
    failed = 0
    for name in names:
        case = name[len("snapshots__"):-len("_vtu.snap")]
        path = os.path.join(outdir, case + ".vtu")
        with open(path, "w", encoding="utf-8") as f:
            f.write(snapshot_body(os.path.join(snapdir, name)))
        summary = snapshot_body(os.path.join(snapdir, f"snapshots__{case}_summary.snap"))
        ours = summary_value(summary, "measure, our quadrature")
        exact = summary_value(summary, "measure, exact")
        fails = []
        grid, messages = read_grid(path)
        if messages:
            fails.append(f"VTK reported: {messages[:300]}")
        measure, worst, ncells = measure_grid(grid)
        if worst <= 0:
            fails.append(f"det J min {worst:.3e} <= 0")
        if abs(measure - ours) > AGREEMENT_TOL * abs(exact):
            fails.append(f"VTK's measure {measure!r} differs from ours {ours!r}")
        if abs(measure - exact) > abs(ours - exact) + AGREEMENT_TOL * abs(exact):
            fails.append(f"VTK's measure is farther from the exact {exact!r} than ours")
        if case.startswith("sphere_p4") and abs(measure - exact) > SPHERE_P4_TOL * exact:
            fails.append(f"volume {measure!r} differs from 216 - 4 pi/3 = {exact!r} by more "
                         f"than {SPHERE_P4_TOL:g} relative")
        status = "FAIL" if fails else "ok"
        print(f"{status} {case}: {ncells} cells, measure VTK {measure:.10f}, ours {ours:.9f}, "
              f"exact {exact:.9f} (rel. error {abs(measure - exact) / exact:.2e}), "
              f"min det J {worst:.3e}")
        for f in fails:
            print(f"    {f}")
        failed += bool(fails)
    print(f"{len(names) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
