#!/usr/bin/env python3
"""Check .msh files written by hocurve with Gmsh itself.

    target/pyenv/bin/python xtask/scripts/check_msh.py [--curved] [--manifest FILE] a.msh ...

Each file is opened with `gmsh.open`; for every element type of the mesh
dimension and the one below:
- the file opens without Gmsh errors;
- unless --curved: every node of every element sits where the straight-sided
  map of the element's vertices puts Gmsh's reference node of that index
  (`getElementProperties` local coordinates), so a node-ordering bug is caught
  node by node;
- Gmsh's own Jacobians (`getJacobians` at Gauss points) are positive (cells;
  in a 2D mesh, the z component of the normal) and, unless --curved, constant
  per element (relative spread < 1e-9, loosened by 10x per order above 4 for
  the conditioning of Gmsh's high-order bases);
- with --manifest (lines "file<TAB>measure"), the summed volume/area of the
  cells (sum of det J x weights) matches the expected one to the same
  relative tolerance.

Gmsh 4.x cannot evaluate complete prisms of order >= 3 ("FaceClosureFull not
implemented for prisms"), although it defines, writes and reads them. For those
the reference nodes are taken from a reference prism that Gmsh meshes at that
order itself (as in dump_orderings.py), the node positions are checked against
them, and the volume is summed from the vertices (straight-sided only); with
--curved they are reported as unchecked.

Prints one line per file; exits 1 on any failure.
"""

import argparse
import os
import sys
import tempfile

import gmsh
import numpy as np

POSITION_TOL = 1e-9


def evaluation_tol(order):
    """Tolerance on det J spread and on the measure for Gmsh's evaluation at `order`.
    Gmsh evaluates its Lagrange bases through monomials, whose conditioning degrades
    with the order (order-6 hexahedra: spread ~2e-9 on exact affine elements)."""
    return 1e-9 * 10 ** max(0, order - 4)

# Complete prism types whose basis Gmsh cannot build, with their order.
PRISM_TYPES = {90: 3, 91: 4, 106: 5, 107: 6, 108: 7, 109: 8, 110: 9}


def family(name):
    for prefix, fam in (("Line", "line"), ("Triangle", "tri"), ("Quadrilateral", "quad"),
                        ("Tetrahedron", "tet"), ("Hexahedron", "hex"), ("Prism", "prism")):
        if name.startswith(prefix):
            return fam
    raise SystemExit(f"unexpected Gmsh element {name}")


def vertex_functions(fam, u):
    """Gmsh's linear shape functions on its reference elements (quad/hex in [-1,1],
    prism = triangle x [-1,1])."""
    x, y, z = u
    if fam == "line":
        return [(1 - x) / 2, (1 + x) / 2]
    if fam == "tri":
        return [1 - x - y, x, y]
    if fam == "quad":
        return [(1 - x) * (1 - y) / 4, (1 + x) * (1 - y) / 4,
                (1 + x) * (1 + y) / 4, (1 - x) * (1 + y) / 4]
    if fam == "tet":
        return [1 - x - y - z, x, y, z]
    if fam == "hex":
        corners = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                   (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
        return [(1 + a * x) * (1 + b * y) * (1 + c * z) / 8 for a, b, c in corners]
    if fam == "prism":
        t = [1 - x - y, x, y]
        return [t[i] * (1 - z) / 2 for i in range(3)] + [t[i] * (1 + z) / 2 for i in range(3)]
    raise ValueError(fam)


_PRISM_REF = {}


def prism_reference_nodes(order):
    """Gmsh's reference nodes of the complete order-`order` prism, in Gmsh's order, read
    off a reference prism that Gmsh meshes itself (z in [-1, 1] like getElementProperties)."""
    if order in _PRISM_REF:
        return _PRISM_REF[order]
    current = gmsh.model.getCurrent()
    gmsh.model.add(f"__prism_reference_{order}")
    geo = gmsh.model.geo
    pts = [geo.addPoint(*x, 1.0) for x in ((0, 0, 0), (1, 0, 0), (0, 1, 0))]
    lines = [geo.addLine(pts[i], pts[(i + 1) % 3]) for i in range(3)]
    surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    for line in lines:
        geo.mesh.setTransfiniteCurve(line, 2)
    geo.mesh.setTransfiniteSurface(surf)
    geo.extrude([(2, surf)], 0, 0, 1, [1], recombine=True)
    geo.synchronize()
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(order)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    where = {int(t): i for i, t in enumerate(tags)}
    _, _, enodes = gmsh.model.mesh.getElements(3)
    ref = []
    for t in enodes[0]:
        x, y, z = coords[3 * where[int(t)]:3 * where[int(t)] + 3]
        ref.append((x, y, 2 * z - 1))
    gmsh.model.remove()
    gmsh.model.setCurrent(current)
    _PRISM_REF[order] = np.array(ref)
    return _PRISM_REF[order]


def element_info(etype):
    """(family, dim, order, number of nodes, reference nodes n x 3, Gmsh can evaluate)."""
    if etype in PRISM_TYPES:
        p = PRISM_TYPES[etype]
        ref = prism_reference_nodes(p)
        return "prism", 3, p, len(ref), ref, False
    name, dim, order, n, local, _ = gmsh.model.mesh.getElementProperties(etype)
    ref = np.zeros((n, 3))
    ref[:, :dim] = np.array(local).reshape(n, dim)
    return family(name), dim, order, n, ref, True


def vertex_volume(fam, x):
    """Volume of a straight-sided element from its vertices (3D cells only)."""
    def tet(a, b, c, d):
        return np.linalg.det(np.array([b - a, c - a, d - a])) / 6
    if fam == "tet":
        return tet(*x[:4])
    if fam == "prism":
        return tet(x[0], x[1], x[2], x[3]) + tet(x[1], x[2], x[3], x[4]) + tet(x[2], x[3], x[4], x[5])
    raise ValueError(fam)


def restart_gmsh():
    """A fresh Gmsh session: after a failed `open`, Gmsh's state is unusable (later files
    read as empty)."""
    gmsh.finalize()
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)


def without_data_sections(path):
    """A copy of the MSH file without its $NodeData/$ElementData sections."""
    out = os.path.join(tempfile.mkdtemp(), os.path.basename(path))
    skip = False
    with open(path) as src, open(out, "w") as dst:
        for line in src:
            if line.startswith(("$NodeData", "$ElementData", "$ElementNodeData")):
                skip = True
            if not skip:
                dst.write(line)
            if line.startswith(("$EndNodeData", "$EndElementData", "$EndElementNodeData")):
                skip = False
    return out


def check_file(path, curved, constant=True):
    fails, notes = [], []
    gmsh.clear()
    gmsh.logger.start()
    try:
        gmsh.open(path)
    except Exception as e:  # noqa: BLE001 - report whatever Gmsh raised
        gmsh.logger.stop()
        restart_gmsh()
        gmsh.logger.start()
        if "FaceClosureFull" in str(e):
            # Gmsh cannot build the post-processing views of point/cell data on complete
            # prisms of order >= 3; the mesh itself is what is checked here.
            notes.append("Gmsh cannot show data on order >= 3 prisms: mesh read without "
                         "its data sections")
            try:
                gmsh.open(without_data_sections(path))
            except Exception as e2:  # noqa: BLE001
                fails.append(f"gmsh.open failed: {e2}")
                restart_gmsh()
        else:
            fails.append(f"gmsh.open failed: {e}")
    log = gmsh.logger.get()
    gmsh.logger.stop()
    errors = [m for m in log if m.startswith("Error") or m.startswith("Warning")]
    if errors:
        fails.append("Gmsh reported: " + " | ".join(errors[:5]))
    if fails:
        return 0, {}, 0.0, fails, notes, 0.0

    types = {}
    for d in (1, 2, 3):
        for t in gmsh.model.mesh.getElementTypes(d):
            types[int(t)] = d
    if not types:
        return 0, {}, 0.0, ["no elements"], notes, 0.0
    mesh_dim = max(types.values())
    tags, coords, _ = gmsh.model.mesh.getNodes()
    where = {int(t): i for i, t in enumerate(tags)}
    coords = np.array(coords).reshape(-1, 3)
    scale = max(1.0, np.abs(coords).max())

    measure = 0.0
    counts = {}
    max_order = 1
    for etype, edim in sorted(types.items()):
        if edim < mesh_dim - 1:
            continue
        fam, dim, order, n, ref, evaluable = element_info(etype)
        max_order = max(max_order, order)
        etags, enodes = gmsh.model.mesh.getElementsByType(etype)
        ne = len(etags)
        counts[etype] = ne
        if len(enodes) != ne * n:
            fails.append(f"type {etype}: {len(enodes)} node tags for {ne} elements of {n} nodes")
            continue
        x = coords[[where[int(t)] for t in enodes]].reshape(ne, n, 3)
        nv = len(vertex_functions(fam, (0, 0, 0)))
        if not curved:
            shape = np.array([vertex_functions(fam, u) for u in ref])  # n x nv
            straight = np.einsum("kv,evd->ekd", shape, x[:, :nv, :])
            err = np.abs(straight - x).max(axis=(1, 2))
            bad = np.nonzero(err > POSITION_TOL * scale)[0]
            for e in bad[:3]:
                k = int(np.argmax(np.abs(straight[e] - x[e]).max(axis=1)))
                fails.append(f"type {etype} element {int(etags[e])}: node {k} at {x[e, k]}, "
                             f"straight-sided position {straight[e, k]}")
        if not evaluable:
            if edim == mesh_dim:
                if curved:
                    notes.append(f"type {etype} (order-{order} prism): Gmsh cannot evaluate it, "
                                 "Jacobians unchecked")
                else:
                    vols = np.array([vertex_volume(fam, xe[:nv]) for xe in x])
                    if vols.min() <= 0:
                        fails.append(f"type {etype}: non-positive volume {vols.min()}")
                    measure += vols.sum()
                    notes.append(f"type {etype} (order-{order} prism): Gmsh cannot evaluate it; "
                                 "nodes checked against Gmsh's own order-p prism, volume from vertices")
            continue
        pts, wts = gmsh.model.mesh.getIntegrationPoints(etype, f"Gauss{2 * order + 2}")
        jac, det, _ = gmsh.model.mesh.getJacobians(etype, pts)
        npts = len(wts)
        jac = np.array(jac).reshape(ne, npts, 3, 3)
        det = np.array(det).reshape(ne, npts)
        if edim == 2 and mesh_dim == 2:
            # Gmsh's det of a 2D element is unsigned; orientation from the normal's z.
            signed = np.cross(jac[:, :, 0, :], jac[:, :, 1, :])[:, :, 2]
        else:
            signed = det
        if edim == mesh_dim or mesh_dim == 2:
            worst = signed.min(axis=1)
            for e in np.nonzero(worst <= 0)[0][:3]:
                fails.append(f"type {etype} element {int(etags[e])}: det J {worst[e]:.3e} <= 0")
        if not curved and constant:
            spread = (signed.max(axis=1) - signed.min(axis=1)) / np.abs(signed).max(axis=1)
            for e in np.nonzero(spread > evaluation_tol(order))[0][:3]:
                fails.append(f"type {etype} element {int(etags[e])}: det J not constant "
                             f"(relative spread {spread[e]:.2e})")
        if edim == mesh_dim:
            measure += float((signed * np.array(wts)).sum())

    # Physical groups must have come through with their names.
    groups = gmsh.model.getPhysicalGroups()
    if not groups:
        notes.append("no physical groups")
    return sum(counts.values()), counts, measure, fails, notes, evaluation_tol(max_order)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--curved", action="store_true",
                    help="only require det J > 0 (elements may be curved)")
    ap.add_argument("--no-constant", action="store_true",
                    help="straight-sided but not affine (bilinear quads, trilinear hexes): "
                         "do not require det J constant")
    ap.add_argument("--manifest", help="TSV lines 'file<TAB>expected measure'")
    ap.add_argument("-v", "--verbose", action="store_true", help="print notes")
    args = ap.parse_args()
    expected = {}
    if args.manifest:
        with open(args.manifest) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    name, value = line.rstrip("\n").split("\t")
                    expected[name] = float(value)
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    failed = 0
    notes_seen = set()
    for path in args.files:
        n, counts, measure, fails, notes, tol = check_file(path, args.curved, not args.no_constant)
        name = os.path.basename(path)
        if name in expected and not fails:
            want = expected[name]
            if abs(measure - want) > tol * abs(want):
                fails.append(f"measure {measure!r} differs from expected {want!r}")
        status = "FAIL" if fails else "ok"
        kinds = " ".join(f"{t}x{k}" for t, k in sorted(counts.items()))
        print(f"{status} {path}: {n} elements ({kinds}), measure {measure:.12g}")
        for f in fails:
            print(f"    {f}")
        for note in notes:
            if args.verbose or note not in notes_seen:
                print(f"    note: {note}")
                notes_seen.add(note)
        failed += bool(fails)
    gmsh.finalize()
    print(f"{len(args.files) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
