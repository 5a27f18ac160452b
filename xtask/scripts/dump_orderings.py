#!/usr/bin/env python3
"""Dump the node orderings of Gmsh's and VTK's complete high-order elements.

Ground truth for `crates/io/src/ordering.rs`: the orderings are read from the
real libraries, not re-derived. Run from the repository root:

    python3 -m venv target/pyenv && target/pyenv/bin/pip install gmsh vtk
    target/pyenv/bin/python xtask/scripts/dump_orderings.py

It writes crates/io/tests/data/orderings_gmsh.json and orderings_vtk.json.
Every node is given by its *lattice index*: the integer coordinates p*xi of
the node in hocurve's reference element (all shapes in the unit box [0, 1]:
triangle (0,0),(1,0),(0,1); quadrilateral/hexahedron [0,1]^d; tetrahedron
the unit simplex; prism = triangle x [0, 1]; line [0, 1]).

Gmsh: `gmsh.model.mesh.getElementProperties(type)` gives the reference nodes
in Gmsh's order (quadrilateral, hexahedron and the prism's third coordinate
live in [-1, 1] there). Gmsh 4.x refuses that call for prisms of order >= 3
("FaceClosureFull not implemented"), although the element types exist and
Gmsh meshes with them; for those the script meshes a single straight prism
equal to the reference prism with `setOrder(p)` and reads back the nodes of
the element in the order Gmsh stores them (that is, writes them to .msh).
Orders 1 and 2 are checked to agree between both ways.

VTK: each Lagrange cell class gives the parametric coordinates of its points
in VTK's order (`GetParametricCoords`, all in [0, 1]). The script checks that
this agrees with the shape functions: N_k(point_k) = 1 and N_k(point_m) = 0.

The output is deterministic (sorted keys, fixed formatting).
"""

import json
import os
import sys

import gmsh
import vtk

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "crates", "io", "tests", "data")

# hocurve shape name -> Gmsh family name for getElementType
GMSH_FAMILY = {
    "line": "Line",
    "triangle": "Triangle",
    "quadrilateral": "Quadrangle",
    "tetrahedron": "Tetrahedron",
    "hexahedron": "Hexahedron",
    "prism": "Prism",
}
# Highest complete order Gmsh defines a type for (GmshDefines.h).
GMSH_MAX_ORDER = {
    "line": 10,
    "triangle": 10,
    "quadrilateral": 10,
    "tetrahedron": 10,
    "hexahedron": 9,
    "prism": 9,
}
VTK_MAX_ORDER = 10


def to_int(v, what):
    r = round(v)
    if abs(v - r) > 1e-6:
        raise SystemExit(f"{what}: {v} is not a lattice coordinate")
    return int(r)


def gmsh_to_lattice(shape, p, x, y, z):
    """Gmsh reference coordinates -> hocurve lattice index."""
    if shape == "line":
        return [to_int((x + 1) * p / 2, shape), 0, 0]
    if shape in ("triangle", "tetrahedron"):
        return [to_int(x * p, shape), to_int(y * p, shape), to_int(z * p, shape)]
    if shape == "quadrilateral":
        return [to_int((x + 1) * p / 2, shape), to_int((y + 1) * p / 2, shape), 0]
    if shape == "hexahedron":
        return [to_int((c + 1) * p / 2, shape) for c in (x, y, z)]
    if shape == "prism":
        return [to_int(x * p, shape), to_int(y * p, shape), to_int((z + 1) * p / 2, shape)]
    raise ValueError(shape)


def gmsh_from_properties(shape, etype, p):
    name, dim, order, n, coords, _ = gmsh.model.mesh.getElementProperties(etype)
    if order != p:
        raise SystemExit(f"Gmsh type {etype} ({name}) has order {order}, expected {p}")
    out = []
    for k in range(n):
        c = list(coords[k * dim:(k + 1) * dim]) + [0.0] * (3 - dim)
        out.append(gmsh_to_lattice(shape, p, *c))
    return out


def gmsh_prism_by_meshing(p):
    """Mesh the reference prism (one element) at order p; return (type, lattice)."""
    gmsh.model.add(f"prism{p}")
    geo = gmsh.model.geo
    pts = [geo.addPoint(*x, 1.0) for x in ((0, 0, 0), (1, 0, 0), (0, 1, 0))]
    lines = [geo.addLine(pts[i], pts[(i + 1) % 3]) for i in range(3)]
    surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    for l in lines:
        geo.mesh.setTransfiniteCurve(l, 2)
    geo.mesh.setTransfiniteSurface(surf)
    geo.extrude([(2, surf)], 0, 0, 1, [1], recombine=True)
    geo.synchronize()
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(p)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    where = {int(t): i for i, t in enumerate(tags)}
    types, etags, enodes = gmsh.model.mesh.getElements(3)
    if len(types) != 1 or len(etags[0]) != 1:
        raise SystemExit(f"prism p={p}: expected one element, got {types} {etags}")
    lattice = []
    for t in enodes[0]:
        i = where[int(t)]
        x, y, z = coords[3 * i:3 * i + 3]
        lattice.append([to_int(x * p, "prism"), to_int(y * p, "prism"), to_int(z * p, "prism")])
    # The mesh must be the reference prism itself, vertices in reference order.
    expect = [[0, 0, 0], [p, 0, 0], [0, p, 0], [0, 0, p], [p, 0, p], [0, p, p]]
    if lattice[:6] != expect:
        raise SystemExit(f"prism p={p}: meshed element is not the reference prism: {lattice[:6]}")
    gmsh.model.remove()
    return int(types[0]), lattice


def dump_gmsh():
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    result = {"source": f"gmsh {gmsh.__version__}", "types": {}, "lattice": {}}
    for shape, family in GMSH_FAMILY.items():
        result["types"][shape] = {}
        result["lattice"][shape] = {}
        for p in range(1, GMSH_MAX_ORDER[shape] + 1):
            if shape == "prism":
                etype, lattice = gmsh_prism_by_meshing(p)
                if p <= 2:
                    ref = gmsh_from_properties(shape, gmsh.model.mesh.getElementType(family, p), p)
                    if ref != lattice:
                        raise SystemExit(f"prism p={p}: meshing and getElementProperties disagree")
            else:
                etype = gmsh.model.mesh.getElementType(family, p)
                lattice = gmsh_from_properties(shape, etype, p)
            result["types"][shape][str(p)] = etype
            result["lattice"][shape][str(p)] = lattice
    gmsh.finalize()
    return result


VTK_CELLS = {
    "line": vtk.vtkLagrangeCurve,
    "triangle": vtk.vtkLagrangeTriangle,
    "quadrilateral": vtk.vtkLagrangeQuadrilateral,
    "tetrahedron": vtk.vtkLagrangeTetra,
    "hexahedron": vtk.vtkLagrangeHexahedron,
    "prism": vtk.vtkLagrangeWedge,
}
NUM_NODES = {
    "line": lambda p: p + 1,
    "triangle": lambda p: (p + 1) * (p + 2) // 2,
    "quadrilateral": lambda p: (p + 1) ** 2,
    "tetrahedron": lambda p: (p + 1) * (p + 2) * (p + 3) // 6,
    "hexahedron": lambda p: (p + 1) ** 3,
    "prism": lambda p: (p + 1) ** 2 * (p + 2) // 2,
}


def vtk_cell(shape, p):
    n = NUM_NODES[shape](p)
    cell = VTK_CELLS[shape]()
    cell.GetPointIds().SetNumberOfIds(n)
    cell.GetPoints().SetNumberOfPoints(n)
    for i in range(n):
        cell.GetPointIds().SetId(i, i)
        cell.GetPoints().SetPoint(i, 0.0, 0.0, 0.0)
    if shape == "quadrilateral":
        cell.SetOrder(p, p)
    elif shape == "hexahedron":
        cell.SetOrder(p, p, p)
    elif shape == "prism":
        cell.SetOrder(p, p, p, n)
    cell.Initialize()
    return cell, n


def vtk_lattice(shape, p):
    cell, n = vtk_cell(shape, p)
    pc = cell.GetParametricCoords()
    lattice = [[to_int(pc[3 * k + d] * p, shape) for d in range(3)] for k in range(n)]
    if len({tuple(l) for l in lattice}) != n:
        raise SystemExit(f"VTK {shape} p={p}: repeated parametric coordinates")
    # Cross-check with the shape functions VTK actually evaluates.
    weights = [0.0] * n
    for k, l in enumerate(lattice):
        cell.InterpolateFunctions([c / p for c in l], weights)
        for m, w in enumerate(weights):
            if abs(w - (1.0 if m == k else 0.0)) > 1e-8:
                raise SystemExit(
                    f"VTK {shape} p={p}: N_{m} at point {k} is {w}: parametric "
                    "coordinates disagree with the shape functions")
    return lattice


def dump_vtk():
    result = {"source": f"vtk {vtk.vtkVersion.GetVTKVersion()}", "lattice": {}}
    for shape in VTK_CELLS:
        result["lattice"][shape] = {str(p): vtk_lattice(shape, p)
                                    for p in range(1, VTK_MAX_ORDER + 1)}
    return result


def write(name, data):
    path = os.path.join(OUT, name)
    # One node per line keeps diffs readable and the file easy to hand-parse.
    lines = ["{", f'  "source": {json.dumps(data["source"])},']
    if "types" in data:
        lines.append('  "types": {')
        shapes = list(data["types"])
        for i, shape in enumerate(shapes):
            items = ", ".join(f'"{p}": {t}' for p, t in data["types"][shape].items())
            lines.append(f'    "{shape}": {{{items}}}' + ("," if i + 1 < len(shapes) else ""))
        lines.append("  },")
    lines.append('  "lattice": {')
    shapes = list(data["lattice"])
    for i, shape in enumerate(shapes):
        lines.append(f'    "{shape}": {{')
        orders = list(data["lattice"][shape])
        for j, p in enumerate(orders):
            nodes = ", ".join(f"[{a}, {b}, {c}]" for a, b, c in data["lattice"][shape][p])
            lines.append(f'      "{p}": [{nodes}]' + ("," if j + 1 < len(orders) else ""))
        lines.append("    }" + ("," if i + 1 < len(shapes) else ""))
    lines.append("  }")
    lines.append("}")
    text = "\n".join(lines) + "\n"
    json.loads(text)  # must be valid JSON
    os.makedirs(OUT, exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    print(f"wrote {os.path.relpath(path, ROOT)} ({data['source']})")


def main():
    write("orderings_gmsh.json", dump_gmsh())
    write("orderings_vtk.json", dump_vtk())
    return 0


if __name__ == "__main__":
    sys.exit(main())
