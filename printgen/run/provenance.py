"""What a `make` folder says about itself: the provenance (version, command line, sha256 of
every input, the versions of Python and of the packages the numbers and bytes depend on, the
solver's linear backend) that goes into manifest.json and the report, and the split of the
run's record into its reproducible part (report.json) and its wall-clock times (timings.json, the one
volatile file, and `make --json`'s "timings" key)."""

from __future__ import annotations

import platform
from pathlib import Path
from typing import TYPE_CHECKING, Any

import printgen
from printgen.outputs import file_digest

if TYPE_CHECKING:
    from printgen.run.make import MakeContext

TIME_KEYS = ("timings_s", "seconds", "time_s")  # record keys that hold wall-clock times
# The packages whose versions can move the outputs' numbers or bytes (meshes, solver, figures);
# the same inputs with other versions may differ in the last digits (values within ~1e-4).
PACKAGES = ("numpy", "scipy", "manifold3d", "trimesh", "shapely", "matplotlib", "qdldl",
            "pypardiso")


def split_timings(record: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """(the record without wall-clock times, the times at the same paths).

    The first is byte-reproducible; the second is `timings.json` and `--json`'s "timings".
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


def json_output(record: dict[str, Any]) -> dict[str, Any]:
    """What `make --json` prints: the reproducible record plus one top-level "timings" key."""
    stable, timings = split_timings(record)
    return {**stable, "timings": timings}


def provenance(ctx: MakeContext) -> dict[str, Any]:
    """Version, command line, the sha256 of every input (prototype, each profile used) and the
    software environment (`environment`)."""
    from printgen.inputs.profiles import BUNDLED, load_raw

    d = ctx.design
    used = {("printers", d.printer), ("materials", d.net.material),
            ("prints", d.net.print_style)}
    used |= {("materials", c.material) for c in d.cables}
    used |= {("prints", c.print_style) for c in d.cables}
    inputs = {"prototype": _digest(ctx.prototype.path)} if ctx.prototype.path else {}
    if ctx.options.design_file:  # make --design FILE: the design is an input too
        inputs["design_file"] = _digest(Path(ctx.options.design_file))
    for kind, name in sorted(used):
        for path in load_raw(kind, name)[1]:
            shown = (Path("profiles") / path.relative_to(BUNDLED)
                     if path.is_relative_to(BUNDLED) else path)
            inputs[f"{kind}/{path.stem}"] = _digest(path, shown)
    return {"printgen_version": printgen.__version__, "command": ctx.options.command,
            "inputs": inputs, "environment": environment(ctx.record)}


def environment(record: dict[str, Any]) -> dict[str, Any]:
    """Python's version, each of PACKAGES' (None: not installed) and the solver backend the
    verification's sweeps used (from the run's record; None when it did not verify)."""
    from importlib.metadata import PackageNotFoundError, version

    def installed(name: str) -> str | None:
        try:
            return version(name)
        except PackageNotFoundError:
            return None

    return {"python": platform.python_version(),
            "packages": {name: installed(name) for name in PACKAGES},
            "solver_backend": record.get("verification", {}).get("solver_backend")}


def _digest(path: Path, shown: Path | None = None) -> dict[str, Any]:
    return {"path": str(shown or path), "sha256": file_digest(Path(path))["sha256"]}
