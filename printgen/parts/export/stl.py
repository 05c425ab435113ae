"""Binary STL of a part (mm): checked watertight and finite before any byte is written."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from printgen.errors import GeometryError
from printgen.outputs import write_bytes

if TYPE_CHECKING:  # pragma: no cover
    import trimesh


def check_mesh(mesh: trimesh.Trimesh, name: str) -> None:
    """GeometryError unless `mesh` is a non-empty, finite, watertight, outward-facing solid."""
    if len(mesh.faces) == 0:
        raise GeometryError(f"{name}: the mesh has no triangles")
    if not np.all(np.isfinite(mesh.vertices)):
        raise GeometryError(f"{name}: the mesh has non-finite vertex coordinates")
    if not (mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0):
        raise GeometryError(f"{name}: the mesh is not a closed, outward-facing solid "
                            "(a slicer would print it wrongly); rebuild it with "
                            "printgen.parts.geometry.solid")


def stl_bytes(mesh: trimesh.Trimesh, name: str = "part") -> bytes:
    """Binary STL of a trimesh (units: mm, as every slicer assumes)."""
    from trimesh.exchange.stl import export_stl

    check_mesh(mesh, name)
    return export_stl(mesh)


def write_stl(path: str | Path, mesh: trimesh.Trimesh, name: str = "part") -> Path:
    """Write the binary STL atomically (nothing is written if the mesh is rejected)."""
    return write_bytes(path, stl_bytes(mesh, name))
