#!/usr/bin/env python3
"""High-order meshes written by Gmsh and VTK, for hocurve's readers (tests/io_foreign_readers.rs).

    target/pyenv/bin/python xtask/scripts/make_foreign_meshes.py gmsh OUTDIR [--orders 1 2 3 4]
    target/pyenv/bin/python xtask/scripts/make_foreign_meshes.py vtk IN.vtu OUTPREFIX

gmsh: meshes three curved domains and raises them to order p with setOrder(p), the
high-order nodes placed on the geometry:
- disk2d: the unit disk as two half disks, the right one recombined (triangles and
  quadrilaterals);
- ball: the unit ball (tetrahedra);
- cylinder: the same two half disks extruded in two recombined layers (hexahedra and
  prisms, curved sides).
Each mesh is saved as MSH 4.1 ASCII, 4.1 binary, 2.2 ASCII and 2.2 binary
(NAME_pP_{v41,v41bin,v22,v22bin}.msh), and NAME_pP.json holds, per element type of the
top dimension: Gmsh's local coordinates of the Gauss points of getIntegrationPoints(type,
"Gauss" + str(2p)), and per element its corner coordinates, the Jacobian determinants
getJacobians gives at those points and the physical points there (Gmsh 4.15 cannot
evaluate prisms of order >= 3: their entry says "skipped" instead).

vtk: reads IN.vtu with vtkXMLUnstructuredGridReader and re-writes it with
vtkXMLUnstructuredGridWriter: OUTPREFIX_default.vtu (appended raw, zlib, UInt64 headers:
the writer's defaults), _ascii.vtu, _base64.vtu (appended base64), _binary.vtu (inline
base64), _uint32.vtu (UInt32 headers), _raw.vtu (appended raw, uncompressed).

Deterministic: one thread, fixed sizes and seed.
"""

import json
import os
import sys


def gmsh_meshes(out, orders):
    import gmsh

    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    for name in ["disk2d", "ball", "cylinder"]:
        for p in orders:
            gmsh.clear()
            gmsh.model.add(f"{name}_p{p}")
            dim = build(gmsh, name)
            gmsh.model.mesh.generate(dim)
            if p > 1:
                gmsh.model.mesh.setOrder(p)
            stem = os.path.join(out, f"{name}_p{p}")
            for suffix, version, binary in [
                ("v41", 4.1, 0),
                ("v41bin", 4.1, 1),
                ("v22", 2.2, 0),
                ("v22bin", 2.2, 1),
            ]:
                gmsh.option.setNumber("Mesh.MshFileVersion", version)
                gmsh.option.setNumber("Mesh.Binary", binary)
                gmsh.write(f"{stem}_{suffix}.msh")
            data = jacobians(gmsh, dim, p)
            with open(stem + ".json", "w") as f:
                json.dump(data, f)
            print(f"{stem}: written", flush=True)
    gmsh.finalize()


def half_disks(gmsh):
    """Two half disks of the unit disk; returns their surface tags (right, left)."""
    geo = gmsh.model.geo
    lc = 0.45
    c = geo.addPoint(0, 0, 0, lc)
    e = geo.addPoint(1, 0, 0, lc)
    n = geo.addPoint(0, 1, 0, lc)
    w = geo.addPoint(-1, 0, 0, lc)
    s = geo.addPoint(0, -1, 0, lc)
    a1 = geo.addCircleArc(s, c, e)
    a2 = geo.addCircleArc(e, c, n)
    a3 = geo.addCircleArc(n, c, w)
    a4 = geo.addCircleArc(w, c, s)
    cut = geo.addLine(n, s)
    right = geo.addPlaneSurface([geo.addCurveLoop([a1, a2, cut])])
    left = geo.addPlaneSurface([geo.addCurveLoop([-cut, a3, a4])])
    geo.mesh.setRecombine(2, right)
    geo.synchronize()
    return right, left


def build(gmsh, name):
    if name == "disk2d":
        half_disks(gmsh)
        return 2
    if name == "ball":
        gmsh.model.occ.addSphere(0, 0, 0, 1)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.6)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.6)
        return 3
    if name == "cylinder":
        right, left = half_disks(gmsh)
        gmsh.model.geo.extrude([(2, right), (2, left)], 0, 0, 0.8, numElements=[2], recombine=True)
        gmsh.model.geo.synchronize()
        return 3
    raise ValueError(name)


def jacobians(gmsh, dim, p):
    tags, coords, _ = gmsh.model.mesh.getNodes()
    position = {int(t): coords[3 * i : 3 * i + 3].tolist() for i, t in enumerate(tags)}
    out = {"dim": dim, "order": p, "num_cells": 0, "types": {}}
    for t in gmsh.model.mesh.getElementTypes(dim):
        element_tags, node_tags = gmsh.model.mesh.getElementsByType(t)
        num_nodes = len(node_tags) // len(element_tags)
        try:
            ename, _, _, _, _, num_primary = gmsh.model.mesh.getElementProperties(t)
        except Exception:
            # Gmsh 4.15 cannot describe prisms of order >= 3 ("FaceClosureFull not
            # implemented"); their shape follows from the node count.
            shapes = {
                (p + 1) * (p + 2) * (p + 3) // 6: ("Tetrahedron", 4),
                (p + 1) ** 3: ("Hexahedron", 8),
                (p + 1) ** 2 * (p + 2) // 2: ("Prism", 6),
            }
            ename, num_primary = shapes[num_nodes]
        local, _ = gmsh.model.mesh.getIntegrationPoints(t, "Gauss" + str(2 * p))
        try:
            _, dets, points = gmsh.model.mesh.getJacobians(t, local)
        except Exception as e:
            # Same Gmsh limitation for prisms of order >= 3: no Jacobians to compare.
            out["types"][str(int(t))] = {
                "name": ename,
                "order": p,
                "skipped": str(e),
                "count": len(element_tags),
            }
            out["num_cells"] += len(element_tags)
            continue
        nq = len(local) // 3
        elements = []
        for k in range(len(element_tags)):
            nodes = node_tags[k * num_nodes : (k + 1) * num_nodes]
            elements.append(
                {
                    "tag": int(element_tags[k]),
                    "corners": [position[int(v)] for v in nodes[:num_primary]],
                    "dets": dets[k * nq : (k + 1) * nq].tolist(),
                    "points": points[3 * k * nq : 3 * (k + 1) * nq].tolist(),
                }
            )
        out["num_cells"] += len(elements)
        out["types"][str(int(t))] = {
            "name": ename,
            "order": p,
            "local_coords": local.tolist(),
            "elements": elements,
        }
    return out


def vtk_rewrite(source, prefix):
    import vtk

    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(source)
    reader.Update()
    grid = reader.GetOutput()
    if grid.GetNumberOfCells() == 0:
        sys.exit(f"{source}: VTK read no cells")

    def write(suffix, configure):
        writer = vtk.vtkXMLUnstructuredGridWriter()
        writer.SetInputData(grid)
        writer.SetFileName(f"{prefix}_{suffix}.vtu")
        configure(writer)
        if writer.Write() != 1:
            sys.exit(f"{prefix}_{suffix}.vtu: VTK failed to write")

    write("default", lambda w: None)
    write("ascii", lambda w: w.SetDataModeToAscii())
    write("base64", lambda w: w.EncodeAppendedDataOn())
    write("binary", lambda w: w.SetDataModeToBinary())
    write("uint32", lambda w: w.SetHeaderTypeToUInt32())
    write("raw", lambda w: w.SetCompressorTypeToNone())
    print(f"{prefix}_*.vtu: {grid.GetNumberOfCells()} cells", flush=True)


def main(argv):
    if len(argv) >= 2 and argv[0] == "gmsh":
        orders = [1, 2, 3, 4]
        if "--orders" in argv:
            orders = [int(o) for o in argv[argv.index("--orders") + 1 :]]
        gmsh_meshes(argv[1], orders)
    elif len(argv) == 3 and argv[0] == "vtk":
        vtk_rewrite(argv[1], argv[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
