"""Errors printgen raises for bad input or impossible designs.

Every message names the value, the limit (with units) and how to fix it. The CLI turns a
`PrintgenError` into a one-line message and exit code 2, without a traceback; so it does the
solver's `SolverError` (`reported`), the one class for a solve that did not converge, which
lives in `printgen.solver` because the solver imports nothing else of printgen.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from printgen.solver.result import SolverError  # noqa: F401 (for type checkers: `__getattr__`)


class PrintgenError(Exception):
    """Base class: bad input, impossible geometry or an unprintable design."""


class InputError(PrintgenError):
    """A value in a data file or on the command line is missing, unknown or out of range."""


class ProfileError(InputError):
    """A profile (material, printer, print style) cannot be found or is invalid."""


class DesignError(PrintgenError):
    """The design cannot meet its targets (no candidate, strength, similitude)."""


class PrintabilityError(DesignError):
    """A part cannot be printed: bead too thin, layer too high, flow or bed limits."""


class GeometryError(PrintgenError):
    """A mesh or outline operation failed (non-manifold result, impossible dimensions)."""


class CalibrationError(InputError):
    """A tensile-test export cannot be read or fitted."""


class TimeLimitError(PrintgenError):
    """A run went past its time limit (`make --time-limit`): stopped, nothing written. The
    CLI exits 4 (not 2: the input may be valid, the run only takes longer)."""


def __getattr__(name: str) -> Any:
    """`SolverError`, the solver's, imported on first use: importing the solver costs numpy
    and scipy, which the command line's start does not need."""
    if name == "SolverError":
        from printgen.solver.result import SolverError

        return SolverError
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def reported(exc: BaseException) -> bool:
    """Whether `exc` is an error the command line reports in one line with exit code 2: a
    `PrintgenError` or the solver's `SolverError` (raised only once the solver is imported,
    hence looked up among the loaded modules)."""
    result = sys.modules.get("printgen.solver.result")
    solver_error = getattr(result, "SolverError", None)
    return isinstance(exc, PrintgenError) or (solver_error is not None
                                              and isinstance(exc, solver_error))
