"""printgen: stiffness-scaled, printable flexible-barrier models for flume experiments.

Based on Lambert et al., "Small-Scale Modeling of Flexible Barriers. I: Mechanical Similitude
of the Structure", J. Hydraul. Eng. 149(3), 2023, doi:10.1061/JHEND8.HYENG-13070.

The public verbs (`printgen.run.api`), imported on first use so `import printgen` stays fast:

- ``targets(prototype, scale)`` -> `ScaledTargets`
- ``select(prototype, scale)`` -> `Selection`
- ``plan(prototype, scale)`` -> `Design` (the printable design `make` writes)
- ``make(prototype, scale, out)`` -> `MakeContext` (files in `out`)
- ``verify(prototype, scale, design=None)`` -> `Verification`
- ``verify_design(prototype, scale, design_file, out)`` -> `VerifyRun` (printgen verify's folder)
- ``calibrate(paths, material=...)`` -> `Calibration`
- ``search_nets(prototype, scales)`` -> `DesignRun` (the inverse design, in parallel)
- ``series(prototype, scales)`` -> `SeriesRun` (the virtual scale series)
- ``panel(design_file)`` -> list of `PanelRun` (the simulated net panel tests)
- ``testpieces(design_file, out)`` -> the record of the test pieces written in `out`
- ``examples()`` -> the bundled examples; ``example(name, out=None)`` -> `Example`
- ``init(path)`` -> the prototype template written at `path`

Plot helpers (`printgen.report.figures`, the `plot` extra), each returning a matplotlib Figure
or drawing on the `ax` given:

- ``plot_curves(result, ax=None, metric=None)``: prototype vs model against h/h_B
- ``plot_net(design, ax=None)``: the printed net's strands

Every result has a short repr and a notebook table; `Verification`, `make`'s and
`verify_design`'s results give their curves as ``curves_table()`` (pandas, the `table` extra)
or ``curve_rows()`` (dicts).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

VERBS = ("targets", "select", "plan", "make", "verify", "verify_design", "calibrate",
         "search_nets", "series", "panel", "testpieces", "examples", "example", "init")
PLOTS = ("plot_curves", "plot_net")  # printgen.report.figures
__all__ = [
    "__version__",
    "calibrate",
    "example",
    "examples",
    "init",
    "make",
    "panel",
    "plan",
    "plot_curves",
    "plot_net",
    "search_nets",
    "select",
    "series",
    "targets",
    "testpieces",
    "verify",
    "verify_design",
]

if TYPE_CHECKING:
    __version__: str
    from printgen.report.figures import plot_curves, plot_net
    from printgen.run.api import (
        calibrate,
        example,
        examples,
        init,
        make,
        panel,
        plan,
        search_nets,
        select,
        series,
        targets,
        testpieces,
        verify,
        verify_design,
    )


def __getattr__(name: str) -> Any:
    if name == "__version__":  # from git or the package's metadata (`printgen.version`)
        from printgen.version import version

        return version()
    if name in VERBS:
        from printgen.run import api

        return getattr(api, name)
    if name in PLOTS:
        from printgen.report import figures

        return getattr(figures, name)
    raise AttributeError(f"module 'printgen' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *VERBS, *PLOTS, "__version__"])
