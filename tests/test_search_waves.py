"""The design search's wave stage (`printgen.search.waves`): the printable waves of the chosen
net, screened by the law up and across against the target law (the prototype's, through the
same blocked-net mapping), the best verified and kept only when the solver finds it closer to
the prototype than the straight net."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from conftest import EXAMPLES, planned, reference_design_1_40
from numpy.testing import assert_allclose

from printgen.barrier.patterns.curved import check_wave_mm
from printgen.errors import GeometryError
from printgen.scaling.record import Wave
from printgen.scaling.selection import target_net_law
from printgen.scaling.similitude import scale_targets
from printgen.search.waves import (
    LAW_REACH,
    WAVE_STEP_MM,
    law_strains,
    printable_waves,
    screen_waves,
    straight_screen,
    target_laws,
    wave_stage,
)

SMALL_STRAIN = 1e-4  # net strain at which the blocked net's law is its small-strain slope
SMALL_REL = 1e-3  # ... to this (the chord's turn is second order in the strain)
ROUNDED_MM = 1e-6  # meshes are recorded rounded to 1e-6 mm (space.MESH_DIGITS)


@pytest.fixture(scope="module")
def realistic():
    """The realistic prototype at 1:40 and the reference's TPE design: a measured, softening
    panel law against the prototype's stiffening one."""
    p, d = planned(EXAMPLES / "realistic_barrier.toml")
    return p, scale_targets(p, d.scale), reference_design_1_40()


def test_every_printable_wave_of_the_grid_and_no_other(realistic):
    _, _, d = realistic
    n, s = d.net, d.net.strand
    waves = printable_waves(n)
    assert waves and all(w.amplitude_mm % WAVE_STEP_MM == 0 for w in waves)
    for k in {w.half_waves for w in waves}:
        top = max(w.amplitude_mm for w in waves if w.half_waves == k)
        with pytest.raises(GeometryError):  # one step more is refused
            check_wave_mm(n.pattern, top + WAVE_STEP_MM, k, s.bead_width_mm, s.beads_across,
                          n.mesh_x_mm, n.mesh_y_mm)


def test_the_target_is_the_prototypes_law_up_the_barrier_at_small_strain(realistic):
    p, t, _ = realistic
    up, across = target_laws(p, t, np.array([SMALL_STRAIN]))
    slope = target_net_law(p, t)[1][0]
    assert_allclose(up, slope * SMALL_STRAIN, rtol=SMALL_REL)
    assert across[0] > 0
    eps = law_strains(p, t)
    assert eps[-1] == pytest.approx(LAW_REACH * target_net_law(p, t)[0][-1])


@pytest.mark.slow  # the beam model solves every printable wave's strand (about 8 s)
def test_waves_are_ranked_by_their_law_error_and_beat_straight_on_a_stiffening_target(
        realistic):
    # the realistic prototype's net stiffens (a knee at 20 % strain) where the straight TPE
    # net softens: unbending strands bring the law closer
    p, t, d = realistic
    ranked = screen_waves(p, t, d.net)
    errors = [r.error for r in ranked]
    assert errors == sorted(errors)
    up, across = straight_screen(p, t, d.net)
    assert ranked[0].error < np.hypot(up, across) / np.sqrt(2)


@pytest.mark.slow  # it screens every printable wave, as above
def test_the_stage_keeps_the_best_verified_wave_only_when_it_beats_straight(realistic):
    p, t, d = realistic
    seen = []

    def verify(designs):  # a stand-in for the solver: mismatch falls with the amplitude
        seen.extend(designs)
        return [1.0 / (1.0 + x.net.wave.amplitude_mm) for x in designs]

    better = wave_stage(p, t, d, 0.9, verify)
    assert [x.net.wave for x in seen] == [s.wave for s in better.screened[:len(seen)]]
    assert better.kept == max(better.verified, key=lambda w: w.amplitude_mm)
    assert "printed with" in better.sentence()
    worse = wave_stage(p, t, d, 0.1, verify)
    assert worse.kept is None and "straight strands are kept" in worse.sentence()
    assert worse.to_record()["kept"] is None


def test_a_net_without_printable_waves_keeps_straight_strands(realistic):
    p, t, d = realistic
    tight = dataclasses.replace(d, net=dataclasses.replace(  # strands as wide as the gap
        d.net, strand=dataclasses.replace(d.net.strand, beads_across=14)))
    choice = wave_stage(p, t, tight, 0.5, lambda ds: [0.0 for _ in ds])
    assert choice.screened == () and choice.kept is None
    assert "no printable wave" in choice.sentence()


def test_a_design_with_a_wave_round_trips(realistic, tmp_path):
    from printgen.scaling.design_file import load_design
    from printgen.search.waves import with_wave

    _, _, d = realistic
    w = with_wave(d, Wave(1.25, 1))
    path = tmp_path / "design.json"
    path.write_text(json.dumps(w.to_dict()))
    assert load_design(path) == w


# ------------------------------------------------------------------ square-mesh prototypes

def _simple_context():
    from printgen.inputs.prototype import load_prototype
    from printgen.search.space import default_space, search_context

    p = load_prototype(EXAMPLES / "simple_barrier.toml")
    t = scale_targets(p, 40)
    space = dataclasses.replace(default_space(p, t), materials=("tpe",), beads=(1,),
                                layers=(2,), border_beads=(2,))
    return p, t, search_context(p, t, space), space


def test_a_square_mesh_prototype_gets_square_candidates_in_whole_meshes():
    from printgen.barrier.patterns import get_pattern
    from printgen.search.space import grid

    p, t, ctx, space = _simple_context()
    points = grid(ctx, space)
    assert points and {q.pattern for q in points} == {"square"}
    for q in points:
        assert q.mesh_x_mm == q.mesh_y_mm
        lo, hi = space.mesh_x_mm
        assert lo - ROUNDED_MM <= q.mesh_x_mm <= hi + ROUNDED_MM
        assert q.half_cells_x % 2 == 0 and q.half_cells_y % 2 == 0  # whole meshes
        assert q.mesh_x_mm * q.half_cells_x / 2 == pytest.approx(ctx.width_mm)
        get_pattern("square").check_mesh(q.mesh_x_mm, q.mesh_y_mm)


def test_a_square_candidate_is_screened_and_built_as_a_square_net():
    from printgen.scaling.plan import make_design
    from printgen.scaling.section import net_membrane_law
    from printgen.scaling.selection import select
    from printgen.search.nets import candidate_design
    from printgen.search.screen import screen_point, strand_section
    from printgen.search.space import grid

    p, t, ctx, space = _simple_context()
    q = grid(ctx, space)[0]
    s = screen_point(ctx, q)
    law = net_membrane_law(ctx.material("tpe"), strand_section(ctx, q), q.mesh_y_mm * 1e-3,
                           q.mesh_x_mm * 1e-3, "square")
    assert s.membrane_n_per_m == law[1][0]
    assert s.opening_mm == pytest.approx(q.mesh_x_mm - strand_section(ctx, q).width_mm)
    d = candidate_design(ctx, q, make_design(p, t, select(p, t)))
    assert d.net.pattern == "square" and len(d.net.graph().nodes_mm) > 0


@pytest.mark.slow
def test_design_on_the_square_barrier_is_at_least_as_good_as_select():
    from printgen.run.options import RunOptions
    from printgen.run.search import SearchOptions, search_at_scales

    opts = SearchOptions(objective="deformation", border_beads=(2,), verify_nets=1,
                         level_step=0.1)
    res = search_at_scales(EXAMPLES / "simple_barrier.toml", [40.0], options=opts,
                           run=RunOptions(serial=True)).results[0]
    assert res.design.net.pattern == "square"
    best = res.verified[res.chosen].mismatch
    if res.wave is not None and res.wave.kept is not None:
        best = res.wave.verified[res.wave.kept]
    assert best <= res.select_score.mismatch
