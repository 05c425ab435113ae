"""What a `make` folder says about itself: the provenance (version, command line, sha256 of
every input) that goes into manifest.json and the report, and the split of the run's record
into its reproducible part (report.json) and its wall-clock times (timings.json, the one
volatile file, and `make --json`'s "timings" key)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from printgen.outputs import file_digest

if TYPE_CHECKING:
    from printgen.run.make import MakeContext

TIMINGS = "timings.json"  # the one volatile file: every wall-clock time of the run
TIME_KEYS = ("timings_s", "seconds", "time_s")  # record keys that hold wall-clock times


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
    """Version, command line and the sha256 of every input (prototype, each profile used)."""
    from importlib.metadata import version

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
    return {"printgen_version": version("printgen"), "command": ctx.options.command,
            "inputs": inputs}


def _digest(path: Path, shown: Path | None = None) -> dict[str, Any]:
    return {"path": str(shown or path), "sha256": file_digest(Path(path))["sha256"]}
