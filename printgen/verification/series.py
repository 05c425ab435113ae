"""The virtual scale series (Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070, Fig. 2): the
prototype's scene (`printgen.scene.build_scene`) rebuilt at 1:lambda
(`printgen.scene.scaled`) for several stiffness rows, each solved under a load case of
`printgen.barrier.loads` up to one relative loading, and read as normalised deformations
(deflection / width, lowering / height, mid-height elongation).

Rows (`Row`): how the strands' axial stiffness goes with lambda while every length is
divided by lambda (nodes, mesh, strand diameter d, so the section A by lambda^2):
- "unscaled": the prototype's laws with its own material, E A / lambda^2 (Froude-only
  practice, the one the paper criticises);
- "similitude": E / lambda, so E A / lambda^3 like every force (identical at every scale);
- a material profile: its tensile modulus (measured when profiled, else the datasheet) on the
  prototype's sections scaled, E_m pi/4 (d / lambda)^2, for the net and the border cables;
  a prototype panel law is replaced by that linear law (stated in the row).
The loads scale by Froude (the load case's own: rho g (h - z) A* with A* / lambda^2, drag at
v / sqrt(lambda) on d / lambda), the hold of unloaded nodes (a share of rho g A*) as lambda^-2.

A case (row, lambda) is a pure task `solve_case(shared, case)`, so the same series gives the
same numbers serially or on a Dask cluster (`printgen.executor.Runner`). The prototype is
solved first (`prototype_states`), with the unscaled row beside it (`starts_cold`): every other
case starts each level from the prototype's converged state scaled by 1 / lambda as well as
from its own path (the solver keeps the start of lowest potential), so the similitude row, the
prototype scaled exactly, converges at once and the materials start near their answer; the
answer is the same to the solver's tolerance. The
similitude row at lambda = 1 is the prototype's own scene: it is solved once (`same_case`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from printgen.barrier.loads import Site, get_load
from printgen.errors import InputError
from printgen.inputs.materials import load_material
from printgen.inputs.profiles import profile_name
from printgen.inputs.prototype import Prototype
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scaled import at_scale
from printgen.scene.scenes import (
    MOUNTINGS,
    ORIENTATIONS,
    PRESSURES,
    PROTOTYPE_ORIENTATION,
    BarrierScene,
)
from printgen.solver import linear
from printgen.units import RHO_WATER, G
from printgen.verification.preprint import levels, sweep

SCALES = (1.0, 10.0, 30.0, 50.0, 100.0)  # the paper's series (Lambert et al. 2023, Fig. 2)
OUTPUTS = {"deflection": "mid-height deflection / width",
           "lowering": "top-centre lowering / height",
           "strain_mid": "mid-height elongation (strain)"}
LEVEL = 1.0  # relative loading read: water depth = barrier height (the paper's series)
LEVEL_STEP = 0.25  # load path steps up to LEVEL (the solver is warm-started along it)
SCALE_MAX = 1000.0  # beyond this the model is smaller than a printed strand is wide


@dataclass(frozen=True)
class Row:
    """One row of the series: `kind` "unscaled", "similitude" or "material" (then `modulus` Pa
    of material `key`, from `source`)."""

    key: str
    label: str
    kind: str
    short: str
    modulus: float | None = None
    source: str = ""

    def to_record(self) -> dict:
        return {"key": self.key, "label": self.label, "kind": self.kind,
                "modulus_gpa": None if self.modulus is None else self.modulus / 1e9,
                "source": self.source}


@dataclass(frozen=True)
class NetOptions:
    """The solver scene's options (`--solver-net KEY=VALUE,...`): `mounting` of the border
    cables (None: the file's [flume] lateral), `sensors` the three 1 N wires pulling on the
    models (lambda > 1), `pressure` along the flow or normal to the net, `slack` the relative
    initial slack of every strand and cable, `orientation` the panel law's diagonal."""

    mounting: str | None = None
    sensors: bool = False
    pressure: str = "flow"
    slack: float = 0.0
    orientation: str = PROTOTYPE_ORIENTATION

    def to_record(self) -> dict:
        return dataclasses.asdict(self)


NET_KEYS = {"mounting": MOUNTINGS, "sensors": ("on", "off"), "pressure": PRESSURES,
            "orientation": ORIENTATIONS, "slack": None}
SLACK_MAX = 0.2  # relative initial slack above this is no longer a small installation defect


def net_options(text: str | None) -> NetOptions:
    """`--solver-net` text "mounting=eyelets,sensors=on,pressure=normal,slack=0.01" as
    NetOptions; InputError naming the key or value and what is allowed."""
    if not text:
        return NetOptions()
    kw: dict = {}
    for item in (t.strip() for t in text.split(",") if t.strip()):
        key, sep, value = (s.strip() for s in item.partition("="))
        if not sep or key not in NET_KEYS:
            raise InputError(f"--solver-net {item!r}: expected KEY=VALUE with KEY one of "
                             f"{', '.join(NET_KEYS)}, e.g. mounting=eyelets,sensors=on")
        allowed = NET_KEYS[key]
        if allowed is None:
            kw[key] = _slack(value)
        elif value not in allowed:
            raise InputError(f"--solver-net {key}={value!r} is not one of {', '.join(allowed)}")
        else:
            kw[key] = value == "on" if key == "sensors" else value
    return NetOptions(**kw)


def _slack(value: str) -> float:
    try:
        s = float(value)
    except ValueError:
        s = math.nan
    if not 0.0 <= s <= SLACK_MAX:
        raise InputError(f"--solver-net slack={value!r} must be a relative slack from 0 to "
                         f"{SLACK_MAX:g}, e.g. slack=0.01 (1 %)")
    return s


def check_scales(scales: list[float] | tuple[float, ...]) -> tuple[float, ...]:
    """The scales, sorted and distinct; InputError for one <= 0, not finite or > SCALE_MAX."""
    if not scales:
        raise InputError("--scales is empty: give e.g. 1,10,30,50,100")
    for s in scales:
        if not (math.isfinite(s) and 0 < s <= SCALE_MAX):
            raise InputError(f"scale {s:g} must be > 0 and <= {SCALE_MAX:g} (lambda = "
                             "prototype / model; 1 is the prototype), e.g. --scales 1,10,30")
    return tuple(sorted({float(s) for s in scales}))


def rows_for(p: Prototype, materials: list[str] | tuple[str, ...]) -> list[Row]:
    """The unscaled and similitude rows of prototype `p`, then one row per material profile
    (ProfileError for an unknown one, before any solve)."""
    own = (f"{p.net.strand_modulus / 1e9:g} GPa" if p.net.strand_modulus is not None
           else "its panel law")
    rows = [Row("unscaled", f"prototype material unscaled ({own}, Froude only)", "unscaled",
                "The prototype's material"),
            Row("similitude", "E / lambda (similitude)", "similitude", "E / lambda")]
    for name in dict.fromkeys(materials):
        m = load_material(profile_name(name, "--materials"))
        e, how = m.modulus()
        rows.append(Row(name, f"{m.name} {e / 1e9:.3g} GPa ({how})", "material", m.name, e,
                        f"profile materials/{name}: {how} tensile modulus"))
    return rows


@dataclass(frozen=True)
class SeriesShared:
    """What every case of a series reads (sent once to each Dask worker)."""

    prototype: Prototype
    rows: tuple[Row, ...]
    load: str
    net: NetOptions = NetOptions()
    level: float = LEVEL
    level_step: float = LEVEL_STEP
    start: dict[float, np.ndarray] = field(default_factory=dict)  # `prototype_states`


@dataclass(frozen=True)
class CaseResult:
    """One (row, lambda): the OUTPUTS at `level`, their curves over `levels`, the net's
    strand stiffness `ea` (N, first slope), the node load scale `node_load` (N, rho g h_B A*),
    the hold's force share and the solver's iterations."""

    row: str
    scale: float
    values: dict[str, float]
    levels: np.ndarray
    curves: dict[str, np.ndarray]
    ea: float
    node_load: float
    hold_share: float
    iterations: int
    failed: dict[float, str] = field(default_factory=dict)


def scaled_scene(base: BarrierScene, p: Prototype, row: Row, lam: float,
                 sensors: bool = False) -> BarrierScene:
    """`base` (the prototype's scene) at 1:`lam` with `row`'s stiffness (see the module)."""
    if row.kind == "material":
        net_law = linear(row.modulus * math.pi / 4 * (p.net.strand_diameter / lam) ** 2)
        cable = linear(row.modulus * math.pi / 4 * (p.border.diameter / lam) ** 2) \
            if p.border is not None else None
        return at_scale(base, lam, f"{base.name} 1:{lam:g} {row.key}",
                        sensors=sensors and lam > 1, net_law=net_law, cable_law=cable)
    f = lam**-2 if row.kind == "unscaled" else lam**-3
    return at_scale(base, lam, f"{base.name} 1:{lam:g} {row.key}",
                    sensors=sensors and lam > 1, factor=f)


def base_scene(shared: SeriesShared) -> BarrierScene:
    """The prototype's scene with the series' net options."""
    o = shared.net
    return build_scene(shared.prototype, SceneOptions(
        mounting=o.mounting, orientation=o.orientation, load=shared.load, pressure=o.pressure))


PROTOTYPE = ("unscaled", 1.0)  # the prototype's case: every ratio's reference, solved first


def solve_case(shared: SeriesShared, case: tuple[str, float]) -> CaseResult:
    """Solve one (row key, lambda) of the series: pure, the same in any process (one BLAS
    thread, so the same sums everywhere), warm-started from `shared.start`."""
    return _solved(shared, case, keep=False)[0]


def prototype_states(shared: SeriesShared) -> tuple[CaseResult, dict[float, np.ndarray]]:
    """The prototype's case and its converged displacements (m) at every level: the warm
    start of the other cases (`SeriesShared.start`)."""
    return _solved(shared, PROTOTYPE, keep=True)


def solve_cold(shared: SeriesShared, case: tuple[str, float]
               ) -> tuple[CaseResult, dict[float, np.ndarray]]:
    """A case solved from its own path alone, beside the prototype's (`starts_cold`), its
    states kept when it is the prototype's (`prototype_states`): a pure task."""
    return _solved(dataclasses.replace(shared, start={}), case, keep=case == PROTOTYPE)


def starts_cold(shared: SeriesShared, case: tuple[str, float]) -> bool:
    """True for the prototype and the unscaled row: its nets, E A / lambda^2 against loads /
    lambda^3, are stiffer than the prototype's, whose scaled state is no nearer their answer
    than their own path (82 against 84 Newton iterations at 1:10 on the paper's series, 115
    against 119 at 1:100), so they run beside the prototype, not after it."""
    return case == PROTOTYPE or next(r.kind for r in shared.rows if r.key == case[0]) \
        == "unscaled"


def same_case(shared: SeriesShared, case: tuple[str, float]) -> tuple[str, float] | None:
    """The case whose scene is `case`'s (the similitude row at lambda = 1 is the prototype:
    E / 1, every length / 1), whose result it takes; None when it has its own."""
    return PROTOTYPE if case == ("similitude", 1.0) else None


def _solved(shared: SeriesShared, case: tuple[str, float], keep: bool
            ) -> tuple[CaseResult, dict[float, np.ndarray]]:
    from threadpoolctl import threadpool_limits

    key, lam = case
    row = next(r for r in shared.rows if r.key == key)
    p = shared.prototype
    s = scaled_scene(base_scene(shared), p, row, lam, shared.net.sensors)
    site = Site(p.velocity / math.sqrt(lam), p.net.strand_diameter / lam, p.depth / lam,
                None, lam)  # the flow spans the barrier's own width at every scale
    lv = levels(step=shared.level_step, top=shared.level)
    start = shared.start

    def guesses(r: float) -> list[np.ndarray]:  # lengths, so displacements, go as 1 / lambda
        u = start.get(float(r))
        return [] if u is None else [u / lam]

    with threadpool_limits(limits=1):
        run = sweep(s, lv, slack=shared.net.slack, load=get_load(shared.load), site=site,
                    guesses=guesses if start else None, keep_states=keep)
    d = run.deformation
    values = {k: float(d.values[k][-1]) if d.levels[-1] == lv[-1] else math.nan
              for k in OUTPUTS}
    return CaseResult(key, lam, values, d.levels, {k: d.values[k] for k in OUTPUTS},
                      float(s.laws[0].slopes[0]), RHO_WATER * G * s.height * s.area_per_node,
                      run.hold_share, int(sum(run.iterations)), dict(run.failed)), run.states


def cases(shared: SeriesShared, scales: tuple[float, ...]) -> list[tuple[str, float]]:
    """Every (row key, lambda) of the series, row by row, with the prototype itself
    ("unscaled" at lambda = 1, the reference of every ratio) first when the series lacks it."""
    own = [] if 1.0 in scales else [("unscaled", 1.0)]
    return own + [(r.key, lam) for r in shared.rows for lam in scales]
