"""The run's records: what `make` and `verify` computed, kept as the objects themselves, each
knowing its own `to_record()`. report.json is their records; report.html, the summary and the
lab's files are rendered from the same objects (printgen.report.build), never from JSON read
back. Wall-clock times are not in them: they live in the run's timings (timings.json)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from printgen.design.record import Design
    from printgen.design.selection import Candidate, Selection
    from printgen.design.similitude import ScaledTargets
    from printgen.inputs.prototype import Prototype
    from printgen.parts.assembly import Assembly
    from printgen.report.html import Drawing
    from printgen.verification.bands import Band
    from printgen.verification.measured import Fit, Measurement
    from printgen.verification.verify import Verification


def record_of(value: Any) -> Any:
    """`value.to_record()` when it has one, else `value` (already a plain record)."""
    to_record = getattr(value, "to_record", None)
    return to_record() if callable(to_record) else value


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
class KitRecords:
    """The kit's assembly and its figures (file name, PNG or its drawing, caption)."""

    assembly: Assembly
    figures: list[tuple[str, bytes | Drawing, str]] = field(default_factory=list)

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
        rec.update(self.records(self.steps))
        return rec
