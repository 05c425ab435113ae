"""Curve fits on a loading branch: linear regression over a strain window (ISO 527-1), the
steepest window (automatic, as test-machine software does), a continuous bilinear fit and
secant moduli. x is strain (a number), y stress (Pa) or force per width (N/m).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from printgen.errors import CalibrationError

ISO_WINDOW = (0.0005, 0.0025)  # strain, ISO 527-1 chord window 0.05 %-0.25 %
MIN_POINTS = 5  # fewest points a regression (or each bilinear segment) may use
AUTO_SPAN = 0.15  # automatic window covers this fraction of the rise to the peak (y_peak - y_0)
KNEE_GRID = 200  # candidate knees scanned before the bounded refinement
ZERO_MODES = ("interpolate", "first")  # preload zero conventions (see zero_at_preload)
DEFAULT_ZERO = "interpolate"
# Break: the force falls by this fraction of its peak (a 40 % drop, as test-machine software's
# usual break detection); the last sample before that drop gives the elongation at break.
BREAK_DROP = 0.4


@dataclass(frozen=True)
class LinearFit:
    """y = slope * x + intercept over lo <= x <= hi (n points, coefficient of determination r2)."""

    slope: float
    intercept: float
    lo: float
    hi: float
    n: int
    r2: float
    mode: str  # "window" or "auto"

@dataclass(frozen=True)
class BilinearFit:
    """Continuous two-slope fit: y = a + s1 x + (s2 - s1) max(x - knee, 0)."""

    slope1: float
    slope2: float
    knee: float
    intercept: float
    rms: float

    def __call__(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return self.intercept + self.slope1 * x + (self.slope2 - self.slope1) * np.maximum(
            x - self.knee, 0.0)


def loading_branch(y: np.ndarray) -> int:
    """Index of the peak of y: the loading branch is [0, peak]; later points are post-failure."""
    if y.size == 0:
        raise CalibrationError("empty curve: no rows to fit")
    return int(np.argmax(y))


def zero_at_preload(x: np.ndarray, y: np.ndarray, preload: float | None,
                    force: np.ndarray | None = None, *, mode: str = DEFAULT_ZERO
                    ) -> tuple[np.ndarray, np.ndarray, float]:
    """(x, y, x0): the points from where `force` (default: y) first reaches `preload`, with
    x0 the strain put to zero there.

    mode "interpolate": x0 and the first y interpolated between the two samples around the
    crossing (independent of the sampling rate); "first": x0 at the first sample at or above
    the preload (as many testers' software does). None: zero at the first point."""
    if mode not in ZERO_MODES:
        raise CalibrationError(f"zero convention {mode!r}; expected one of {', '.join(ZERO_MODES)}")
    if preload is None:
        return x - x[0], y, float(x[0])
    ref = y if force is None else force
    above = np.nonzero(ref >= preload)[0]
    if above.size == 0:
        raise CalibrationError(f"preload {preload:g} N never reached (peak {ref.max():.4g} N); "
                               "lower --preload")
    k = int(above[0])
    if k == 0 or mode == "first":
        return x[k:] - x[k], y[k:], float(x[k])
    t = (preload - ref[k - 1]) / (ref[k] - ref[k - 1])
    x0 = x[k - 1] + t * (x[k] - x[k - 1])
    y0 = y[k - 1] + t * (y[k] - y[k - 1])
    return np.concatenate([[0.0], x[k:] - x0]), np.concatenate([[y0], y[k:]]), float(x0)


def break_index(y: np.ndarray, drop: float = BREAK_DROP) -> int | None:
    """Index of the break: the last sample before y first falls below (1 - drop) x its peak
    after the peak; None when it never does (the test stopped before the break)."""
    p = int(np.argmax(y))
    below = np.nonzero(y[p:] < (1.0 - drop) * y[p])[0]
    return None if below.size == 0 else p + int(below[0]) - 1


def linear_fit(x: np.ndarray, y: np.ndarray, lo: float, hi: float) -> LinearFit:
    """Least-squares line through the points with lo <= x <= hi."""
    if not hi > lo:
        raise CalibrationError(f"fit window {lo:g}..{hi:g} is empty; the upper strain must be "
                               "above the lower")
    m = (x >= lo) & (x <= hi)
    if m.sum() < MIN_POINTS:
        raise CalibrationError(
            f"only {int(m.sum())} points in the strain window {lo * 100:g}-{hi * 100:g} % "
            f"(need {MIN_POINTS}; the loading branch reaches {x.max() * 100:.4g} %); "
            "widen --window or use --window auto")
    return _line(x[m], y[m], lo, hi, "window")


def _line(x: np.ndarray, y: np.ndarray, lo: float, hi: float, mode: str) -> LinearFit:
    slope, intercept = np.polyfit(x, y, 1)
    resid = y - (slope * x + intercept)
    ss = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum(resid**2)) / ss if ss > 0 else 1.0
    return LinearFit(float(slope), float(intercept), float(lo), float(hi), int(x.size), r2, mode)


def steepest_fit(x: np.ndarray, y: np.ndarray, span: float = AUTO_SPAN) -> LinearFit:
    """The steepest regression line over consecutive points whose y rises by `span` of the
    branch's rise (y_peak - y_0): the machine software's 'automatic' modulus."""
    n = x.size
    rise = span * (y.max() - y[0])
    run_max = np.maximum.accumulate(y)
    ends = np.searchsorted(run_max, y + rise, side="left")
    c = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones(n), x, y, x * x, x * y)]
    best: tuple[float, int, int] | None = None
    for i, j in enumerate(ends):
        j = max(int(j) + 1, i + MIN_POINTS)
        if j > n:
            break
        cnt, sx, sy, sxx, sxy = (v[j] - v[i] for v in c)
        den = cnt * sxx - sx * sx
        if den <= 0:
            continue
        slope = (cnt * sxy - sx * sy) / den
        if best is None or slope > best[0]:
            best = (slope, i, j)
    if best is None:
        raise CalibrationError(f"curve too short for an automatic window (need {MIN_POINTS} "
                               "points rising by the span)")
    _, i, j = best
    return _line(x[i:j], y[i:j], x[i:j].min(), x[i:j].max(), "auto")


def bilinear_fit(x: np.ndarray, y: np.ndarray) -> BilinearFit:
    """Continuous bilinear least-squares fit; the knee is scanned then refined."""
    if x.size < 2 * MIN_POINTS:
        raise CalibrationError(f"{x.size} points: too few for a bilinear fit "
                               f"(need {2 * MIN_POINTS})")
    xs = np.sort(x)
    lo, hi = xs[MIN_POINTS - 1], xs[-MIN_POINTS]
    grid = np.linspace(lo, hi, KNEE_GRID)
    sse = np.array([_bilinear_lstsq(x, y, k)[1] for k in grid])
    b = int(np.argmin(sse))
    a, z = grid[max(b - 1, 0)], grid[min(b + 1, grid.size - 1)]
    res = minimize_scalar(lambda k: _bilinear_lstsq(x, y, k)[1], bounds=(a, z), method="bounded",
                          options={"xatol": 1e-12 * max(abs(hi), 1e-30)})
    knee = float(res.x) if res.fun <= sse[b] else float(grid[b])
    coef, err = _bilinear_lstsq(x, y, knee)
    return BilinearFit(float(coef[1]), float(coef[1] + coef[2]), knee, float(coef[0]),
                       float(np.sqrt(err / x.size)))


def _bilinear_lstsq(x: np.ndarray, y: np.ndarray, knee: float) -> tuple[np.ndarray, float]:
    a = np.column_stack([np.ones_like(x), x, np.maximum(x - knee, 0.0)])
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    r = y - a @ coef
    return coef, float(r @ r)


def secant_moduli(x: np.ndarray, y: np.ndarray, at: tuple[float, ...], *, x0: float = 0.0,
                  y0: float = 0.0) -> dict[float, float | None]:
    """(y(e) - y0) / e at each strain e measured from x0; None beyond the branch."""
    out: dict[float, float | None] = {}
    for e in at:
        xe = x0 + e
        out[e] = (float(np.interp(xe, x, y)) - y0) / e if x[0] <= xe <= x[-1] else None
    return out
