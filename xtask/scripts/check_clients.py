#!/usr/bin/env python3
"""Check that the solvers' own readers take every MSH variant hocurve writes.

    python xtask/scripts/check_clients.py REFERENCE.vtu MESH.msh ...

REFERENCE.vtu is hocurve's `.vtu` of the same curved mesh: VTK reads it and
integrates its volume (area in 2D) with its own Lagrange shape functions. Each
MESH.msh (MSH 4.1 or 2.2, ASCII or binary, as the header says) is then read by
- Gmsh (`gmsh.open`): node coordinates, by tag, equal to the `.vtu`'s points
  (hocurve writes node i as tag i + 1 in both) to 1e-15 of the model size, and
  the volume summed from Gmsh's own Jacobians at its Gauss points;
- MFEM (`mfem.ser.Mesh`): the sum of its element volumes (its curved-mesh
  quadrature on the nodal grid function it builds from the file);
- PyFR (`pyfr import`, its Gmsh importer) for ASCII files: the volume summed
  from the `.pyfrm`'s shape points with PyFR's own nodal bases and quadrature
  rules. PyFR 3.1 reads ASCII MSH only (its reader opens the file as text and
  refuses file-type 1), so binary files are reported as not applicable.
Each volume must equal VTK's to a relative 1e-9. Prints one line per reader and
file; exits 1 on any failure.

Needs the client environment (`gmsh vtk numpy mfem pyfr mpich`).
"""

import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_snapshots import measure_grid  # noqa: E402
from check_vtu import read_grid  # noqa: E402

TOL = 1e-9


def msh_header(path):
    with open(path, 'rb') as f:
        f.readline()
        version, filetype, _ = f.readline().split()
    return version.decode(), filetype == b'1'


def gmsh_read(path, points):
    import gmsh
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber('General.Terminal', 0)
    try:
        gmsh.open(path)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        coords = coords.reshape(-1, 3)
        order = np.argsort(tags)
        tags, coords = tags[order], coords[order]
        if len(tags) != len(points) or np.any(tags != np.arange(1, len(points) + 1)):
            return None, f'node tags are not 1..{len(points)}'
        size = np.ptp(points, axis=0).max()
        gap = np.abs(coords - points).max()
        if gap > 1e-15 * size:
            return None, f'node coordinates differ from the .vtu by {gap:.2e}'
        dim = gmsh.model.getDimension()
        volume = 0.0
        for etype in gmsh.model.mesh.getElementTypes(dim):
            order = gmsh.model.mesh.getElementProperties(etype)[2]
            pts, wts = gmsh.model.mesh.getIntegrationPoints(etype, f'Gauss{3 * order + 2}')
            _, dets, _ = gmsh.model.mesh.getJacobians(etype, pts)
            volume += float(np.sum(dets.reshape(-1, len(wts)) * wts))
        return volume, None
    finally:
        gmsh.finalize()


def mfem_volume(path):
    """The sum over MFEM's elements of its transformation weights (|det J|, from the
    nodal grid function MFEM builds from the file) at its Gauss points, exact for
    det J of a degree-p map (MFEM's GetElementVolume uses a lower order)."""
    import mfem.ser as mfem
    mesh = mfem.Mesh(path, 1, 1)
    nodes = mesh.GetNodes()
    p = nodes.FESpace().GetMaxElementOrder() if nodes is not None else 1
    volume = 0.0
    for i in range(mesh.GetNE()):
        t = mesh.GetElementTransformation(i)
        rule = mfem.IntRules.Get(mesh.GetElementBaseGeometry(i), 3 * p + 2)
        for k in range(rule.GetNPoints()):
            ip = rule.IntPoint(k)
            t.SetIntPoint(ip)
            volume += ip.weight * t.Weight()
    return volume


def pyfr_volume(path):
    import h5py
    from pyfr.polys import get_polybasis
    from pyfr.quadrules import get_quadrule
    from pyfr.shapes import BaseShape
    from pyfr.util import subclass_where
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, 'm.pyfrm')
        pyfr = os.path.join(os.path.dirname(sys.executable), 'pyfr')
        run = subprocess.run([pyfr, 'import', path, out], capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f'pyfr import failed: {run.stderr.strip().splitlines()[-1]}')
        volume = 0.0
        with h5py.File(out) as f:
            nodes = f['nodes']['location']
            for name, eles in f['eles'].items():
                shape = subclass_where(BaseShape, name=name)
                conn = eles['nodes']
                order = shape.order_from_npts(conn.shape[1])
                basis = get_polybasis(name, order + 1, shape.std_ele(order))
                rule = get_quadrule(name, qdeg=min(3 * order + 2, 15))
                dphi = basis.jac_nodal_basis_at(rule.pts)  # (dim, npts, nq)
                x = nodes[conn]  # (ne, npts, dim)
                jac = np.einsum('knq,enj->eqkj', dphi, x[:, :, :shape.ndims])
                volume += float(np.sum(np.linalg.det(jac) * rule.wts))
    return volume


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    reference, meshes = sys.argv[1], sys.argv[2:]
    grid, messages = read_grid(reference)
    if messages or grid.GetNumberOfCells() == 0:
        print(f'FAIL vtk   {reference}: {messages or "no cells read"}')
        return 1
    expected = measure_grid(grid)[0]
    from vtk.util import numpy_support
    points = numpy_support.vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
    print(f'{reference}: VTK volume {expected!r}')
    failed = False

    def verdict(reader, path, volume, note=None):
        nonlocal failed
        if volume is None:
            ok = note.startswith('n/a')
            text = note
        else:
            gap = abs(volume - expected) / abs(expected)
            ok = gap <= TOL
            text = f'volume {volume!r}, relative gap {gap:.1e}'
        failed |= not ok
        print(f"{'ok  ' if ok else 'FAIL'} {reader:5} {os.path.basename(path)}: {text}")

    for path in meshes:
        version, binary = msh_header(path)
        volume, problem = gmsh_read(path, points)
        verdict('gmsh', path, volume, problem)
        try:
            verdict('mfem', path, mfem_volume(path))
        except Exception as e:  # noqa: BLE001 - any reader failure is a finding
            verdict('mfem', path, None, f'{type(e).__name__}: {e}')
        if binary:
            verdict('pyfr', path, None, 'n/a: PyFR 3.1 reads ASCII MSH only')
        else:
            try:
                verdict('pyfr', path, pyfr_volume(path))
            except Exception as e:  # noqa: BLE001
                verdict('pyfr', path, None, f'{type(e).__name__}: {e}')
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
