"""The net: nodes, anchors, tension-only strands, sliding cables (SI units)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .laws import Law


@dataclass(frozen=True)
class SlidingCable:
    """A cable threaded through `nodes` (in order; ends normally on fixed anchors). The nodes
    slide along it without friction: one tension, from the total length of all its segments.

    rest_length : m; None means the initial length x (1 + slack of the net)
    """

    nodes: np.ndarray
    law: Law
    rest_length: float | None = None


@dataclass(frozen=True)
class Net:
    """A tension-only cable net.

    nodes : (n, 3) m; fixed : (n, 3) bool (or (n,) bool: all directions) anchors;
    elements : (m, 2) int node pairs; laws : list of Law; element_law : (m,) int index into
    laws; rest_length : (m,) m or None (= initial length x (1 + slack) / (1 + pretension
    strain)); slack : relative initial slack of every strand and cable (0.005 = 0.5 %);
    pretension : N, initial tension of every strand (needs slack = 0).
    """

    nodes: np.ndarray
    fixed: np.ndarray
    elements: np.ndarray
    laws: list[Law]
    element_law: np.ndarray | None = None
    rest_length: np.ndarray | None = None
    slack: float = 0.0
    pretension: float = 0.0
    cables: list[SlidingCable] = field(default_factory=list)

    def __post_init__(self) -> None:
        n = len(self.nodes)
        if self.nodes.ndim != 2 or self.nodes.shape[1] != 3:
            raise ValueError(f"nodes must be (n, 3), got {self.nodes.shape}")
        if self.elements.size and (self.elements.min() < 0 or self.elements.max() >= n):
            raise ValueError("element node index out of range")
        if self.slack < 0 or self.pretension < 0:
            raise ValueError("slack and pretension must be >= 0")
        if self.slack > 0 and self.pretension > 0:
            raise ValueError("give either initial slack or pretension, not both")

    @property
    def fixed_dofs(self) -> np.ndarray:
        """(n, 3) bool."""
        f = np.asarray(self.fixed, dtype=bool)
        return np.repeat(f[:, None], 3, axis=1) if f.ndim == 1 else f

    @property
    def law_index(self) -> np.ndarray:
        if self.element_law is None:
            return np.zeros(len(self.elements), dtype=int)
        return np.asarray(self.element_law, dtype=int)

    def rest_lengths(self) -> np.ndarray:
        """(m,) rest lengths of the strands."""
        if self.rest_length is not None:
            return np.asarray(self.rest_length, dtype=float)
        d = self.nodes[self.elements[:, 1]] - self.nodes[self.elements[:, 0]]
        length = np.linalg.norm(d, axis=1)
        if self.pretension > 0:
            eps0 = np.array([strain_at(self.laws[k], self.pretension) for k in self.law_index])
            return length / (1.0 + eps0)
        return length * (1.0 + self.slack)

    def cable_rest_length(self, c: SlidingCable) -> float:
        if c.rest_length is not None:
            return float(c.rest_length)
        p = self.nodes[c.nodes]
        return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) * (1.0 + self.slack)


def strain_at(law: Law, force: float) -> float:
    """Inverse of a tension-only law: the strain where it carries `force` N."""
    eps, f = 0.0, 0.0
    bounds = [*law.knees, np.inf]
    for k, slope in enumerate(law.slopes):
        span = bounds[k] - eps
        if f + slope * span >= force:
            return eps + (force - f) / slope
        f += slope * span
        eps = bounds[k]
    raise ValueError("unreachable")  # the last segment is unbounded
