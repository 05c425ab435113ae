"""Material profiles: datasheet and measured (printed) properties with provenance.

A measured value always records its source and test conditions. `Material.modulus()` prefers
the measured printed modulus and says which one it used. The net-panel law of a material is
piecewise linear in strain: tangent panel stiffness kappa (N/m per m) on each segment between
knee strains, measured on a panel of length L_p in the loading direction (reference, section 2:
kappa divides an elongation, so the membrane stiffness per unit width is kappa * L_p).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from printgen.errors import ProfileError
from printgen.inputs.laws import piecewise_linear
from printgen.inputs.profiles import list_profiles, load_raw
from printgen.inputs.schema import Field, positive, read_table

# Materials one selection or design search weighs at most: each costs ~3 ms in select and a
# grid of sections in the search (benchmarks/measurements.md#calibrate-limits).
MAX_MATERIALS = 100

PROVENANCE = [
    Field("source", str, help="where the value comes from", multiline=True),
    Field("conditions", str, help="specimen and test conditions", multiline=True),
    Field("date", str, required=False),
    Field("files", list, required=False, default=[]),
    Field("n_samples", int, lo=1, required=False),
    Field("correction", str, required=False),
    Field("fit_window_percent", list, required=False),
]
MEASURED_MODULUS = [positive("value_gpa", 500.0), positive("sd_gpa", 500.0, required=False),
                    *PROVENANCE]
MEASURED_STRESS = [positive("value_mpa", 5000.0), positive("sd_mpa", 5000.0, required=False),
                   *PROVENANCE]
PANEL_LAW = [
    Field("knee_strain_percent", list, default=[], required=False),
    Field("kappa_kn_per_m_per_m", list),
    positive("panel_length_mm", 1e4),
    positive("panel_width_mm", 1e4, required=False),
    # Geometry of the tested net, so the law can be rescaled to another strand or mesh.
    positive("strand_width_mm", 100.0, required=False),
    positive("strand_thickness_mm", 100.0, required=False),
    positive("mesh_along_load_mm", 1e4, required=False),
    positive("mesh_across_load_mm", 1e4, required=False),
    # How the source held the panel between its clamps: "free" (a tensile test of a printed
    # panel, its sides unsupported) or "blocked" (transverse displacement held, as the
    # prototype's 1.33 m panel); the reading of the law is checked against that test.
    Field("test_mode", str, choices=("free", "blocked"), required=False, default="free",
          help="free: the panel's sides unsupported between the clamps (a plain tensile "
               "test); blocked: its transverse displacement held"),
    *PROVENANCE,
]
DATASHEET = [
    positive("tensile_modulus_gpa", 500.0), positive("failure_stress_mpa", 5000.0),
    Field("source", str, help="manufacturer, product, document and its date"),
    Field("test_standard", str, required=False, default="",
          help="the datasheet's test standard, e.g. ISO 527 or ASTM D638"),
    Field("modulus_basis", str, required=False, default="",
          help="how the modulus was read off the datasheet when it is not a tensile modulus"),
    positive("elongation_at_break_percent", 5000.0, required=False, si=False),
    Field("shore_hardness_a", float, lo=0.0, hi=100.0, required=False, si=False),
    Field("plausible_modulus_gpa", list, required=False, default=[],
          help="[low, high] modulus a printed strand of this material can have (GPa): the "
               "range a panel law's reading is checked against"),
    Field("plausible_modulus_source", str, required=False, default="",
          help="where the plausible modulus range comes from"),
]
PRINT = [
    Field("source", str, required=False, default="",
          help="where the print settings come from (datasheet, or which are printgen's)"),
    Field("filament_type", str, si=False),
    positive("nozzle_temperature_deg_c", 500.0, si=False),
    positive("first_layer_nozzle_temperature_deg_c", 500.0, si=False),
    Field("bed_temperature_deg_c", float, lo=0.0, hi=150.0, si=False),
    Field("first_layer_bed_temperature_deg_c", float, lo=0.0, hi=150.0, si=False),
    positive("max_volumetric_flow_mm3_per_s", 100.0, si=False),
    positive("print_speed_mm_per_s", 500.0, si=False),
    positive("first_layer_speed_mm_per_s", 500.0, si=False),
    Field("fan_min_percent", float, lo=0.0, hi=100.0, si=False),
    Field("fan_max_percent", float, lo=0.0, hi=100.0, si=False),
    Field("retract_length_mm", float, lo=0.0, hi=20.0, si=False),
    positive("retract_speed_mm_per_s", 200.0, si=False),
]
TOP = [
    Field("name", str),
    Field("description", str, required=False, default="", multiline=True),
    Field("family", str, choices=("rigid", "flexible")),
    positive("density_g_per_cm3", 25.0),
    Field("datasheet", dict),
    Field("measured", dict, required=False, default={}),
    Field("print", dict),
]


@dataclass(frozen=True)
class Measured:
    """A measured property: value in SI (Pa), with provenance."""

    value: float
    source: str
    conditions: str
    sd: float | None = None
    n_samples: int | None = None
    date: str | None = None
    files: tuple[str, ...] = ()
    fit_window_percent: tuple[float, ...] | None = None
    correction: str | None = None


@dataclass(frozen=True)
class PanelLaw:
    """Piecewise-linear net-panel law.

    knee_strains : (k,) strain where the tangent stiffness changes
    kappas : (k+1,) tangent panel stiffness, N/m per m, on each segment
    panel_length, panel_width : m, the tested panel
    """

    knee_strains: tuple[float, ...]
    kappas: tuple[float, ...]
    panel_length: float
    panel_width: float | None
    source: str
    conditions: str
    strand_width: float | None = None  # m, tested net's strand
    strand_thickness: float | None = None  # m
    mesh_along_load: float | None = None  # m, mesh diagonal along the load
    mesh_across_load: float | None = None  # m
    test_mode: str = "free"  # "free" or "blocked" between the clamps, as the source ran it

    @property
    def has_geometry(self) -> bool:
        return None not in (self.strand_width, self.strand_thickness,
                            self.mesh_along_load, self.mesh_across_load)

    def force_per_width(self, strain: np.ndarray | float) -> np.ndarray:
        """Panel force per unit width (N/m) at `strain`; zero in compression."""
        slopes = [k * self.panel_length for k in self.kappas]  # N/m per unit strain
        return piecewise_linear(strain, self.knee_strains, slopes)

@dataclass(frozen=True)
class PrintSettings:
    """Per-material print settings in file units (degC, mm/s, mm^3/s, mm, %)."""

    filament_type: str
    nozzle_temperature_deg_c: float
    first_layer_nozzle_temperature_deg_c: float
    bed_temperature_deg_c: float
    first_layer_bed_temperature_deg_c: float
    max_volumetric_flow_mm3_per_s: float
    print_speed_mm_per_s: float
    first_layer_speed_mm_per_s: float
    fan_min_percent: float
    fan_max_percent: float
    retract_length_mm: float
    retract_speed_mm_per_s: float
    source: str = ""


@dataclass(frozen=True)
class Datasheet:
    """What a datasheet states besides modulus and strength (file units; None: not stated)."""

    test_standard: str = ""
    modulus_basis: str = ""
    elongation_at_break_percent: float | None = None
    shore_hardness_a: float | None = None
    plausible_modulus: tuple[float, float] | None = None  # Pa, a printed strand's (low, high)
    plausible_modulus_source: str = ""


@dataclass(frozen=True)
class Material:
    """A polymer: datasheet values (SI), measured printed values, print settings."""

    key: str
    name: str
    family: str
    density: float  # kg/m^3
    datasheet_modulus: float  # Pa
    datasheet_failure_stress: float  # Pa
    datasheet_source: str
    print: PrintSettings
    measured_modulus: Measured | None = None
    measured_failure_stress: Measured | None = None
    panel_law: PanelLaw | None = None
    description: str = ""
    files: tuple[Path, ...] = field(default=())
    sheet: Datasheet = field(default=Datasheet())

    def modulus(self) -> tuple[float, str]:
        """(E in Pa, 'measured' or 'datasheet'), measured preferred."""
        if self.measured_modulus is not None:
            return self.measured_modulus.value, "measured"
        return self.datasheet_modulus, "datasheet"

    def failure_stress(self) -> tuple[float, str]:
        """(failure stress in Pa, 'measured' or 'datasheet'), measured preferred."""
        if self.measured_failure_stress is not None:
            return self.measured_failure_stress.value, "measured"
        return self.datasheet_failure_stress, "datasheet"


def load_material(name: str) -> Material:
    """Load and validate the material profile `name` (with its inherits chain)."""
    data, files = load_raw("materials", name)
    where = str(files[0])
    top = read_table(data, TOP, where=where)
    sheet = read_table(top["datasheet"], DATASHEET, where=f"{where} [datasheet]")
    measured = top["measured"]
    allowed = {"tensile_modulus", "failure_stress", "panel_law"}
    unknown = sorted(set(measured) - allowed)
    if unknown:
        raise ProfileError(f"{where} [measured]: unknown table {unknown[0]!r}; "
                           f"allowed: {', '.join(sorted(allowed))}")
    return Material(
        key=files[0].stem,
        name=top["name"],
        family=top["family"],
        density=top["density"],
        datasheet_modulus=sheet["tensile_modulus"],
        datasheet_failure_stress=sheet["failure_stress"],
        datasheet_source=sheet["source"],
        print=PrintSettings(**read_table(top["print"], PRINT, where=f"{where} [print]")),
        measured_modulus=_measured(measured, "tensile_modulus", MEASURED_MODULUS, where),
        measured_failure_stress=_measured(measured, "failure_stress", MEASURED_STRESS, where),
        panel_law=_panel_law(measured.get("panel_law"), where),
        description=top["description"],
        files=tuple(files),
        sheet=Datasheet(sheet["test_standard"], sheet["modulus_basis"],
                        sheet["elongation_at_break_percent"], sheet["shore_hardness_a"],
                        _modulus_range(sheet["plausible_modulus_gpa"], where),
                        sheet["plausible_modulus_source"]),
    )


def _measured(measured: dict, key: str, fields: list[Field], where: str) -> Measured | None:
    if key not in measured:
        return None
    t = read_table(measured[key], fields, where=f"{where} [measured.{key}]")
    window = t["fit_window_percent"]
    return Measured(
        value=t["value"], sd=t["sd"], source=t["source"], conditions=t["conditions"],
        n_samples=t["n_samples"], date=t["date"], files=tuple(t["files"]),
        fit_window_percent=tuple(window) if window else None, correction=t["correction"],
    )


def _panel_law(raw: dict | None, where: str) -> PanelLaw | None:
    if raw is None:
        return None
    loc = f"{where} [measured.panel_law]"
    t = read_table(raw, PANEL_LAW, where=loc)
    knees = [_number(v, loc, "knee_strain_percent") / 100.0 for v in t["knee_strain_percent"]]
    kappas = [_number(v, loc, "kappa_kn_per_m_per_m") * 1e3 for v in t["kappa_kn_per_m_per_m"]]
    if len(kappas) != len(knees) + 1:
        raise ProfileError(f"{loc}: {len(kappas)} kappa values for {len(knees)} knees; "
                           "give one kappa per segment (knees + 1)")
    if any(b <= a for a, b in zip([0.0, *knees], knees, strict=False)) or min(kappas) <= 0:
        raise ProfileError(f"{loc}: knee strains must increase from 0 and kappas be > 0")
    return PanelLaw(tuple(knees), tuple(kappas), t["panel_length"], t["panel_width"],
                    t["source"], t["conditions"], t["strand_width"], t["strand_thickness"],
                    t["mesh_along_load"], t["mesh_across_load"], t["test_mode"])


def _modulus_range(raw: list, where: str) -> tuple[float, float] | None:
    """[low, high] GPa of [datasheet] plausible_modulus_gpa in Pa, or None when not given."""
    if not raw:
        return None
    key = "plausible_modulus_gpa"
    values = [_number(v, f"{where} [datasheet]", key) for v in raw]
    if len(values) != 2 or not 0 < values[0] < values[1]:
        raise ProfileError(f"{where} [datasheet]: {key} = {raw!r} must be [low, high] with "
                           "0 < low < high (GPa)")
    return values[0] * 1e9, values[1] * 1e9


def _number(v: object, where: str, key: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
        raise ProfileError(f"{where}: {key} holds {v!r}, not a finite number")
    return float(v)


def material_names(chosen: tuple[str, ...] | None, preferred: tuple[str, ...] = (),
                   where: str = "--materials") -> tuple[str, ...]:
    """The materials to weigh: `chosen` (the command line), else `preferred` (the prototype's
    [model] materials), else every material profile found; repeats dropped, at most
    MAX_MATERIALS (ProfileError beyond, before any is loaded)."""
    names = tuple(dict.fromkeys(chosen or preferred or list_profiles("materials")))
    if len(names) > MAX_MATERIALS:
        src = where if chosen else "[model] materials" if preferred else "the profile folders"
        raise ProfileError(f"{len(names)} materials to weigh (from {src}); at most "
                           f"{MAX_MATERIALS}: name the few to consider with --materials or "
                           "[model] materials")
    return names

