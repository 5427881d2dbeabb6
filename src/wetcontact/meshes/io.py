"""meshio <-> scikit-fem: second-order triangle meshes with named boundaries, VTU output.

scikit-fem's own ``from_meshio`` does not match 3-node boundary lines (``line3``) of a
second-order mesh to facets, so the named groups are matched here by their end vertices.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import meshio
import numpy as np
from skfem import MeshTri2

from wetcontact.errors import SolverError


def read_msh(path: str | Path) -> meshio.Mesh:
    """``meshio.read`` of a gmsh file, with meshio's stray blank line on stdout swallowed
    (it would corrupt the CLI's ``--json`` output and tables)."""
    with contextlib.redirect_stdout(io.StringIO()):
        return meshio.read(path)


def to_skfem(m: meshio.Mesh) -> MeshTri2:
    """Quadratic scikit-fem mesh from a gmsh/meshio ``triangle6`` mesh.

    Every named ``line3`` cell set (a gmsh physical group) becomes ``mesh.boundaries[name]``,
    a facet index array. Triangles are reoriented counter-clockwise (gmsh orders them by its
    own surface orientation).
    """
    cells = m.cells_dict
    if "triangle6" not in cells:
        raise SolverError(f"mesh has no 6-node triangles (cells: {sorted(cells)}); "
                          "expected a second-order gmsh mesh")
    p = np.ascontiguousarray(m.points[:, :2].T)
    t = cells["triangle6"].T.copy()
    # counter-clockwise orientation of the vertex triangle
    a, b, c = p[:, t[0]], p[:, t[1]], p[:, t[2]]
    cw = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0
    # swapping vertices 1 and 2 swaps edge nodes 3 (0-1) and 5 (2-0)
    t[:, cw] = t[[0, 2, 1, 5, 4, 3]][:, cw]
    mesh = MeshTri2(p, t)
    # vertex renumbering done by MeshTri2: old vertex ids -> new ids
    old_vertices = np.unique(cells["triangle6"][:, :3])
    new_of_old = np.full(m.points.shape[0], -1, dtype=np.int64)
    new_of_old[old_vertices] = np.arange(old_vertices.size)
    facets = np.sort(mesh.facets, axis=0)
    nv = mesh.nvertices
    facet_key = facets[0].astype(np.int64) * nv + facets[1]
    order = np.argsort(facet_key)
    boundaries: dict[str, np.ndarray] = {}
    for name, sets in m.cell_sets_dict.items():
        if name.startswith("gmsh:") or "line3" not in sets:
            continue
        lines = cells["line3"][sets["line3"]][:, :2]
        ends = np.sort(new_of_old[lines], axis=1)
        key = ends[:, 0] * nv + ends[:, 1]
        pos = np.searchsorted(facet_key[order], key)
        pos = np.clip(pos, 0, order.size - 1)
        found = facet_key[order][pos] == key
        if not found.all() or (ends < 0).any():
            raise SolverError(f"boundary group '{name}': {int((~found).sum())} lines are not "
                              "mesh facets")
        boundaries[name] = np.sort(order[pos]).astype(np.int32)
    return mesh.with_boundaries(boundaries) if boundaries else mesh


def write_vtu(path: Path, mesh: MeshTri2, point_data: dict[str, np.ndarray],
              scale: float = 1.0) -> Path:
    """Write a VTU (ParaView) file: the mesh vertices (times ``scale``) and vertex fields.

    Atomic (:func:`wetcontact.fileio.atomic_output`): a killed writer or a full disk leaves
    the old file or none, never a truncated one.
    """
    from wetcontact.fileio import atomic_output

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nv = int(mesh.t.max()) + 1  # vertices come first in a quadratic skfem mesh
    p = mesh.p[:, :nv]
    pts = np.column_stack([p.T * scale, np.zeros(nv)])
    with atomic_output(path) as tmp:
        meshio.Mesh(pts, [("triangle", mesh.t.T)], point_data=point_data).write(
            tmp, file_format="vtu")
    return path


def write_pvd(path: Path, files: list[tuple[float, Path]], time_name: str = "gap_m") -> Path:
    """Write a ParaView collection (``.pvd``) of VTU files, each with its gap as the time.

    ParaView opens the collection as one data set whose time steps are the gaps (m), in
    increasing order, so its time slider walks through the solved gaps. File names are
    stored relative to the collection's folder (the VTU files are beside it). Atomic, like
    :func:`write_vtu`.

    Parameters
    ----------
    path
        The ``.pvd`` file to write.
    files
        (gap in m, VTU path) pairs; two files at one gap keep their order (``part`` 0, 1).
    time_name
        What the time step is, stated in a comment (ParaView reads no unit).
    """
    import os
    from xml.etree import ElementTree as ET

    from wetcontact.fileio import atomic_write_text

    path = Path(path)
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    root.append(ET.Comment(f" timestep = {time_name} of each file "))
    coll = ET.SubElement(root, "Collection")
    parts: dict[float, int] = {}
    for gap, vtu in sorted(files, key=lambda item: item[0]):
        part = parts[gap] = parts.get(gap, -1) + 1
        rel = os.path.relpath(Path(vtu), path.parent)
        ET.SubElement(coll, "DataSet", timestep=repr(float(gap)), group="", part=str(part),
                      file=Path(rel).as_posix())
    ET.indent(root)
    atomic_write_text(path, '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode")
                      + "\n")
    return path
