"""Every choice of a scene in one frozen record, and the one builder that reads it.

`build_scene(source, options)` builds the prototype's scene (`source` a `Prototype`) or the
printed model's (`source` a `Design`), then applies each model-form option as a transform
that returns a new scene (`printgen.scene.forms`, `printgen.scene.mount`): nothing a caller
holds is ever changed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from printgen.barrier.loads import LoadCase
from printgen.errors import GeometryError
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design
from printgen.scene.forms import BEDS, NET_LAWS, ROUTINGS, held_on_bed, routed, with_derived_law
from printgen.scene.mount import in_free_section
from printgen.scene.scenes import (
    MOUNTINGS,
    PRESSURES,
    PROTOTYPE_ORIENTATION,
    SENSOR_FORCE_N,
    BarrierScene,
    model_scene,
    prototype_scene,
    with_factors,
)
from printgen.scene.waved import with_wave_law


@dataclass(frozen=True)
class SceneOptions:
    """All options of a scene; the defaults are the nominal scene.

    mounting : one of MOUNTINGS (None: the prototype file's [flume] lateral for the prototype,
    the first of MOUNTINGS for a design); orientation : the mesh diagonal the panel law is
    read along ("short", "long"; None: for a design the reading its material can produce,
    `printgen.scaling.reading`; PROTOTYPE_ORIENTATION for the prototype); load : the load
    case the assumptions state (None: hydrostatic);
    pressure : one of PRESSURES; net_law : one of NET_LAWS; bed : one of BEDS; routing : one of
    ROUTINGS; span : m between the lateral supports (None: the printed width);
    net_factor, frame_factor, cable_factor : multipliers on the force laws of the net's
    strands, the printed border frame and the border cables; coarsen : the design's meshes
    this many times coarser, its strands as many times stiffer (the same membrane stiffness
    per unit width); sensor_force : N pulled by each sensor wire (None: the nominal, the
    paper's SENSOR_FORCE_N on the model, read only on the prototype).
    """

    mounting: str | None = None
    orientation: str | None = None
    load: str | LoadCase | None = None
    pressure: str = PRESSURES[0]
    net_law: str = NET_LAWS[0]
    bed: str = BEDS[0]
    routing: str = ROUTINGS[0]
    span: float | None = None
    net_factor: float = 1.0
    frame_factor: float = 1.0
    cable_factor: float = 1.0
    coarsen: int = 1
    sensor_force: float | None = None

    def __post_init__(self) -> None:
        for name, allowed in (("pressure", PRESSURES), ("net_law", NET_LAWS), ("bed", BEDS),
                              ("routing", ROUTINGS)):
            if getattr(self, name) not in allowed:
                raise GeometryError(f"scene option {name} = {getattr(self, name)!r} is not one "
                                    f"of {', '.join(allowed)}")
        if self.coarsen < 1:
            raise GeometryError(f"scene option coarsen = {self.coarsen} must be 1 or more")


NOMINAL = SceneOptions()


def build_scene(source: Prototype | Design, options: SceneOptions = NOMINAL) -> BarrierScene:
    """The scene of the prototype or of the printed model (`source`) with `options`."""
    o = options
    if isinstance(source, Prototype):
        if o.net_law != NET_LAWS[0] or o.coarsen != 1:
            raise GeometryError("the prototype's scene takes neither a derived net law nor a "
                                "coarser mesh (design options)")
        s = prototype_scene(source, mounting=o.mounting,
                            orientation=o.orientation or PROTOTYPE_ORIENTATION, load=o.load,
                            sensor_force=o.sensor_force or 0.0)
    else:
        d = coarsened(source, o.coarsen)
        s = model_scene(d, mounting=o.mounting or MOUNTINGS[0], orientation=o.orientation,
                        load=o.load, sensor_force=SENSOR_FORCE_N if o.sensor_force is None
                        else o.sensor_force)
        if o.net_law == "derived":
            s = with_derived_law(s, d, o.orientation)
        s = with_wave_law(s, source)  # the design's own strands' curve, as stiff per strain
    if (o.net_factor * o.coarsen, o.frame_factor, o.cable_factor) != (1.0, 1.0, 1.0):
        s = with_factors(s, o.net_factor * o.coarsen, o.frame_factor, o.cable_factor)
    if o.pressure != s.pressure:
        s = dataclasses.replace(s, pressure=o.pressure)
    if o.span is not None:
        s = in_free_section(s, o.span)
    if o.bed == "held":
        s = held_on_bed(s)
    return routed(s, o.routing)


def coarsened(d: Design, k: int) -> Design:
    """Design `d` with its net's meshes `k` times coarser (itself when k is 1)."""
    if k == 1:
        return d
    n = d.net
    return dataclasses.replace(d, net=dataclasses.replace(
        n, mesh_x_mm=n.mesh_x_mm * k, mesh_y_mm=n.mesh_y_mm * k))
