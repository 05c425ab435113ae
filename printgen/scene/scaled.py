"""A scene at another scale: the prototype's scene rebuilt at 1:lambda for the virtual scale
series (`printgen.verification.series`), every length divided by lambda, its tributary area
and the hold of unloaded nodes by lambda^2, its laws scaled or replaced as a row of the
series says."""

from __future__ import annotations

import dataclasses

from printgen.scene.scenes import SENSOR_FORCE_N, BarrierScene
from printgen.solver import Law


def at_scale(base: BarrierScene, lam: float, name: str, *, sensors: bool = False,
             factor: float | None = None, net_law: Law | None = None,
             cable_law: Law | None = None) -> BarrierScene:
    """`base` at 1:`lam`, named `name`: every law times `factor`, or (`net_law` given) the net's
    strands of `net_law`, its other strand laws (the border frame) times lam^-2 and its cables of
    `cable_law` (None: their own); the sensor wires pull SENSOR_FORCE_N when `sensors`, else only
    read."""
    if net_law is not None:
        laws = [net_law] + [law.scaled(lam**-2) for law in base.laws[1:]]
        cables = {k: (n, law if cable_law is None else cable_law)
                  for k, (n, law) in base.cables.items()}
    else:
        f = 1.0 if factor is None else factor
        laws = [law.scaled(f) for law in base.laws]
        cables = {k: (n, law.scaled(f)) for k, (n, law) in base.cables.items()}
    force = SENSOR_FORCE_N if sensors else 0.0
    wires = {k: dataclasses.replace(w, exit=w.exit / lam, force=force * w.weight)
             for k, w in base.wires.items()}
    return dataclasses.replace(
        base, name=name, scale=lam, width=base.width / lam, height=base.height / lam,
        nodes=base.nodes / lam, laws=laws, cables=cables,
        area_per_node=base.area_per_node / lam**2, wires=wires, hold=base.hold / lam**2)
