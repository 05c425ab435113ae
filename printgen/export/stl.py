"""Binary STL bytes of a mesh (mm)."""

from __future__ import annotations


def stl_bytes(mesh) -> bytes:
    """Binary STL of a trimesh (units: mm, as every slicer assumes)."""
    from trimesh.exchange.stl import export_stl

    return export_stl(mesh)
