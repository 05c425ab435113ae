"""`printgen series`, the virtual scale series (issue 26 item 3): E / lambda identical at every
scale, the linear rows against the (F/EA)^(1/3) law of a pure elastic net, the +-10 % sentence,
serial and Dask runs equal, the output folder, and bad input refused before anything is
written. Small nets (9 x 5 nodes) and few load levels keep it cheap."""

from __future__ import annotations

import json
import math

import pytest
from proto_files import REALISTIC, SIMPLE, write_variant

from printgen.cli import main
from printgen.errors import InputError
from printgen.run.options import RunOptions
from printgen.run.series import run_series
from printgen.verification.series import check_scales, net_options
from printgen.verification.series_table import in_band

SIMILITUDE_RTOL = 1e-9  # the bar: E / lambda reproduces the prototype to 1e-9
# Local exponents of the tiny steel net (deformations < 3 % of its size) read from steps of
# one decade: the pure law's 1/3 and 2/3 within this (measured 0.3334 and about 0.66)
LAW_EXPONENT_TOL = 0.02
LAW_DEPARTURE_TOL = 0.02  # steel's deflection within 2 % of the law anchored at the prototype
# porosity 0: the same loads as hydrostatic to round-off (test_loads: 1e-12)
JAM_AS_HYDROSTATIC_RTOL = 1e-9
# A warm start changes where Newton stops inside the solver's force tolerance (1e-7 of the
# load): the deformations agree to about 1e-6 (measured 2e-6 on the simple barrier's PETG)
WARM_RTOL = 1e-5
SIMILAR_ITERATIONS = 2  # the prototype's state scaled is the similar net's answer: 0 or 1 step


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """The simple barrier cut to 2 x 1 m with 0.25 m meshes (9 x 5 nodes)."""
    d = tmp_path_factory.mktemp("series")
    return write_variant(d, {("barrier", "width_m"): 2.0, ("barrier", "height_m"): 1.0,
                             ("net", "mesh_x_m"): 0.25, ("net", "mesh_y_m"): 0.25}, base=SIMPLE)


@pytest.fixture(scope="module")
def tiny_run(tiny):
    return run_series(tiny, [1, 10, 100], materials=("petg",), options=RunOptions(serial=True))


@pytest.fixture(scope="module")
def tiny_realistic(tmp_path_factory):
    """The realistic barrier cut to 2.64 x 0.8 m: border cables sliding, panel law."""
    d = tmp_path_factory.mktemp("series-real")
    return write_variant(d, {("barrier", "width_m"): 2.64, ("barrier", "height_m"): 0.8},
                         base=REALISTIC)


def _values(run, row):
    return [run.series.point(row, lam).values for lam in run.series.scales]


@pytest.mark.slow
def test_similitude_identical_at_every_scale(tiny_run):
    vals = _values(tiny_run, "similitude")
    for v in vals[1:]:
        for k in v:
            assert v[k] == pytest.approx(vals[0][k], rel=SIMILITUDE_RTOL), k
    steel = _values(tiny_run, "unscaled")
    assert steel[-1]["deflection"] < 0.3 * steel[0]["deflection"]  # Froude only: too stiff


@pytest.mark.slow
def test_similitude_on_the_realistic_scene(tiny_realistic):
    """Border cables sliding and a panel law: E / lambda is still exact; the 1 N sensors on
    the models (--solver-net sensors=on) do not scale and break it."""
    off = run_series(tiny_realistic, [1, 40], options=RunOptions(serial=True),
                     net=net_options("mounting=eyelets"))
    a, b = _values(off, "similitude")
    assert b["deflection"] == pytest.approx(a["deflection"], rel=SIMILITUDE_RTOL)
    on = run_series(tiny_realistic, [1, 40], options=RunOptions(serial=True),
                    net=net_options("mounting=eyelets,sensors=on"))
    a, b = _values(on, "similitude")
    assert abs(b["strain_mid"] / a["strain_mid"] - 1) > 0.1  # the wires pull 1 N at 1:40
    assert "not a pure elastic net" in " ".join(on.series.law["unscaled"]["explanation"])


def test_linear_rows_follow_the_cube_root_law(tiny_run):
    law = tiny_run.series.law
    for e in law["unscaled"]["local_exponents"]["deflection"]:
        assert e == pytest.approx(1 / 3, abs=LAW_EXPONENT_TOL)
    for e in law["unscaled"]["local_exponents"]["strain_mid"]:
        assert e == pytest.approx(2 / 3, abs=LAW_EXPONENT_TOL)
    assert max(abs(d) for d in law["unscaled"]["departure"]["deflection"]) < LAW_DEPARTURE_TOL
    assert law["unscaled"]["lowering_in_bracket"]
    # PETG: far from the prototype (large deformation) it departs more than near it
    dep = law["petg"]["departure"]["deflection"]
    assert abs(dep[-1]) < abs(dep[0])
    assert law["petg"]["pure_elastic_net"]


def test_sentence(tiny_run):
    text = tiny_run.series.sentences["petg"]
    ratio = tiny_run.series.point("petg", 100.0).ratio["deflection"]
    assert abs(ratio - 1) <= 0.10 and "PETG keeps deflection within +-10% of the prototype " \
        "for lambda = 100" in text
    assert "exact at lambda = 76.9" in text  # 100 GPa / 1.30 GPa
    assert in_band([(1, 0.5), (10, 0.95), (30, 1.05), (50, 1.2), (100, 1.0)]) == \
        [(10, 30), (100, 100)]
    assert in_band([(1, 2.0)]) == []


def test_warm_start_from_the_prototype_keeps_the_numbers(tiny):
    """Every case starts from the prototype's states scaled by 1 / lambda: the similitude
    row, the prototype scaled exactly, converges at once; each case's numbers are a cold
    solve's to the solver's tolerance; the similitude row at lambda = 1 is the prototype's
    case under its own row."""
    import dataclasses

    from printgen.barrier.loads import get_load
    from printgen.executor import open_runner
    from printgen.inputs.prototype import load_prototype
    from printgen.run.series import solve_cases
    from printgen.verification.series import (
        NetOptions,
        SeriesShared,
        cases,
        prototype_states,
        rows_for,
        solve_case,
    )

    p = load_prototype(tiny)
    cold = SeriesShared(p, tuple(rows_for(p, ["petg"])), get_load(None).spec, NetOptions())
    proto, states = prototype_states(cold)
    warm = dataclasses.replace(cold, start=states)
    assert sorted(states) == [0.0, 0.25, 0.5, 0.75, 1.0]
    for case in (("similitude", 10.0), ("petg", 100.0), ("unscaled", 10.0)):
        a, b = solve_case(cold, case), solve_case(warm, case)
        for k in a.values:
            assert b.values[k] == pytest.approx(a.values[k], rel=WARM_RTOL), (case, k)
        if case[0] == "similitude":
            assert b.iterations <= SIMILAR_ITERATIONS < a.iterations
    todo = cases(cold, (1.0, 10.0))
    with open_runner(serial=True) as runner:
        runs = solve_cases(runner, cold, todo)
    assert [(r.row, r.scale) for r in runs] == todo
    same = next(r for r in runs if (r.row, r.scale) == ("similitude", 1.0))
    assert same.values == proto.values and same.iterations == proto.iterations


@pytest.mark.slow
def test_serial_local_pool_and_dask_give_the_same_numbers(tiny):
    """One executor: the same cases serially, on this machine's pool and on a Dask scheduler
    (the route of work that may leave the machine) give the same numbers."""
    from printgen.executor.start import cores

    distributed = pytest.importorskip("distributed")
    serial = run_series(tiny, [1, 10], options=RunOptions(serial=True))
    local = run_series(tiny, [1, 10], options=RunOptions(serial=False, workers=min(2, cores())))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        remote = run_series(tiny, [1, 10],
                            options=RunOptions(scheduler=cluster.scheduler_address))
    assert "Dask scheduler" in remote.where and "Dask" not in local.where
    for other in (local, remote):
        assert [(r.row, r.scale, r.values) for r in other.results] == \
            [(r.row, r.scale, r.values) for r in serial.results]
        for a, b in zip(serial.results, other.results, strict=True):
            assert all((a.curves[k] == b.curves[k]).all() for k in a.curves)


@pytest.mark.slow
def test_cli_writes_the_folder(capsys, tiny, tmp_path):
    out = tmp_path / "series"
    assert main(["series", str(tiny), "--scales", "1,100", "--materials", "petg",
                 "--out", str(out)]) == 0
    names = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert {"report.html", "report.json", "series.csv", "manifest.json", "timings.json",
            "figures/01-scale-series.png", "figures/01-scale-series.svg"} <= names
    rec = json.loads((out / "report.json").read_text())
    assert rec["sentences"]["petg"].startswith("PETG keeps deflection")
    assert {a["what"] for a in rec["assumptions"]} >= {"scaling", "rows: materials", "loading"}
    lines = (out / "series.csv").read_text().splitlines()
    assert lines[0].startswith("row,lambda,deflection") and len(lines) == 1 + 3 * 2
    captured = capsys.readouterr()
    assert "PETG keeps deflection" in captured.out
    assert "\u2501" not in captured.err  # no progress bar on a stderr that is no terminal
    # the run's total ends after the figure and the report; the process's wall (the command
    # line's: the interpreter's start and the imports too) holds it
    times = json.loads((out / "timings.json").read_text())["timings_s"]
    assert 0 < times["cases"] < times["total"] <= times["wall"]


@pytest.mark.parametrize("terminal", ["0", "1"])
def test_the_status_line_runs_no_thread(monkeypatch, capsys, terminal):
    """The command's status line starts no thread, on a terminal (drawn when its text
    changes, then erased) or off one (nothing drawn): a process running a thread starts its
    workers from a fork server, which imports the cases' modules again, instead of forking
    them with those imported."""
    import threading

    from printgen.commands.series import spinner

    monkeypatch.setenv("TTY_COMPATIBLE", terminal)  # rich's switch: stderr is a terminal or not
    before = threading.active_count()
    with spinner("reading inputs") as status:
        status.update("15 cases ...")
        assert threading.active_count() == before
    err = capsys.readouterr().err
    assert ("15 cases ..." in err) == (terminal == "1")


@pytest.mark.parametrize("argv, word", [
    (["--scales", "0,10"], "scale 0"),
    (["--scales", "-1"], "scale -1"),
    (["--scales", "1,x"], "--scales"),
    (["--materials", "unobtainium"], "unobtainium"),
    (["--solver-net", "mounting=glue"], "mounting"),
    (["--solver-net", "slack=2"], "slack"),
    (["--solver-net", "colour=red"], "colour"),
])
def test_bad_input_exits_2_and_writes_nothing(capsys, tiny, tmp_path, argv, word):
    out = tmp_path / "never"
    assert main(["series", str(tiny), "--out", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_check_scales():
    assert check_scales([10, 1, 10.0]) == (1.0, 10.0)
    for bad in ([], [math.nan], [math.inf], [0.5e4]):
        with pytest.raises(InputError):
            check_scales(bad)


@pytest.mark.slow
def test_sensor_row_says_the_models_pull(tiny_realistic):
    on = run_series(tiny_realistic, [1, 40], options=RunOptions(serial=True),
                    net=net_options("sensors=on"))
    rows = {a[0]: a[1] for a in on.series.assumptions}
    assert "1 N along each wire on the models" in rows["sensor wires"]
    assert "read only (no sensors" not in rows["sensor wires"]
    assert rows["sensors"].startswith("three 1 N wires pulling")


@pytest.mark.slow
def test_jam_of_porosity_zero_runs_as_hydrostatic(tiny):
    """The series takes a load case's parameters (its spec) and hands each scale its own
    depth and lambda: a jam of porosity 0 is a wall of logs, the hydrostatic case (issue 26's
    limiting case), at every scale."""
    jam = run_series(tiny, [1, 10], options=RunOptions(load="jam:porosity=0", serial=True))
    hyd = run_series(tiny, [1, 10], options=RunOptions(serial=True))
    assert jam.record["load_case"].startswith("jam:") and "porosity=0" in jam.record["load_case"]
    for lam in (1, 10):
        a = jam.series.point("similitude", lam).values
        b = hyd.series.point("similitude", lam).values
        for k in b:
            assert a[k] == pytest.approx(b[k], rel=JAM_AS_HYDROSTATIC_RTOL), k


def test_a_huge_series_is_refused_before_any_solve(tmp_path, capsys):
    """A net of millions of nodes is refused with its estimate (exit 2), not run out of
    memory (exit 1), and nothing is written."""
    huge = write_variant(tmp_path, {("net", "mesh_x_m"): 0.005, ("net", "mesh_y_m"): 0.005},
                         base=SIMPLE)
    out = tmp_path / "o"
    assert main(["series", str(huge), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "this series is too big" in err and "--time-limit" in err and "GB" in err, err
    assert not out.exists()
