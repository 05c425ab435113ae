"""Fuzz: random prototype files and scales never raise anything but the project's errors."""

from __future__ import annotations

import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from proto_files import write_variant

from printgen.design.selection import select
from printgen.design.similitude import scale_targets
from printgen.errors import PrintgenError
from printgen.inputs.prototype import load_prototype

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
