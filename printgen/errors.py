"""Errors printgen raises for bad input or impossible designs.

Every message names the value, the limit (with units) and how to fix it. The CLI turns a
`PrintgenError` into a one-line message and exit code 2, without a traceback.
"""


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


class SolverError(PrintgenError):
    """The cable-net solver did not converge where the caller required it."""


class TimeLimitError(PrintgenError):
    """A run went past its time limit (`make --time-limit`): stopped, nothing written. The
    CLI exits 4 (not 2: the input may be valid, the run only takes longer)."""
