#!/usr/bin/env python3
"""Gmsh's det J of the curved meshes hocurve writes, against hocurve's own.

    target/pyenv/bin/python xtask/scripts/compare_jacobians.py a_p3.msh ...

Beside each a.msh, a.json (written by `cargo xtask`, see xtask/src/curved_interop.rs)
holds, per element shape, reference points in hocurve's coordinates, the
Gmsh tags of the cells and hocurve's det J of each cell at each point,
computed on the mesh before it was resampled to Gmsh's equispaced nodes.
Gmsh opens the .msh and evaluates `getJacobians` at the same points, given
in its own reference coordinates: the unit triangle and tetrahedron are
shared, but quadrilaterals and hexahedra live on [-1, 1]^d and the prism's
third direction on [-1, 1], so u = 2 xi - 1 there and Gmsh's determinant is
ours / 2 per such direction. In 2D Gmsh's determinant is unsigned; the signed
one is the z component of the cross product of its Jacobian rows.

Checks, per cell: Gmsh's det J > 0, and |det_gmsh - det_ours| <= tol x
max |det_ours| with tol = 1e-9 x 10^max(0, p - 4) (Gmsh evaluates its
Lagrange bases through monomials, whose conditioning grows with the order).
Gmsh cannot evaluate complete prisms of order >= 3 (see check_msh.py): those
are reported as unchecked.

Prints one line per file; exits 1 on any failure.
"""

import json
import os
import sys

import gmsh
import numpy as np

GMSH_FAMILY = {"triangle": "Triangle", "quadrilateral": "Quadrangle", "tetrahedron": "Tetrahedron",
               "hexahedron": "Hexahedron", "prism": "Prism", "line": "Line"}
# reference directions that Gmsh maps to [-1, 1]
SYMMETRIC_AXES = {"quadrilateral": (0, 1), "hexahedron": (0, 1, 2), "prism": (2,)}


def tolerance(order):
    return 1e-9 * 10 ** max(0, order - 4)


def check_file(path):
    with open(os.path.splitext(path)[0] + ".json") as f:
        ours = json.load(f)
    fails, notes = [], []
    gmsh.clear()
    gmsh.open(path)
    dim = max(d for d, _ in gmsh.model.getEntities())
    compared = 0
    worst_rel = 0.0
    for group in ours["groups"]:
        shape, p = group["shape"], group["order"]
        if shape == "prism" and p >= 3:
            notes.append(f"order-{p} prisms: Gmsh cannot evaluate them, unchecked")
            continue
        family = GMSH_FAMILY.get(shape)
        if family is None:
            fails.append(f"unknown shape {shape}")
            continue
        etype = gmsh.model.mesh.getElementType(family, p)
        tags, _ = gmsh.model.mesh.getElementsByType(etype)
        where = {int(t): i for i, t in enumerate(tags)}
        xi = np.array(group["points"], dtype=float)
        u = xi.copy()
        axes = SYMMETRIC_AXES.get(shape, ())
        for a in axes:
            u[:, a] = 2 * xi[:, a] - 1
        jac, det, _ = gmsh.model.mesh.getJacobians(etype, u.ravel().tolist())
        npts = len(xi)
        jac = np.array(jac).reshape(len(tags), npts, 3, 3)
        det = np.array(det).reshape(len(tags), npts)
        if dim == 2:
            det = np.cross(jac[:, :, 0, :], jac[:, :, 1, :])[:, :, 2]
        det = det * 2.0 ** len(axes)
        missing = [t for t in group["tags"] if t not in where]
        if missing:
            fails.append(f"{shape}: {len(missing)} cells not found in the file (tag {missing[0]})")
            continue
        gm = det[[where[t] for t in group["tags"]]]
        mine = np.array(group["det"], dtype=float)
        if gm.shape != mine.shape:
            fails.append(f"{shape}: {gm.shape} Gmsh values for {mine.shape} of ours")
            continue
        if gm.min() <= 0:
            e = int(np.argmin(gm.min(axis=1)))
            fails.append(f"{shape}: Gmsh det J {gm.min():.3e} <= 0 in cell tag {group['tags'][e]}")
        scale = np.abs(mine).max(axis=1, keepdims=True)
        rel = np.abs(gm - mine) / scale
        worst_rel = max(worst_rel, float(rel.max()))
        bad = np.nonzero(rel.max(axis=1) > tolerance(p))[0]
        for e in bad[:3]:
            fails.append(f"{shape} cell tag {group['tags'][e]}: det J differs by "
                         f"{rel[e].max():.2e} relative (Gmsh {gm[e].tolist()[:3]}..., ours "
                         f"{mine[e].tolist()[:3]}...)")
        compared += mine.size
    return compared, worst_rel, fails, notes


def main():
    files = sys.argv[1:]
    if not files:
        raise SystemExit(__doc__)
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    failed = 0
    for path in files:
        compared, worst, fails, notes = check_file(path)
        status = "FAIL" if fails else "ok"
        print(f"{status} {path}: {compared} det J compared, largest difference "
              f"{worst:.1e} of the cell's max det J")
        for f in fails:
            print(f"    {f}")
        for n in notes:
            print(f"    note: {n}")
        failed += bool(fails)
    gmsh.finalize()
    print(f"{len(files) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
