"""The run's records: what `make` and `verify` computed, kept as the objects themselves, each
knowing its own `to_record()`. report.json is their records; report.html, the summary and the
lab's files are rendered from the same objects (printgen.report.build), never from JSON read
back. Wall-clock times are not in them: they live in the run's timings (timings.json)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from printgen.inputs.prototype import Prototype
    from printgen.parts.assembly import Assembly
    from printgen.parts.gcode.estimate import PrintEstimate
    from printgen.report.html import Drawing
    from printgen.scaling.record import Design
    from printgen.scaling.selection import Candidate, Selection
    from printgen.scaling.similitude import ScaledTargets
    from printgen.verification.bands import Band
    from printgen.verification.measured import Fit, Measurement
    from printgen.verification.preprint import Verification


def record_of(value: Any) -> Any:
    """`value.to_record()` when it has one, a dict's values' records, else `value` (already
    a plain record)."""
    to_record = getattr(value, "to_record", None)
    if callable(to_record):
        return to_record()
    if isinstance(value, dict):
        return {k: record_of(v) for k, v in value.items()}
    return value


@dataclass(frozen=True)
class PlanRecords:
    """Targets, selection and the printed design (`make`'s plan). `design_file`: the name of
    the design.json printed instead of the selection's choice, with `own_net`, its net scored
    like the selection's candidates."""

    prototype: Prototype
    targets: ScaledTargets
    selection: Selection
    design: Design
    design_file: str | None = None
    own_net: Candidate | None = None

    def to_record(self) -> dict[str, Any]:
        """report.json's "targets", "selection", "design" (and "design_file", "design_net")."""
        rec: dict[str, Any] = {"targets": self.targets.to_record(),
                               "selection": self.selection.to_record(),
                               "design": self.design.to_dict()}
        if self.design_file and self.own_net is not None:
            rec["design_file"] = self.design_file
            rec["design_net"] = self.own_net.to_record()  # its own stiffness error
        return rec


@dataclass(frozen=True)
class MeshRecord:
    """One part's mesh as written: its files, its volume and the analytic one (mm^3), its
    size on the bed (mm, x y z), its triangles, and the angle it was turned by on the bed."""

    files: list[str]
    volume_mm3: float
    analytic_volume_mm3: float
    size_mm: np.ndarray
    triangles: int
    watertight: bool
    bed_angle_deg: float

    @property
    def volume_error(self) -> float:
        """The mesh's volume against the analytic one, relative."""
        return self.volume_mm3 / self.analytic_volume_mm3 - 1

    def to_record(self) -> dict[str, Any]:
        return {"files": list(self.files), "volume_mm3": self.volume_mm3,
                "analytic_volume_mm3": self.analytic_volume_mm3,
                "volume_error": self.volume_error, "size_mm": self.size_mm,
                "triangles": self.triangles, "watertight": self.watertight,
                "bed_angle_deg": self.bed_angle_deg}


@dataclass(frozen=True)
class PlateRecord:
    """Parts laid out together on one bed: the file, and each part's angle on it (deg)."""

    files: list[str]
    parts: dict[str, float]

    def to_record(self) -> dict[str, Any]:
        return {"files": list(self.files), "parts": dict(self.parts)}


@dataclass(frozen=True)
class GcodeRecord:
    """One part's direct G-code: its file, layers, the toolpath's volume (mm^3) and the one
    read back from the G-code, relative to it and to the STL's (None: no STL), retractions,
    and the print's estimate."""

    file: str
    layers: int
    volume_mm3: float
    readback_volume_mm3: float
    readback_vs_stl: float | None
    retractions: int
    estimate: PrintEstimate

    @property
    def readback_error(self) -> float:
        return self.readback_volume_mm3 / self.volume_mm3 - 1

    def to_record(self) -> dict[str, Any]:
        return {"file": self.file, "layers": self.layers, "volume_mm3": self.volume_mm3,
                "readback_volume_mm3": self.readback_volume_mm3,
                "readback_error": self.readback_error, "readback_vs_stl": self.readback_vs_stl,
                "retractions": self.retractions, "print": self.estimate.to_record()}


@dataclass(frozen=True)
class KitRecords:
    """The kit's assembly and its figures (file name, PNG or its drawing, caption)."""

    assembly: Assembly
    figures: Sequence[tuple[str, bytes | Drawing, str]] = ()

    def to_record(self) -> dict[str, Any]:
        return self.assembly.to_record()


@dataclass(frozen=True)
class CheckRecords:
    """The pre-print verification with the model's uncertainty band at scale 1:`scale`.

    `solver_work` : what the solver did (make's; its times are in the run's timings);
    `counterexample` : show the steel counter-example the verification carries (make's);
    `nested` : report.json holds the band, the lab's record and the solver's work inside
    "verification" (make's layout) or the band and the lab beside it (verify's).
    """

    verification: Verification
    band: Band
    scale: float
    solver_work: dict[str, Any] | None = None
    counterexample: bool = False
    nested: bool = True

    @cached_property
    def lab(self) -> dict[str, Any]:
        """The lab's curves, expected readings and layout (printgen.report.labfiles)."""
        from printgen.report.labfiles import lab_record

        return lab_record(self.verification, self.band, self.scale)

    @cached_property
    def bands(self) -> dict[str, Any]:
        from printgen.report.uncertainty import band_record

        return band_record(self.verification, self.band)

    def to_record(self) -> dict[str, Any]:
        """The record under report.json's "verification" (make's layout)."""
        rec = self.verification.to_record()
        if self.solver_work is not None:
            rec["solver_work"] = self.solver_work
        rec["bands"], rec["lab"] = self.bands, self.lab
        return rec

    def top_level(self) -> dict[str, Any]:
        """report.json's keys of these records: "verification" (with the band and the lab
        inside when `nested`), else "verification", "bands" and "lab"."""
        if self.nested:
            return {"verification": self.to_record()}
        return {"verification": self.verification.to_record(), "bands": self.bands,
                "lab": self.lab}


@dataclass(frozen=True)
class MeasuredRecords:
    """A lab's measured loading test against the band, the fitted factor of the printed net
    (None: no fit) and the fitted profile's text ("" when it explains nothing)."""

    measurement: Measurement
    band: Band
    fit: Fit | None
    profile: str = ""

    def sentence(self) -> str:
        """What the fit says (the summary's next step); "" without a fit."""
        from printgen.report.uncertainty import fit_sentence

        return fit_sentence(self.fit) if self.fit else ""

    def to_record(self) -> dict[str, Any]:
        from printgen.report.uncertainty import measured_record

        return measured_record(self.measurement, self.band, self.fit, self.profile)


@dataclass
class RunRecords:
    """Every record of one run, in the order the report shows them: `make`'s plan, then each
    step's records by report.json key ("parts", "gcode", "assembly", "verification",
    "measured", ...: record objects or plain records), and `make`'s provenance (the
    manifest's, shown in the report only). `verify`'s run is the same with fewer records."""

    title: str
    design: Design
    plan: PlanRecords | None = None
    steps: dict[str, Any] = field(default_factory=dict)
    provenance: dict[str, Any] | None = None

    @property
    def check(self) -> CheckRecords | None:
        c = self.steps.get("verification")
        return c if isinstance(c, CheckRecords) else None

    @property
    def measured(self) -> MeasuredRecords | None:
        m = self.steps.get("measured")
        return m if isinstance(m, MeasuredRecords) else None

    def records(self, steps: dict[str, Any]) -> dict[str, Any]:
        """The report.json keys of `steps` (some of this run's steps' records)."""
        out: dict[str, Any] = {}
        for key, value in steps.items():
            out.update(value.top_level() if isinstance(value, CheckRecords)
                       else {key: record_of(value)})
        return out

    def to_record(self) -> dict[str, Any]:
        """report.json without its summary (printgen.report.summary adds it)."""
        rec = {} if self.plan is None else self.plan.to_record()
        if self.plan is None:
            rec["design"] = self.design.to_dict()
        from printgen.inputs.materials import load_material
        from printgen.scaling.reading import panel_reading

        reading = panel_reading(load_material(self.design.net.material))
        if reading is not None:  # which reading of the net's panel law, its checks and why
            rec["panel_law_reading"] = reading.to_record()
        rec.update(self.records(self.steps))
        return rec
