"""Statistics over samples: mean, sample standard deviation (ddof = 1), count, outliers.

Outliers are flagged (not removed) with the modified z-score of Iglewicz and Hoaglin,
|0.6745 (x - median) / MAD| > 3.5, when also more than 1 % from the median, and only from
`MIN_SAMPLES` samples on: fewer give mean and SD only ("n = 3: spread only").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_SAMPLES = 5  # ISO 527-1 asks for at least five specimens per direction
OUTLIER_Z = 3.5  # modified z-score above which a sample is flagged (Iglewicz & Hoaglin 1993)
MAD_SCALE = 0.6745  # makes the median absolute deviation consistent with a normal SD
OUTLIER_MIN_REL = 0.01  # never flag a sample within 1 % of the median (round-off, tight sets)


@dataclass(frozen=True)
class Stats:
    """mean and sd (ddof = 1; None for one sample) of `values`; outliers are indices."""

    mean: float
    sd: float | None
    n: int
    values: tuple[float, ...]
    outliers: tuple[int, ...]
    warnings: tuple[str, ...]

def summarise(values: list[float] | np.ndarray, *, what: str = "value",
              labels: list[str] | None = None, unit: tuple[str, float] = ("", 1.0)) -> Stats:
    """Mean, SD, count and (from MIN_SAMPLES samples on) flagged outliers of one measured
    quantity; outlier warnings give values in `unit` (label, factor from SI)."""
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        raise ValueError(f"no samples of {what}")
    sd = float(np.std(v, ddof=1)) if v.size > 1 else None
    out = outliers(v) if v.size >= MIN_SAMPLES else ()
    label, factor = unit
    warns = []
    for i in out:
        name = labels[i] if labels else f"sample {i + 1}"
        warns.append(f"{what}: {name} = {v[i] / factor:.4g} {label}".rstrip()
                     + f" is an outlier (modified z-score > {OUTLIER_Z:g}, median "
                     f"{np.median(v) / factor:.4g} {label}); check the specimen")
    return Stats(float(v.mean()), sd, int(v.size), tuple(float(x) for x in v), out, tuple(warns))


def spread_only(n: int) -> str | None:
    """The one warning for fewer than MIN_SAMPLES samples, or None."""
    if n >= MIN_SAMPLES:
        return None
    return (f"n = {n}: spread only (mean ± SD, no outlier flags); ISO 527-1 asks for at least "
            f"{MIN_SAMPLES} specimens, and outliers are flagged from n = {MIN_SAMPLES}")


def outliers(v: np.ndarray) -> tuple[int, ...]:
    """Indices whose modified z-score exceeds OUTLIER_Z (none when the MAD is zero)."""
    if v.size < 3:
        return ()
    med = np.median(v)
    mad = np.median(np.abs(v - med))
    if mad == 0:
        return ()
    z = MAD_SCALE * (v - med) / mad
    far = np.abs(v - med) > OUTLIER_MIN_REL * abs(med)
    return tuple(int(i) for i in np.nonzero((np.abs(z) > OUTLIER_Z) & far)[0])
