"""The scene stage's one way in: `build_scene` with a frozen `SceneOptions`; model-form options
are transforms that return a new scene and leave the one they were given as it was."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import reference_design_1_40
from proto_files import REALISTIC

from printgen.errors import GeometryError
from printgen.inputs.prototype import load_prototype
from printgen.scene import SceneOptions, build_scene
from printgen.scene.forms import held_on_bed, routed
from printgen.scene.mount import in_free_section
from printgen.scene.scenes import MOUNTINGS, PROTOTYPE_ORIENTATION, with_factors
from printgen.verification.variants import Variant, model_variants

SAME = 0.0  # a transform copies what it changes: the original's arrays stay equal, exactly


def _copy(s):
    return {"nodes": s.nodes.copy(), "fixed": s.fixed.copy(), "laws": list(s.laws),
            "wires": {k: w.exit.copy() for k, w in s.wires.items()},
            "assumptions": s.assumptions}


def test_options_are_frozen_and_checked():
    o = SceneOptions()
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.bed = "held"  # type: ignore[misc]
    with pytest.raises(GeometryError, match="bed = 'sunk' is not one of free, held"):
        SceneOptions(bed="sunk")
    with pytest.raises(GeometryError, match="coarsen = 0"):
        SceneOptions(coarsen=0)


def test_defaults_are_the_nominal_scenes():
    d = reference_design_1_40()
    s = build_scene(d)
    assert s.mounting == MOUNTINGS[0] and s.pressure == "flow" and s.rest_nodes is None
    p = load_prototype(REALISTIC)
    same = build_scene(p, SceneOptions(orientation=PROTOTYPE_ORIENTATION))
    assert build_scene(p).laws == same.laws


def test_the_prototype_takes_no_design_option():
    p = load_prototype(REALISTIC)
    with pytest.raises(GeometryError, match="prototype's scene takes neither"):
        build_scene(p, SceneOptions(coarsen=2))


def test_transforms_return_new_scenes_and_leave_theirs_unchanged():
    s = build_scene(reference_design_1_40(), SceneOptions(mounting="eyelets"))
    before = _copy(s)
    for t in (held_on_bed(s), routed(s, "downstream"), in_free_section(s, 0.3),
              with_factors(s, 0.5, 0.5, 2.0)):
        assert t is not s
    after = _copy(s)
    np.testing.assert_allclose(after["nodes"], before["nodes"], rtol=SAME, atol=SAME)
    assert np.array_equal(after["fixed"], before["fixed"])
    assert after["laws"] == before["laws"] and after["assumptions"] == before["assumptions"]
    for k, exit_point in before["wires"].items():
        assert np.array_equal(after["wires"][k], exit_point)


def test_options_compose_in_one_build():
    d = reference_design_1_40()
    o = SceneOptions(mounting="eyelets", bed="held", routing="downstream", span=0.3,
                     net_factor=0.5)
    s = build_scene(d, o)
    nominal = build_scene(d, SceneOptions(mounting="eyelets"))
    assert s.fixed[s.rows["bottom"]].all() and s.rest_nodes is not None
    assert s.laws[0] == nominal.laws[0].scaled(0.5)
    assert {a[0] for a in s.assumptions} >= {"bed", "sensor routing", "mounting span"}


def test_variants_are_data_in_the_report_order():
    """A variant is label, source, scene options, slack and effort; the list's order is the
    band's (and the report's), whatever order the sweeps start in."""
    variants, _ = model_variants(reference_design_1_40(), "walls", 0.3)
    assert all(isinstance(v, Variant) and v.source for v in variants)
    assert len({v.label for v in variants}) == len(variants)
    fs = "mounted in the 300 mm free section"
    assert [v.label for v in variants][-2:] == [fs, f"{fs}, bottom on the bed"]
    # the folded net of the free section, bottom free, is the band's longest sweep: it starts
    # first (the order the sweeps start in changes no number)
    assert max(variants, key=lambda v: v.effort).label == fs
