"""Tension-only force-strain laws: linear E*A or piecewise linear (stiffening or softening)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Law:
    """Force (N) of strain eps: zero for eps <= 0, slopes[i] (N per unit strain) on segment i.

    knees : (k,) increasing strains where the slope changes; slopes : (k+1,) N
    """

    knees: tuple[float, ...]
    slopes: tuple[float, ...]

    def __post_init__(self) -> None:
        if len(self.slopes) != len(self.knees) + 1:
            raise ValueError(f"a law needs one slope per segment: {len(self.knees)} knees, "
                             f"{len(self.slopes)} slopes")
        if any(k <= 0 for k in self.knees) or list(self.knees) != sorted(self.knees):
            raise ValueError(f"knees must be positive and increasing, got {self.knees}")
        if any(not np.isfinite(s) or s <= 0 for s in self.slopes):
            raise ValueError(f"slopes must be positive and finite, got {self.slopes}")

    def force_and_tangent(self, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(force N, tangent dF/deps N) at each strain; both zero when eps <= 0."""
        e = np.maximum(eps, 0.0)
        lo = np.array([0.0, *self.knees])
        width = np.append(np.diff(lo), np.inf)
        slopes = np.asarray(self.slopes)
        force = np.clip(e[..., None] - lo, 0.0, width) @ slopes
        tangent = slopes[np.searchsorted(np.asarray(self.knees), e, side="right")]
        return force, np.where(eps > 0, tangent, 0.0)

    def energy(self, eps: np.ndarray) -> np.ndarray:
        """Strain energy per unit rest length, integral of the force from 0 to eps (N)."""
        e = np.maximum(eps, 0.0)
        lo = np.array([0.0, *self.knees])
        width = np.append(np.diff(lo), np.inf)
        seg = np.clip(e[..., None] - lo, 0.0, width)  # strain spent on each segment
        before = np.concatenate([[0.0], np.cumsum(np.asarray(self.slopes[:-1]) * width[:-1])])
        return (np.asarray(self.slopes) * 0.5 * seg**2 + before * seg).sum(axis=-1)

    def scaled(self, factor: float) -> Law:
        return Law(self.knees, tuple(s * factor for s in self.slopes))


def linear(ea: float) -> Law:
    """Linear tension-only law of axial stiffness `ea` (N)."""
    return Law((), (float(ea),))


def piecewise(knees, slopes) -> Law:
    """Piecewise-linear tension-only law: strain knees, slopes in N per unit strain."""
    return Law(tuple(float(k) for k in knees), tuple(float(s) for s in slopes))
