#!/usr/bin/env python3
"""Check a curved mesh written by hocurve against the geometry, with Gmsh as the evaluator.

    target/pyenv/bin/python xtask/scripts/check_cad.py MESH.msh GEOMETRY(.json|.igs|.step) GROUP [--distance-only]

- Every node of every boundary element of physical group GROUP (the curved wall; `*`: of
  every boundary element in the file and of every cell face no other cell shares or that
  lies between two volumes) lies on
  the geometry: for a JSON sphere, | |x - c| - r | (a cylinder: its radial distance minus r;
  a circle: the same in the plane);
  for IGES and STEP, the distance to the nearest
  face of the model as OpenCASCADE (Gmsh's `getClosestPoint`) computes it.
- det J of every cell, by Gmsh's `getJacobians`, at the degree-2p Gauss points and at the
  element's own nodes, is positive; Ĩ = min det J / max det J over those points. For 2D
  cells Gmsh's determinant is unsigned, so the signed one is formed from its Jacobian
  matrices (the mesh is counter-clockwise in the xy plane).

Prints one JSON line {"max_distance", "size", "invalid", "min_scaled_jacobian", "elements"};
exits 1 if a node is farther than 1e-10 x the model size or an element has det J <= 0.
`--distance-only` leaves det J out ("invalid" and "min_scaled_jacobian" null): Gmsh 4.15
cannot evaluate complete prisms beyond order 2, whose det J `check_vtu.py` then checks.
"""

import json
import sys

import gmsh
import numpy as np


def main():
    mesh_path, geometry_path, group = sys.argv[1:4]
    distance_only = sys.argv[4:] == ["--distance-only"]
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    if distance_only:
        # Gmsh refuses to open such files at all: read the nodes from the text.
        dim, points, elements = read_msh41(mesh_path, group)
        gmsh.model.add("empty")
        distance, size = distances(geometry_path, points, dim == 2)
        invalid, min_scaled = None, None
    else:
        gmsh.open(mesh_path)
        wall_nodes = group_nodes(group)
        coords = node_coordinates()
        points = np.array([coords[n] for n in sorted(wall_nodes)])
        distance, size = distances(geometry_path, points, gmsh.model.getDimension() == 2)
        invalid, min_scaled, elements = jacobians()
    gmsh.finalize()
    result = {
        "max_distance": float(distance.max()) if len(distance) else 0.0,
        "size": size,
        "wall_nodes": len(points),
        "invalid": invalid,
        "min_scaled_jacobian": min_scaled,
        "elements": elements,
    }
    print(json.dumps(result))
    ok = result["max_distance"] <= 1e-10 * size and not invalid
    sys.exit(0 if ok else 1)


def group_nodes(name):
    if name == "*":
        # Every boundary element the file holds (meshes without physical groups), and the
        # faces (edges in 2D) of the cells that no other cell shares: a file saved with a
        # physical group on the volume alone holds no boundary elements.
        nodes = set()
        for dim, entity in gmsh.model.getEntities(gmsh.model.getDimension() - 1):
            _, _, element_nodes = gmsh.model.mesh.getElements(dim, entity)
            for block in element_nodes:
                nodes.update(int(n) for n in block)
        return nodes | uncovered_facet_nodes()
    for dim, tag in gmsh.model.getPhysicalGroups():
        if gmsh.model.getPhysicalName(dim, tag) == name:
            nodes = set()
            for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                _, _, element_nodes = gmsh.model.mesh.getElements(dim, entity)
                for block in element_nodes:
                    nodes.update(int(n) for n in block)
            return nodes
    raise SystemExit(f"no physical group {name!r}")


def uncovered_facet_nodes():
    """The nodes, by Gmsh's own face (2D: edge) nodes of each cell, of the facets on the
    boundary of a model entity: those of one cell, and those between cells of two
    entities (two volumes' interface)."""
    dim = gmsh.model.getDimension()
    facets = []
    for _, entity in gmsh.model.getEntities(dim):
        for etype in gmsh.model.mesh.getElementTypes(dim, entity):
            for kind in ((3, 4) if dim == 3 else (2,)):
                if dim == 3:
                    corners = gmsh.model.mesh.getElementFaceNodes(etype, kind, entity, True)
                    full = gmsh.model.mesh.getElementFaceNodes(etype, kind, entity, False)
                else:
                    corners = gmsh.model.mesh.getElementEdgeNodes(etype, entity, True)
                    full = gmsh.model.mesh.getElementEdgeNodes(etype, entity, False)
                per = kind if dim == 3 else 2
                count = len(corners) // per
                if count == 0:
                    continue
                corners = np.asarray(corners).reshape(count, per).tolist()
                full = np.asarray(full).reshape(count, -1).tolist()
                facets.extend((tuple(sorted(c)), entity, f) for c, f in zip(corners, full))
    owners = {}
    for key, entity, _ in facets:
        owners.setdefault(key, []).append(entity)
    return {int(n) for key, _, full in facets
            if len(owners[key]) == 1 or len(set(owners[key])) > 1 for n in full}


def read_msh41(path, group):
    """An ASCII MSH 4.1 file by hand: the mesh dimension, the coordinates of the nodes of the
    elements of physical group `group` (one dimension below the mesh), the cell count."""
    with open(path) as f:
        lines = f.read().split("\n")
    sections, i = {}, 0
    while i < len(lines):
        if lines[i].startswith("$") and not lines[i].startswith("$End"):
            name, start = lines[i][1:], i + 1
            while not lines[i].startswith("$End"):
                i += 1
            sections[name] = lines[start:i]
        i += 1
    tag_of = {}
    for line in sections["PhysicalNames"][1:]:
        d, t, name = line.split(maxsplit=2)
        tag_of[(int(d), name.strip('"'))] = int(t)
    ent = sections["Entities"]
    counts = [int(c) for c in ent[0].split()]
    physical = {}
    row = 1
    for d, count in enumerate(counts):
        for _ in range(count):
            v = ent[row].split()
            row += 1
            at = 4 if d == 0 else 7
            n = int(v[at])
            physical[(d, int(v[0]))] = [int(x) for x in v[at + 1:at + 1 + n]]
    dim = max(d for d, c in enumerate(counts) if c > 0)
    want = tag_of[(dim - 1, group)]
    coords, nodes = {}, sections["Nodes"]
    blocks, row = int(nodes[0].split()[0]), 1
    for _ in range(blocks):
        count = int(nodes[row].split()[3])
        tags = [int(t) for t in nodes[row + 1:row + 1 + count]]
        for k, t in enumerate(tags):
            coords[t] = [float(x) for x in nodes[row + 1 + count + k].split()[:3]]
        row += 1 + 2 * count
    wall, cells, elements = set(), 0, sections["Elements"]
    blocks, row = int(elements[0].split()[0]), 1
    for _ in range(blocks):
        d, entity, _, count = (int(x) for x in elements[row].split())
        if d == dim:
            cells += count
        if d == dim - 1 and want in physical.get((d, entity), []):
            for line in elements[row + 1:row + 1 + count]:
                wall.update(int(x) for x in line.split()[1:])
        row += 1 + count
    return dim, np.array([coords[n] for n in sorted(wall)]), cells


def node_coordinates():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = np.asarray(xyz).reshape(-1, 3)
    return {int(t): xyz[i] for i, t in enumerate(tags)}


def distances(path, points, planar_mesh):
    if path.endswith(".json"):
        with open(path) as f:
            entities = json.load(f)["entities"]
        if len(entities) != 1 or entities[0]["kind"] not in ("sphere", "cylinder", "circle"):
            raise SystemExit("the JSON check knows one sphere, cylinder or circle only")
        e = entities[0]
        r = float(e["radius"])
        if e["kind"] == "circle":
            c = np.array(list(e["center"]) + [0.0], float)[:3]
            planar = (points - c)[:, :2]
            return np.abs(np.linalg.norm(planar, axis=1) - r), 2.0 * r
        if e["kind"] == "sphere":
            c = np.array(e["center"], float)
            return np.abs(np.linalg.norm(points - c, axis=1) - r), 2.0 * r
        # Distance from the (infinite) cylinder's side: |radial part| - r.
        p0, axis = np.array(e["point"], float), np.array(e["axis"], float)
        axis = axis / np.linalg.norm(axis)
        rel = points - p0
        radial = rel - np.outer(rel @ axis, axis)
        return np.abs(np.linalg.norm(radial, axis=1) - r), 2.0 * r
    # IGES, STEP: OpenCASCADE's closest point on each face, in a model of its own.
    gmsh.model.add("geometry")
    gmsh.model.occ.importShapes(path)
    gmsh.model.occ.synchronize()
    # The wall of a 2D mesh is made of curves, that of a 3D mesh of faces.
    dim = 1 if planar_mesh else 2
    faces = [t for _, t in gmsh.model.getEntities(dim)]
    box = gmsh.model.getBoundingBox(-1, -1)
    size = float(np.linalg.norm(np.array(box[3:]) - np.array(box[:3])))
    best = np.full(len(points), np.inf)
    flat = points.reshape(-1)
    for face in faces:
        closest, _ = gmsh.model.getClosestPoint(dim, face, flat)
        d = np.linalg.norm(np.asarray(closest).reshape(-1, 3) - points, axis=1)
        best = np.minimum(best, d)
    # OpenCASCADE's closest point on a curve is ~1e-8 off at the curve's ends: the model's
    # vertices are candidates of their own.
    for _, vertex in gmsh.model.getEntities(0):
        x = np.asarray(gmsh.model.getValue(0, vertex, []))
        best = np.minimum(best, np.linalg.norm(points - x, axis=1))
    gmsh.model.remove()
    gmsh.model.setCurrent(gmsh.model.list()[0])
    return best, size


def jacobians():
    invalid, min_scaled, elements = 0, np.inf, 0
    dim = gmsh.model.getDimension()
    for element_type in gmsh.model.mesh.getElementTypes(dim):
        _, _, order, _, local_nodes, _ = gmsh.model.mesh.getElementProperties(element_type)
        gauss, _ = gmsh.model.mesh.getIntegrationPoints(element_type, "Gauss%d" % (2 * order))
        det_gauss = determinants(element_type, gauss, dim)
        det_nodes = determinants(element_type, pad(local_nodes, dim) if dim == 2 else local_nodes, dim)
        det = np.concatenate([det_gauss, det_nodes], axis=1)
        elements += det.shape[0]
        invalid += int(np.sum(det.min(axis=1) <= 0))
        scaled = det.min(axis=1) / np.abs(det).max(axis=1)
        min_scaled = min(min_scaled, float(scaled.min()))
    return invalid, min_scaled, elements


def pad(points, dim):
    p = np.asarray(points).reshape(-1, dim)
    return np.hstack([p, np.zeros((p.shape[0], 3 - dim))]).reshape(-1)


def determinants(element_type, local, dim):
    jac, det, _ = gmsh.model.mesh.getJacobians(element_type, list(local))
    count = len(local) // 3
    if dim == 2:
        # Gmsh's determinant of a surface element is unsigned (its third column is the
        # normal the first two give): take the signed one of the in-plane 2 x 2 block,
        # columns d/du = (Jxu, Jyu, Jzu) and d/dv; the mesh is counter-clockwise.
        j = np.asarray(jac).reshape(-1, 9)
        return (j[:, 0] * j[:, 4] - j[:, 1] * j[:, 3]).reshape(-1, count)
    return np.asarray(det).reshape(-1, count)


if __name__ == "__main__":
    main()
