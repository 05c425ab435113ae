"""Tension-only force-strain laws: linear E*A or piecewise linear (stiffening or softening)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

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

    # arrays reused by every evaluation, computed once per law (cached_property: not fields,
    # so equality, hashing and records see only knees and slopes)
    @cached_property
    def _lo(self) -> np.ndarray:
        return np.array([0.0, *self.knees])

    @cached_property
    def _width(self) -> np.ndarray:
        return np.append(np.diff(self._lo), np.inf)

    @cached_property
    def _slopes(self) -> np.ndarray:
        return np.asarray(self.slopes, dtype=float)

    @cached_property
    def _knees(self) -> np.ndarray:
        return np.asarray(self.knees, dtype=float)

    @cached_property
    def _before(self) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(self._slopes[:-1] * self._width[:-1])])

    def force_and_tangent(self, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(force N, tangent dF/deps N) at each strain; both zero when eps <= 0."""
        e = np.maximum(eps, 0.0)
        if not self.knees:  # linear: the common case, no segments to walk
            return self._slopes[0] * e, np.where(eps > 0, self._slopes[0], 0.0)
        force = np.clip(e[..., None] - self._lo, 0.0, self._width) @ self._slopes
        tangent = self._slopes[np.searchsorted(self._knees, e, side="right")]
        return force, np.where(eps > 0, tangent, 0.0)

    def evaluate(self, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(force N, tangent N, energy per unit rest length N) at each strain: the values of
        `force_and_tangent` and `energy`, segment by segment on 1-d arrays (the strain on
        segment i is clip(e - lo_i, 0, width_i); the first starts at 0, the last is open)."""
        e = np.maximum(eps, 0.0)
        s = self._slopes
        if not self.knees:
            return s[0] * e, np.where(eps > 0, s[0], 0.0), 0.5 * s[0] * e * e
        force = energy = None
        segments = zip(self._lo, self._width, self._before, strict=True)
        for i, (lo, width, before) in enumerate(segments):
            seg = e if i == 0 else np.maximum(e - lo, 0.0)
            if i < len(self.knees):
                seg = np.minimum(seg, width)
            f, w = seg * s[i], (s[i] * 0.5) * (seg * seg) + before * seg
            force, energy = (f, w) if force is None else (force + f, energy + w)
        assert force is not None and energy is not None  # knees: the loop ran at least once
        tangent = s[np.searchsorted(self._knees, e, side="right")]
        return force, np.where(eps > 0, tangent, 0.0), energy

    def energy(self, eps: np.ndarray) -> np.ndarray:
        """Strain energy per unit rest length, integral of the force from 0 to eps (N)."""
        e = np.maximum(eps, 0.0)
        if not self.knees:
            return 0.5 * self._slopes[0] * e * e
        seg = np.clip(e[..., None] - self._lo, 0.0, self._width)  # strain on each segment
        return (self._slopes * 0.5 * seg**2 + self._before * seg).sum(axis=-1)

    def scaled(self, factor: float) -> Law:
        return Law(self.knees, tuple(s * factor for s in self.slopes))


def linear(ea: float) -> Law:
    """Linear tension-only law of axial stiffness `ea` (N)."""
    return Law((), (float(ea),))


def piecewise(knees, slopes) -> Law:
    """Piecewise-linear tension-only law: strain knees, slopes in N per unit strain."""
    return Law(tuple(float(k) for k in knees), tuple(float(s) for s in slopes))
