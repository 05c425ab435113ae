"""The reference scenes of barrier-physics.md, section 7, built from numbers (SI)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .laws import linear
from .loads import Drag, Hydrostatic
from .model import Net

# The simple barrier (Lambert et al. 2023): 12 x 4 m, square mesh 0.2 m, d 10 mm, steel
# 100 GPa, flow 6 m/s, water depth = barrier height.
SIMPLE = {"width": 12.0, "height": 4.0, "mesh": 0.2, "diameter": 0.010, "modulus": 100e9,
          "velocity": 6.0}


@dataclass(frozen=True)
class Scene:
    """A net, its load function of relative loading h / h_B, and the nodes outputs refer to."""

    name: str
    net: Net
    loads_at: object  # Callable[[float], list]
    width: float
    height: float
    centre: int  # mid-height centre node
    top_centre: int


def square_net(width: float, height: float, mesh: float):
    """Nodes (n, 3) of a square grid in the x-z plane, elements, shape (nx, nz)."""
    nx, nz = round(width / mesh) + 1, round(height / mesh) + 1
    xs, zs = np.linspace(0, width, nx), np.linspace(0, height, nz)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    nodes = np.column_stack([X.ravel(), np.zeros(X.size), Z.ravel()])
    idx = np.arange(nx * nz).reshape(nx, nz)
    el = np.vstack([np.column_stack([idx[:-1, :].ravel(), idx[1:, :].ravel()]),
                    np.column_stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()])])
    return nodes, el, idx


def simple_scene(*, scale: float = 1.0, modulus: float | None = None, pinned_top: bool = True,
                 refine: int = 1, drag: bool = True, slack: float = 0.0,
                 current_z: bool = True) -> Scene:
    """simple-pinned (pinned_top) or simple-free-top at 1:scale; `refine` halves the mesh
    that many times minus one (1 -> 61 x 21 nodes, 2 -> 121 x 41, 4 -> 241 x 81).

    `loads_at(r)`: hydrostatic to the water level r h plus (`drag`) the drag on the submerged
    nodes, ramped in over one node row below the level, as printgen's drag load case does
    (`solver.Drag` ramp): at full depth and in overflow (r >= 1: every free node a row or more
    below the level) the same as the sharp switch, but a level that sits on a node row no
    longer makes the node's load jump as it moves (the sharp switch made the load path 0 to
    1.1 by 0.05 fail at r = 0.9 on 61 x 21 nodes: no equilibrium within 400 iterations)."""
    s = SIMPLE
    lam = float(scale)
    w, h, a = s["width"] / lam, s["height"] / lam, s["mesh"] / lam / refine
    d = s["diameter"] / lam
    e = s["modulus"] if modulus is None else modulus
    ea = e * math.pi / 4 * (s["diameter"] / lam) ** 2 / refine  # same stiffness per width
    nodes, el, idx = square_net(w, h, a)
    x, z = nodes[:, 0], nodes[:, 2]
    tol = 1e-9 * w
    fixed = (x < tol) | (x > w - tol) | (z < tol)
    if pinned_top:
        fixed |= z > h - tol
    net = Net(nodes, fixed, el, [linear(ea)], slack=slack)
    free = np.flatnonzero(~fixed)
    v = s["velocity"] / math.sqrt(lam)
    z0 = None if current_z else nodes[free, 2]

    def loads_at(r: float) -> list[Hydrostatic | Drag]:
        out: list[Hydrostatic | Drag] = [Hydrostatic(free, a * a, r * h, initial_z=z0)]
        if drag:
            out.append(Drag(free, 2 * a, d / refine, v, r * h, ramp=a))
        return out

    nx, nz = idx.shape
    return Scene("simple-pinned" if pinned_top else "simple-free-top", net, loads_at, w, h,
                 int(idx[nx // 2, nz // 2]), int(idx[nx // 2, nz - 1]))
