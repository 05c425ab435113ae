"""Is a modulus fit where it should be? Checks of the fit window against its own curve, and of
the fitted modulus against the machine software's own value when the export carries one.

Against the curve (every sample): the window must hold enough points, the curve must be linear
there (the slopes of the window's lower and upper halves agree), and the window must lie on the
curve's steepest part: a window whose slope is well below the steepest window of the branch
(`fit.steepest_fit`, the machine software's "automatic" modulus) lies either in the toe region
(the steepest part comes after it: the curve still stiffens) or past the linear part (the
steepest part comes before it: the curve has already softened).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from printgen.calibrate.fit import MIN_POINTS, LinearFit, steepest_fit
from printgen.errors import CalibrationError

if TYPE_CHECKING:
    from printgen.calibrate.sample import SampleFit

# Enough points: at least WINDOW_POINTS, and a slope whose standard error (ASTM E111's
# coefficient of variation of the slope, from the regression's residuals) is at most
# SLOPE_SE_TOL of it. Measured on the Bluehill exports: 0.14-1.3 % over 13 to 688 points.
WINDOW_POINTS = 10
SLOPE_SE_TOL = 0.02
# Linear there: the slopes of the window's lower and upper halves differ by at most this
# fraction, or by no more than NOISE_SIGMAS of their standard errors (noise, not a bend).
# Measured on the Bluehill exports: automatic windows bend by up to 13 % between halves (and
# match the machine's own modulus within 4.4 %); ISO windows past the knee by up to 40 %.
LINEARITY_TOL = 0.15
NOISE_SIGMAS = 3.0
# The window's slope may fall this far below the steepest window of the branch before the
# window is said to miss the linear part (the same 10 % as the machine comparison).
STEEPEST_TOL = 0.10
MACHINE_TOL = 0.10  # |fitted / machine's own modulus - 1| above this warns
SHOWN = 3  # files named in a warning about several files; the table has the rest
POSITIONS = ("steepest part", "toe region", "past the linear part", "automatic")


@dataclass(frozen=True)
class WindowCheck:
    """How the modulus window sits on its curve."""

    points: int
    slope_se: float  # standard error of the window's slope / the slope
    slope_change: float | None  # upper-half slope / lower-half slope - 1; None: too few points
    bends: bool  # the halves differ by more than LINEARITY_TOL and more than the noise
    position: str  # one of POSITIONS
    steepest: LinearFit | None  # the branch's steepest window (None for an automatic window)

    @property
    def problems(self) -> tuple[str, ...]:
        out = []
        if self.points < WINDOW_POINTS or self.slope_se > SLOPE_SE_TOL:
            out.append("few points")
        if self.bends:
            out.append("not linear")
        if self.position in POSITIONS[1:3]:
            out.append(self.position)
        return tuple(out)

    def record(self, unit: tuple[str, float]) -> dict[str, object]:
        """Plain data for --json; moduli in `unit` (label, factor from SI)."""
        s, (label, factor) = self.steepest, unit
        return {"points": self.points, "slope_se_percent": self.slope_se * 100,
                "linear": not self.bends,
                "slope_change_percent": None if self.slope_change is None
                else self.slope_change * 100, "position": self.position,
                "steepest_window_percent": None if s is None else [s.lo * 100, s.hi * 100],
                f"steepest_modulus_{label}": None if s is None else s.slope / factor,
                "problems": list(self.problems)}


def check_window(x: np.ndarray, y: np.ndarray, lin: LinearFit, auto_span: float) -> WindowCheck:
    """Check the fit `lin` against the loading branch (x, y) it was fitted on."""
    m = (x >= lin.lo) & (x <= lin.hi)
    xs, ys = x[m], y[m]
    se = _slope(xs, ys)[1] / abs(lin.slope) if lin.slope else np.inf
    change, bends = None, False
    if xs.size >= 2 * MIN_POINTS:
        order = np.argsort(xs, kind="stable")
        (s1, e1), (s2, e2) = (_slope(xs[k], ys[k]) for k in np.array_split(order, 2))
        if s1 > 0:
            change = s2 / s1 - 1
            bends = abs(change) > LINEARITY_TOL and abs(s2 - s1) > NOISE_SIGMAS * np.hypot(e1, e2)
    if lin.mode == "auto":
        return WindowCheck(lin.n, float(se), change, bends, POSITIONS[3], None)
    try:
        best = steepest_fit(x, y, auto_span)
    except CalibrationError:
        return WindowCheck(lin.n, float(se), change, bends, POSITIONS[0], None)
    position = POSITIONS[0]
    if lin.slope < (1 - STEEPEST_TOL) * best.slope:
        centre = (best.lo + best.hi) / 2
        position = POSITIONS[1] if centre > (lin.lo + lin.hi) / 2 else POSITIONS[2]
    return WindowCheck(lin.n, float(se), change, bends, position, best)


def _slope(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(least-squares slope, its standard error) of y over x."""
    dx = x - x.mean()
    sxx = float(dx @ dx)
    if x.size < 3 or sxx == 0:
        return 0.0, np.inf
    slope = float(dx @ (y - y.mean())) / sxx
    r = y - y.mean() - slope * dx
    return slope, float(np.sqrt(r @ r / (x.size - 2) / sxx))


def window_warnings(samples: list[SampleFit], window: str, unit: tuple[str, float]
                    ) -> tuple[list[str], str]:
    """(one warning per kind of problem, naming files and values; the check's summary)."""
    label, f = unit
    total = len(samples)
    warns = []
    by = {p: [s for s in samples if p in s.window_check.problems]
          for p in ("past the linear part", "toe region", "not linear", "few points")}
    for problem, hits in by.items():
        if not hits:
            continue
        head = f"modulus window {window}: {_what(problem)} in {len(hits)} of {total} files"
        fix = _fix(problem, auto="auto" in window)
        warns.append(f"{head} ({_examples(problem, hits, f, label)}); {fix}")
    bad = {s.path for hits in by.values() for s in hits}
    ok = total - len(bad)
    summary = (f"modulus window {window} checked against each curve: linear, at least "
               f"{WINDOW_POINTS} points (slope known to {SLOPE_SE_TOL:.0%})"
               + (", on its steepest part" if "auto" not in window else "")
               + f" in {ok} of {total} files" + (" (see the warnings)" if bad else ""))
    return warns, summary


def machine_refutes(samples: tuple[SampleFit, ...] | list[SampleFit]) -> tuple[int, int] | None:
    """(files, files with the machine's own modulus) when the fitted modulus differs from the
    machine's by more than MACHINE_TOL in every file that carries one (at least two): the
    window does not fit these curves, and a profile from it would be wrong; else None."""
    with_m = [s for s in samples if s.machine_modulus]
    far = [s for s in with_m if abs(s.modulus / s.machine_modulus - 1) > MACHINE_TOL]
    return (len(far), len(with_m)) if len(with_m) >= 2 and len(far) == len(with_m) else None


def machine_warning(samples: list[SampleFit], window: str, unit: tuple[str, float]
                    ) -> str | None:
    """One warning when the fitted modulus differs from the machine's own value by more than
    MACHINE_TOL in any file, naming both values (means, and the worst files)."""
    label, f = unit
    with_m = [s for s in samples if s.machine_modulus]
    far = sorted((s for s in with_m if abs(s.modulus / s.machine_modulus - 1) > MACHINE_TOL),
                 key=lambda s: -abs(s.modulus / s.machine_modulus - 1))
    if not far:
        return None
    ours = float(np.mean([s.modulus for s in far])) / f
    theirs = float(np.mean([s.machine_modulus for s in far])) / f
    worst = "; ".join(f"{Path(s.path).name} {s.modulus / f:.4g} vs {s.machine_modulus / f:.4g} "
                      f"{label}" for s in far[:SHOWN])
    more = f"; {len(far) - SHOWN} more in the table's diff column" if len(far) > SHOWN else ""
    fix = ("the automatic window differs too: check the strain source and the cross-section"
           if "auto" in window else
           "try --window auto (the steepest window, as the machine's software fits it)")
    return (f"modulus {ours:.4g} {label} (fitted, window {window}) differs from the machine's "
            f"own {theirs:.4g} {label} by {ours / theirs - 1:+.1%} (more than "
            f"{MACHINE_TOL:.0%} in {len(far)} of {len(with_m)} files: {worst}{more}); {fix}")


def _what(problem: str) -> str:
    return {"past the linear part": "past the linear part (the curve is steepest before it)",
            "toe region": "inside the toe region (the curve still stiffens after it)",
            "not linear": f"not linear (its halves' slopes differ by more than "
                          f"{LINEARITY_TOL:.0%})",
            "few points": f"fewer than {WINDOW_POINTS} points or a slope uncertain by more "
                          f"than {SLOPE_SE_TOL:.0%}"}[problem]


def _examples(problem: str, hits: list[SampleFit], f: float, label: str) -> str:
    def one(s: SampleFit) -> str:
        c, name = s.window_check, Path(s.path).name
        if problem in ("past the linear part", "toe region"):
            b = c.steepest
            return (f"{name}: {s.modulus / f:.4g} {label} in the window, {b.slope / f:.4g} "
                    f"{label} from {b.lo * 100:.3g} to {b.hi * 100:.3g} % strain")
        if problem == "not linear":
            return f"{name}: slope {c.slope_change:+.0%} from its lower to its upper half"
        return f"{name}: {c.points} points, slope ± {c.slope_se:.1%}"
    more = f"; {len(hits) - SHOWN} more" if len(hits) > SHOWN else ""
    return "; ".join(one(s) for s in hits[:SHOWN]) + more


def _fix(problem: str, *, auto: bool) -> str:
    if auto:
        return {"not linear": "lower --auto-span, or give a --window on the linear part",
                "few points": "raise --auto-span, or record more samples per second"}[problem]
    return {"past the linear part": "use --window auto, or a --window on the linear part",
            "toe region": "zero at a preload past the toe (--preload N), move the --window "
                          "up, or use --window auto",
            "not linear": "narrow the --window to the linear part, or use --window auto",
            "few points": "widen the --window, or record more samples per second"}[problem]
