"""Prototype barrier input files (TOML in `examples/`): geometry, net, border cables, flow, flume.

Every key names its unit; unknown keys are errors listing the allowed keys; every value is
range-checked where it is read. Values are SI in the dataclasses. An optional `[model]` table
holds the lab's choices for the printed model (mesh, pattern, printer, print styles, materials).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from printgen.barrier.patterns import get_pattern, pattern_names, printed_pattern_names
from printgen.errors import GeometryError, InputError
from printgen.inputs.materials import MAX_MATERIALS
from printgen.inputs.profiles import profile_name
from printgen.inputs.schema import Field, load_toml, positive, read_table

DEPTH_OVER_HEIGHT_MAX = 2.0  # flow depth / barrier height: beyond it the barrier is drowned
# Smallest plausible values (file units): far below any real barrier, net or flow, and far
# above the 1e-300 or 5e-324 that would reach the maths as a zero in disguise.
MIN_BARRIER_M = 0.1  # a prototype barrier 10 cm wide or high
MIN_MESH_M = 1e-3  # a 1 mm mesh (real nets: 0.1-0.6 m; the model is printed at 1/lambda)
MIN_DIAMETER_MM = 0.1  # a 0.1 mm strand or cable
MIN_MODULUS_GPA = 1e-3  # 1 MPa: softer than any cable, rope or printed polymer
MIN_PANEL_M = 0.01  # a 1 cm test panel
MIN_VELOCITY_M_PER_S = 0.01  # 1 cm/s: water that barely moves
MIN_DEPTH_M = 0.01  # 1 cm of flow
MIN_DENSITY_KG_PER_M3 = 500.0  # lighter than any water or debris mixture
MIN_FLUME_M = 0.01  # a 1 cm wide flume
MIN_MODEL_MESH_MM = 0.5  # a printed mesh diagonal narrower than one bead of a 0.4 mm nozzle
# The string potentiometers' wire tension: about 1 N in the paper's flume (Lambert et al. 2023);
# 100 N is far beyond any extension sensor a flume model carries.
SENSOR_FORCE_N = 1.0
MAX_SENSOR_N = 100.0

TOP = [Field("name", str),
       Field("description", str, required=False, default="", multiline=True),
       Field("barrier", dict), Field("net", dict), Field("border", dict, required=False),
       Field("flow", dict), Field("flume", dict, required=False),
       Field("model", dict, required=False, default={})]
BARRIER = [positive("width_m", 1000.0, MIN_BARRIER_M), positive("height_m", 100.0, MIN_BARRIER_M),
           Field("anchors", int, lo=0, hi=64, required=False, default=0)]
NET = [
    Field("pattern", str, choices=pattern_names()),  # printgen/barrier/patterns, AS_DRAWN
    positive("mesh_x_m", 10.0, MIN_MESH_M,
             help="mesh diagonal (or square side) across the barrier"),
    positive("mesh_y_m", 10.0, MIN_MESH_M, help="mesh diagonal (or square side) up the barrier"),
    positive("strand_diameter_mm", 1000.0, MIN_DIAMETER_MM),
    positive("strand_modulus_gpa", 500.0, MIN_MODULUS_GPA, required=False),
    Field("pretension_n", float, lo=0.0, hi=1e9, required=False, default=0.0),
    Field("panel_law", dict, required=False),
]
PANEL_LAW = [Field("knee_strain_percent", list, required=False, default=[], items=float),
             Field("kappa_kn_per_m_per_m", list, items=float),
             positive("panel_length_m", 100.0, MIN_PANEL_M),
             Field("source", str, required=False, default="")]
BORDER = [positive("diameter_mm", 1000.0, MIN_DIAMETER_MM),
          positive("modulus_gpa", 500.0, MIN_MODULUS_GPA),
          Field("sliding", bool, required=False, default=True),
          Field("pretension_n", float, lo=0.0, hi=1e9, required=False, default=0.0)]
FLOW = [positive("velocity_m_per_s", 50.0, MIN_VELOCITY_M_PER_S),
        positive("depth_m", 100.0, MIN_DEPTH_M, required=False),
        positive("density_kg_per_m3", 3000.0, MIN_DENSITY_KG_PER_M3, required=False,
                 default=1000.0, si=False)]
LATERAL = ("walls", "eyelets")  # lateral mounting of the barrier in the flume, default first
FLUME = [positive("width_m", 10.0, MIN_FLUME_M), positive("max_discharge_l_per_s", 1e5),
         positive("free_section_m", 10.0, MIN_DEPTH_M, required=False),
         positive("froude_min", 10.0, si=False), positive("froude_max", 10.0, si=False),
         Field("lateral", str, choices=LATERAL, required=False, default=LATERAL[0],
               help="walls: side sheets hold the lateral edges; eyelets: only the cables' ends"),
         Field("sensor_force_n", float, lo=0.0, hi=MAX_SENSOR_N, required=False,
               default=SENSOR_FORCE_N,
               help="pull of each string-potentiometer wire on the model (0: read only)")]
MODEL = [positive("mesh_x_mm", 1000.0, MIN_MODEL_MESH_MM, si=False, required=False,
                  help="printed mesh across (default: the prototype's mesh_x_m scaled)"),
         positive("mesh_y_mm", 1000.0, MIN_MODEL_MESH_MM, si=False, required=False,
                  help="printed mesh up (default: the prototype's mesh_y_m scaled)"),
         Field("pattern", str, required=False, choices=printed_pattern_names(),
               help="pattern of the printed net (default: the prototype's; water-drop: diamond)"),
         Field("printer", str, required=False), Field("net_print", str, required=False),
         Field("cable_print", str, required=False),
         # each entry is checked by _check_profile_names (a name, never a path or a number)
         Field("materials", list, required=False, default=[], max_items=MAX_MATERIALS)]


@dataclass(frozen=True)
class NetSpec:
    """Prototype net (SI). panel_law: (knee strains, kappas N/m/m, panel length m) or None."""

    pattern: str
    mesh_x: float
    mesh_y: float
    strand_diameter: float
    strand_modulus: float | None
    pretension: float
    panel_law: tuple[tuple[float, ...], tuple[float, ...], float] | None


@dataclass(frozen=True)
class BorderSpec:
    diameter: float
    modulus: float
    sliding: bool
    pretension: float


@dataclass(frozen=True)
class FlumeSpec:
    width: float
    max_discharge: float  # m^3/s
    free_section: float | None
    froude_min: float
    froude_max: float
    lateral: str = LATERAL[0]  # walls: lateral edges held along their height; eyelets: ends only
    sensor_force: float = SENSOR_FORCE_N  # N, the pull of each sensor wire on the model


@dataclass(frozen=True)
class ModelPrefs:
    """The lab's choices for the printed model; None means: let printgen choose."""

    mesh_x_mm: float | None = None
    mesh_y_mm: float | None = None
    pattern: str | None = None
    printer: str | None = None
    net_print: str | None = None
    cable_print: str | None = None
    materials: tuple[str, ...] = ()


@dataclass(frozen=True)
class Prototype:
    """A full-scale barrier and its flow (SI)."""

    name: str
    description: str
    width: float
    height: float
    anchors: int
    net: NetSpec
    border: BorderSpec | None
    velocity: float
    depth: float  # flow depth, = height unless given
    density: float
    flume: FlumeSpec | None
    model: ModelPrefs = field(default_factory=ModelPrefs)
    path: Path | None = None


def load_prototype(path: str | Path) -> Prototype:
    """Read and validate a prototype TOML file."""
    p = Path(path)
    where = str(p)
    top = read_table(load_toml(p, "prototype file"), TOP, where=where)
    bar = read_table(top["barrier"], BARRIER, where=f"{where} [barrier]")
    net = read_table(top["net"], NET, where=f"{where} [net]")
    flow = read_table(top["flow"], FLOW, where=f"{where} [flow]")
    law = _panel_law(net["panel_law"], f"{where} [net.panel_law]")
    if law is None and net["strand_modulus"] is None:
        raise InputError(f"{where} [net]: give strand_modulus_gpa or a [net.panel_law] table; "
                         "the net's stiffness is otherwise unknown")
    border = top["border"] and BorderSpec(**read_table(top["border"], BORDER,
                                                       where=f"{where} [border]"))
    flume = top["flume"] and FlumeSpec(**read_table(top["flume"], FLUME, where=f"{where} [flume]"))
    _check_profile_names(top["model"], f"{where} [model]")  # the names' one check, first
    model = read_table(top["model"], MODEL, where=f"{where} [model]") if top["model"] else {}
    if (model.get("mesh_x_mm") is None) != (model.get("mesh_y_mm") is None):
        raise InputError(f"{where} [model]: give both mesh_x_mm and mesh_y_mm, or neither (then "
                         "the prototype's mesh is scaled)")
    depth = flow["depth"] if flow["depth"] is not None else bar["height"]
    if flume and flume.froude_min > flume.froude_max:
        raise InputError(f"{where} [flume]: froude_min = {flume.froude_min:g} is above "
                         f"froude_max = {flume.froude_max:g}; give the flume's range low to high")
    if flume and flume.lateral == "eyelets" and not border:
        raise InputError(f"{where} [flume]: lateral = \"eyelets\" anchors the lateral border "
                         "cables at their eyelets, but the barrier has no [border] cables; set "
                         "lateral = \"walls\" (net anchored on the banks) or add a [border] table")
    if depth > DEPTH_OVER_HEIGHT_MAX * bar["height"]:
        raise InputError(f"{where} [flow]: depth_m = {depth:g} m is more than "
                         f"{DEPTH_OVER_HEIGHT_MAX:g} x the barrier height ({bar['height']:g} m): "
                         "such a flow drowns the barrier, and printgen's loads (hydrostatic up to "
                         f"overflow, h = 1.1 h_B) do not describe it; give a depth up to "
                         f"{DEPTH_OVER_HEIGHT_MAX * bar['height']:g} m")
    for label, mesh in (("mesh_x_m", net["mesh_x"]), ("mesh_y_m", net["mesh_y"])):
        limit = bar["width"] if label == "mesh_x_m" else bar["height"]
        if mesh > limit / 2:
            raise InputError(f"{where} [net]: {label} = {mesh:g} m exceeds half the barrier "
                             f"({limit / 2:g} m); a net needs at least two meshes each way")
    try:
        get_pattern(net["pattern"]).check_mesh(net["mesh_x"], net["mesh_y"], "[net]")
    except GeometryError:
        name = net["pattern"]
        raise InputError(f"{where} [net]: pattern \"{name}\" needs mesh_x_m = mesh_y_m (the "
                         f"{name}'s side), got {net['mesh_x']:g} x {net['mesh_y']:g} m; give "
                         "equal sides") from None
    return Prototype(
        name=top["name"], description=top["description"], width=bar["width"],
        height=bar["height"], anchors=bar["anchors"],
        net=NetSpec(net["pattern"], net["mesh_x"], net["mesh_y"], net["strand_diameter"],
                    net["strand_modulus"], net["pretension"], law),
        border=border or None, velocity=flow["velocity"], depth=depth,
        density=flow["density_kg_per_m3"], flume=flume or None,
        model=ModelPrefs(**{**model, "materials": tuple(model.get("materials") or ())}),
        path=p,
    )


def _check_profile_names(model: object, where: str) -> None:
    """[model] printer, net_print, cable_print and materials name profiles: names, not paths
    (checked on the raw table, before read_table, so that a name is refused by this one rule)."""
    if not isinstance(model, dict):
        return  # read_table names the wrong type
    for key in ("printer", "net_print", "cable_print"):
        if model.get(key) is not None:
            profile_name(model[key], f"{where}: {key}")
    materials = model.get("materials")
    for i, name in enumerate(materials if isinstance(materials, list) else ()):
        profile_name(name, f"{where}: materials[{i}]")


def _panel_law(raw: dict | None, where: str):
    if raw is None:
        return None
    t = read_table(raw, PANEL_LAW, where=where)
    knees, kappas = t["knee_strain_percent"], t["kappa_kn_per_m_per_m"]
    values = [*knees, *kappas]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0 and v < 1e9
               for v in values):
        raise InputError(f"{where}: knee_strain_percent and kappa_kn_per_m_per_m must hold "
                         "positive finite numbers")
    if len(kappas) != len(knees) + 1 or sorted(knees) != list(knees):
        raise InputError(f"{where}: give increasing knees and one kappa per segment "
                         f"(got {len(knees)} knees, {len(kappas)} kappas)")
    return (tuple(k / 100 for k in knees), tuple(k * 1e3 for k in kappas), t["panel_length"])


OPTIONAL_TABLES = ("[net.panel_law]", "[border]", "[flume]", "[model]")  # may be left out
SCHEMA_TABLES = (("", TOP), ("[barrier]", BARRIER), ("[net]", NET),
                 ("[net.panel_law]", PANEL_LAW), ("[border]", BORDER), ("[flow]", FLOW),
                 ("[flume]", FLUME), ("[model]", MODEL))
CROSS_CHECKS = (
    "[net] mesh_x_m <= barrier width / 2 and mesh_y_m <= barrier height / 2 (two meshes each way)",
    "[net] pattern = \"square\": mesh_x_m = mesh_y_m (the square's side)",
    f"[flow] depth_m <= {DEPTH_OVER_HEIGHT_MAX:g} x barrier height_m (deeper flows drown it)",
    "[net.panel_law]: increasing knees, one kappa per segment (knees + 1), all > 0 and < 1e9",
    "[net]: strand_modulus_gpa or a [net.panel_law] is required",
    "[flume] lateral = \"eyelets\" needs a [border] table (the eyelets are the cables' ends)",
    "[flume] froude_min <= froude_max",
    "[model] mesh_x_mm and mesh_y_mm: both or neither (neither: the prototype's mesh scaled)",
    ("a printed square net ([model] pattern, default the prototype's) needs a square mesh "
     "(mesh_x = mesh_y)"),
)


def ranges_markdown() -> str:
    """The user guide's table (docs/user-guide.md) of every key of the prototype schema with its
    range (generated here, and compared with that page by the tests, so the two cannot drift
    apart)."""
    rows = ["| table | key | type | range | required |", "|---|---|---|---|---|"]
    for table, fields in SCHEMA_TABLES:
        for f in fields:
            if f.kind is dict:
                continue
            need = ("no" if not f.required else
                    "when the table is given" if table in OPTIONAL_TABLES else "yes")
            rows.append(f"| {table or '(top)'} | `{f.key}` | {f.kind.__name__} | {_range(f)} | "
                        f"{need} |")
    rows += ["", "Checks across keys:", ""] + [f"- {c}" for c in CROSS_CHECKS]
    return "\n".join(rows) + "\n"


def _range(f: Field) -> str:
    if f.choices:
        return ", ".join(f"`{c}`" for c in f.choices)
    if f.lo is None and f.hi is None:
        return "-"
    lo = "" if f.lo is None else f"{'>' if f.lo_open else '>='} {f.lo:g}"
    hi = "" if f.hi is None else f"<= {f.hi:g}"
    return " and ".join(x for x in (lo, hi) if x)
