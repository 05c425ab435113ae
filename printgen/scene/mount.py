"""The printed barrier mounted in the flume's free section: the paper's printed net
is about 330 mm wide (13.2 m / 40) while the side sheets leave a 300 mm free section
(barrier-physics.md, section 4). How the extra width is held is not stated. Two readings:
- "printed" (the default): the net spans its own printed width between the lateral supports
  (the extra width lies on the side sheets, or the sheets stand at the net's edges);
- "free-section": the lateral supports stand the free section apart, so the printed net and
  its cables are mounted with their printed lengths over a shorter span: every horizontal
  length is squeezed by span / width at rest, strands and cables keep their printed rest
  lengths (a slack of up to width / span - 1 across the barrier, 9.9 % at 1:40), and the
  sensors are zeroed on that slack net under their 1 N pulls.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from printgen.errors import GeometryError
from printgen.scene.scenes import BarrierScene

SPANS = ("printed", "free-section")


def in_free_section(s: BarrierScene, span: float) -> BarrierScene:
    """Scene `s` with its lateral supports `span` (m) apart: every x scaled by span / width
    (the wires' potentiometers too), the printed geometry kept as the strands' rest shape."""
    if not 0 < span <= s.width:
        raise GeometryError(f"free section {span * 1e3:g} mm must be positive and at most the "
                            f"barrier's width {s.width * 1e3:g} mm; check [flume] free_section_m")
    k = span / s.width
    nodes = s.nodes.copy()
    nodes[:, 0] *= k
    wires = {name: dataclasses.replace(w, exit=w.exit * np.array([k, 1.0, 1.0]))
             for name, w in s.wires.items()}
    note = ("mounting span", (f"lateral supports {span * 1e3:g} mm apart (the flume's free "
            f"section) for a net printed {s.width * 1e3:.4g} mm wide: squeezed by {k:.3f} at "
            "rest, strands and cables at their printed rest lengths"),
            "Lambert et al. 2023: 300 mm free section, printed barrier about 330 mm")
    return dataclasses.replace(s, nodes=nodes, rest_nodes=s.nodes, wires=wires,
                               assumptions=(*s.assumptions, note))
