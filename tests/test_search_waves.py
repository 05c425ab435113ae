"""The design search's wave stage (`printgen.search.waves`): the printable waves of the chosen
net, screened by the law up and across against the target law (the prototype's, through the
same blocked-net mapping), the best verified and kept only when the solver finds it closer to
the prototype than the straight net."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from conftest import EXAMPLES, planned
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


@pytest.fixture(scope="module")
def realistic():
    p, d = planned(EXAMPLES / "realistic_barrier.toml")
    return p, scale_targets(p, d.scale), d


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
