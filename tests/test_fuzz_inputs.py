"""Fuzz: random prototype files and scales never raise anything but the project's errors."""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from proto_files import write_variant

from printgen.errors import PrintgenError
from printgen.inputs.prototype import load_prototype
from printgen.scaling.selection import select
from printgen.scaling.similitude import scale_targets

KEYS = [("barrier", "width_m"), ("barrier", "height_m"), ("barrier", "anchors"),
        ("net", "mesh_x_m"), ("net", "mesh_y_m"), ("net", "strand_diameter_mm"),
        ("net", "pretension_n"), ("net", "pattern"), ("net", "panel_law", "kappa_kn_per_m_per_m"),
        ("net", "panel_law", "knee_strain_percent"), ("border", "modulus_gpa"),
        ("flow", "velocity_m_per_s"), ("flow", "depth_m"), ("flume", "width_m"),
        ("model", "mesh_x_mm"), ("model", "materials"), ("barrier", "bogus")]
VALUES = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False, width=32), st.integers(-10**6, 10**6),
    st.booleans(), st.text(max_size=5), st.none(),
    st.lists(st.floats(min_value=-100, max_value=2000, allow_nan=False), max_size=3),
    st.lists(st.sampled_from(["tpe", "petg", "nylon"]), max_size=2))
SCALES = st.one_of(st.floats(min_value=-5, max_value=500), st.just(math.nan), st.just(math.inf))


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits=st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=3), scale=SCALES)
def test_random_inputs_raise_only_project_errors(tmp_path, edits, scale):
    path = write_variant(tmp_path, edits)
    try:
        p = load_prototype(path)
        t = scale_targets(p, scale)
        select(p, t)
    except PrintgenError as exc:
        assert str(exc)  # every project error carries a message


# Issue 20: values that reached the maths (or Python's limits) and ended as an internal error.
HUGE_INTS = st.integers(min_value=10**300, max_value=10**400)
TINY = st.one_of(st.floats(min_value=0.0, max_value=1e-300), st.just(5e-324))
NESTED = st.recursive(st.integers(-3, 3) | st.text(max_size=3),
                      lambda kids: st.lists(kids, max_size=3)
                      | st.dictionaries(st.text(max_size=3), kids, max_size=3), max_leaves=10)
CONTROL_TEXT = st.text(st.characters(codec="utf-8", categories=("Cc", "Ll")), min_size=1,
                       max_size=6)
HOSTILE = st.one_of(HUGE_INTS, TINY, NESTED, CONTROL_TEXT, st.floats(min_value=1e300),
                    st.lists(st.one_of(st.integers(), NESTED), max_size=3))
ALL_KEYS = [*KEYS, ("name",), ("description",), ("flume", "froude_min"),
            ("flume", "froude_max"), ("model", "printer"), ("net", "strand_modulus_gpa"),
            ("flow", "density_kg_per_m3"), ("net", "panel_law", "panel_length_m")]


@pytest.mark.slow
@settings(max_examples=80, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(edits=st.dictionaries(st.sampled_from(ALL_KEYS), HOSTILE, min_size=1, max_size=2))
def test_hostile_prototype_values_are_project_errors(tmp_path, edits):
    """400-digit integers, 1e-300, nested tables, control characters, lists of anything:
    either a valid prototype or a PrintgenError, never another exception (input stage and
    the size estimate only: no solve)."""
    from printgen.run.api import plan
    from printgen.run.budget import estimate

    path = write_variant(tmp_path, edits)
    try:
        p = load_prototype(path)
        estimate(p, plan(p, 40), cores=2)
    except PrintgenError as exc:
        assert str(exc) and "\n" not in str(exc)


def design_dict() -> dict:
    from conftest import reference_design_1_40

    return reference_design_1_40().to_dict()


DESIGN_KEYS = [("scale",), ("printer",), ("net", "material"), ("net", "width_mm"),
               ("net", "mesh_x_mm"), ("net", "border_width_mm"), ("net", "strand", "beads_across"),
               ("net", "strand", "layer_heights_mm"), ("cables",), ("net", "strand")]


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(key=st.sampled_from(DESIGN_KEYS), value=HOSTILE)
def test_hostile_design_values_are_input_errors(key, value):
    from printgen.errors import InputError
    from printgen.scaling.design_file import design_from_dict

    data = design_dict()
    node = data
    for k in key[:-1]:
        node = node[k]
    node[key[-1]] = value
    try:
        design_from_dict(data)
    except InputError as exc:
        assert str(exc) and "\n" not in str(exc)
