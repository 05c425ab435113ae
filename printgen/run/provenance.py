"""What a `make` folder says about itself: the provenance (version, command line, sha256 of
every input, the versions of Python and of the packages the numbers and bytes depend on, the
solver's linear backend) that goes into manifest.json and the report, and `make --json`'s
output: report.json's record with the run's wall-clock times (timings.json, the one volatile
file) under "timings"."""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import printgen
from printgen.outputs import file_digest

if TYPE_CHECKING:
    from printgen.report.records import CheckRecords
    from printgen.run.make import MakeContext
    from printgen.scaling.record import Design

TIME_KEYS = ("timings_s", "seconds", "time_s")  # record keys that hold wall-clock times
# The packages whose versions can move the outputs' numbers or bytes (meshes, solver, figures);
# the same inputs with other versions may differ in the last digits (values within ~1e-4).
PACKAGES = ("numpy", "scipy", "manifold3d", "trimesh", "shapely", "matplotlib", "qdldl",
            "cvxopt", "pymetis", "pypardiso")


def split_timings(record: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """(the record without wall-clock times, the times at the same paths): for a record made
    outside the report's records that carries its times (the solver's counted work), so that
    they go to the run's timings.
    """
    def split(v: Any) -> tuple[Any, Any]:
        if isinstance(v, dict):
            keep, times = {}, {}
            for k, x in v.items():
                if k in TIME_KEYS:
                    times[k] = x
                    continue
                keep[k], t = split(x)
                if t:
                    times[k] = t
            return keep, times
        if isinstance(v, list):
            parts = [split(x) for x in v]
            times = {str(i): t for i, (_, t) in enumerate(parts) if t}
            return [k for k, _ in parts], times
        return v, {}

    return split(record)


def process_seconds() -> float | None:
    """Seconds since this process started (the interpreter's start-up and the imports
    included: for the command line, what its user has waited so far), from Linux's
    /proc/self/stat (its start in clock ticks since boot, against CLOCK_BOOTTIME, the same
    clock: to 1 / SC_CLK_TCK, 0.01 s); None where the system does not say."""
    try:
        stat = Path("/proc/self/stat").read_text()
        ticks = int(stat.rsplit(")", 1)[1].split()[19])  # field 22, starttime
        return time.clock_gettime(time.CLOCK_BOOTTIME) - ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def json_output(ctx: MakeContext) -> dict[str, Any]:
    """What `make --json` prints: report.json's record plus one top-level "timings" key (the
    run's timings, timings.json)."""
    return {**ctx.record, "timings": ctx.timings}


def provenance(ctx: MakeContext) -> dict[str, Any]:
    """`make`'s provenance (`provenance_record`): its prototype, the design file of `--design`,
    the design's profiles, and the solver backend of its verification."""
    return provenance_record(ctx.options.command, prototype=ctx.prototype.path,
                             files={"design_file": ctx.options.design_file},
                             design=ctx.design, check=ctx.records.check)


def provenance_record(command: list[str] | None, *, prototype: str | Path | None = None,
                      files: dict[str, str | Path | None] | None = None,
                      design: Design | None = None,
                      check: CheckRecords | None = None) -> dict[str, Any]:
    """Version, command line, the sha256 of every input (the prototype, the other input
    `files` by label, None ones left out, each profile the `design` uses) and the software
    environment (`environment`): what every run's manifest.json carries, so `printgen check`
    names the code and the inputs that made a folder."""
    inputs = {"prototype": _digest(Path(prototype))} if prototype else {}
    inputs |= {label: _digest(Path(path)) for label, path in (files or {}).items() if path}
    if design is not None:
        inputs |= profile_digests(design)
    return {"printgen_version": printgen.__version__, "command": command,
            "inputs": inputs, "environment": environment(check)}


def profile_digests(d: Design) -> dict[str, Any]:
    """The sha256 of every profile file design `d` uses (printer, materials, print styles,
    each with the files it inherits), by kind/name."""
    from printgen.inputs.profiles import BUNDLED, load_raw

    used = {("printers", d.printer), ("materials", d.net.material),
            ("prints", d.net.print_style)}
    used |= {("materials", c.material) for c in d.cables}
    used |= {("prints", c.print_style) for c in d.cables}
    out = {}
    for kind, name in sorted(used):
        for path in load_raw(kind, name)[1]:
            shown = (Path("profiles") / path.relative_to(BUNDLED)
                     if path.is_relative_to(BUNDLED) else path)
            out[f"{kind}/{path.stem}"] = _digest(path, shown)
    return out


def environment(check: CheckRecords | None = None) -> dict[str, Any]:
    """Python's version, each of PACKAGES' (None: not installed) and the solver backend the
    verification's sweeps used (`check`'s; None when the run did not verify)."""
    from importlib.metadata import PackageNotFoundError, version

    def installed(name: str) -> str | None:
        try:
            return version(name)
        except PackageNotFoundError:
            return None

    return {"python": platform.python_version(),
            "packages": {name: installed(name) for name in PACKAGES},
            "solver_backend": None if check is None else {
                who: run.backend for who, run in (("prototype", check.verification.prototype),
                                                  ("model", check.verification.model))}}


def _digest(path: Path, shown: Path | None = None) -> dict[str, Any]:
    return {"path": str(shown or path), "sha256": file_digest(Path(path))["sha256"]}
