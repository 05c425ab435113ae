"""Design search (printgen design): Pareto sets, the same JSON serially and on Dask, bad input.

The grid is small and coarse (two materials, one bead, three layer counts, coarse meshes) and
the solver stage runs at a coarse load step, so the whole file stays well under a minute.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import EXAMPLES

from printgen.errors import InputError
from printgen.report.jsonout import dumps
from printgen.run.options import RunOptions
from printgen.run.search import SearchOptions, search_at_scales
from printgen.scaling.design_file import design_from_dict, load_design
from printgen.search.pareto import dominates, pareto_mask

REALISTIC = EXAMPLES / "realistic_barrier.toml"
SCALE = 40.0
COARSE_STEP = 0.275  # solver stage at h/h_B = 0, 0.275, ..., 1.1: enough to compare runs
SMALL = SearchOptions(objective="deformation", materials=("tpe", "petg"),
                      mesh_x_mm=(26.0, 30.0), mesh_y_mm=(12.5, 14.5), border_beads=(2, 4),
                      verify_nets=1, level_step=COARSE_STEP)

pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def serial_run():
    return search_at_scales(REALISTIC, [SCALE], options=SMALL, run=RunOptions(serial=True))


def _objectives(rec: dict, rows: list[dict]) -> np.ndarray:
    key = "mismatch_rms" if rec["objective"] == "deformation" else None
    return np.array([[r["verification"]["mismatch_rms"] if key else r["error_rms_log"],
                      abs(r["d_pi2"]), abs(r["d_pi3"]), r["print_time_s"]] for r in rows])


def test_pareto_mask_analytic():
    v = np.array([[1, 2], [2, 1], [2, 2], [1, 2], [0.5, 3]])
    assert pareto_mask(v).tolist() == [True, True, False, True, True]  # equal rows both kept
    assert dominates(np.array([1, 1]), np.array([1, 2]))
    assert not dominates(np.array([1, 2]), np.array([1, 2]))
    with pytest.raises(ValueError, match="finite"):
        pareto_mask(np.array([[np.nan, 1.0]]))


@pytest.mark.slow
def test_pareto_set_has_no_dominated_member(serial_run):
    rec = serial_run.record["scales"][f"{SCALE:g}"]
    verified = rec["verified"]
    assert verified and rec["pareto"]["members"]
    members = {m[0] for m in rec["pareto"]["members"]}
    vals = _objectives(rec, verified)
    index = [r["index"] for r in verified]
    for i, row in zip(index, vals, strict=True):
        beaten = any(dominates(other, row) for other in vals)
        assert (i in members) == (not beaten), f"candidate {i}: member {i in members}"


@pytest.mark.slow
def test_stiffness_objective_pareto_over_every_printable_candidate(tmp_path, monkeypatch):
    import printgen.run.search as run_search
    from printgen.commands.design import SHOW, shown_rows
    from printgen.run import api

    writes = []
    write = run_search.write_folder
    monkeypatch.setattr(run_search, "write_folder", lambda *a, **k: writes.append(a) or
                        write(*a, **k))
    run = api.search_nets(REALISTIC, [SCALE], options=SearchOptions(
        objective="stiffness", materials=("tpe", "tpu"), mesh_x_mm=(18.0, 22.0),
        mesh_y_mm=(8.0, 10.0)), serial=True, out=tmp_path / "o")
    assert len(writes) == 1 and "design.json" in run.files  # one folder, written once
    res = run.results[0]
    rows = shown_rows(res)  # the table's rows: the chosen net first, marked "* "
    assert rows[0] == res.chosen and len(rows) == min(SHOW, len(set(res.pareto) | {rows[0]}))
    strength = [r for s in res.screened for k, r in s.violations if k == "strength"]
    assert strength and all(", mesh " in r for r in strength)  # the net named unambiguously
    assert not res.verified and res.select_score is None  # no solver with this objective
    feasible = [s for s in res.screened if s.feasible]
    vals = np.array([[s.error_rms_log, abs(s.d_pi2), abs(s.d_pi3), s.print_time_s]
                     for s in feasible])
    members = set(res.pareto)
    for s, row in zip(feasible, vals, strict=True):
        assert (s.point.index in members) == (not any(dominates(o, row) for o in vals))
    assert res.chosen == min(feasible, key=lambda s: (s.score, s.point.index)).point.index


@pytest.mark.slow
def test_same_json_serial_local_cluster_and_remote_scheduler(serial_run):
    from distributed import LocalCluster

    local = search_at_scales(REALISTIC, [SCALE], options=SMALL, run=RunOptions(workers=2))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        remote = search_at_scales(REALISTIC, [SCALE], options=SMALL,
                                  run=RunOptions(scheduler=cluster.scheduler_address))
    assert "local pool" in local.where and "Dask scheduler" in remote.where
    ref = dumps(serial_run.record)
    assert dumps(local.record) == ref
    assert dumps(remote.record) == ref
    assert len(serial_run.results[0].verified) == 2  # one net x two border widths


@pytest.mark.slow
def test_report_names_choice_select_pick_and_design_round_trips(serial_run, tmp_path):
    from printgen.run.search import write_outputs

    rec = serial_run.record["scales"][f"{SCALE:g}"]
    assert rec["chosen"]["feasible"] and rec["chosen"]["safety_factor"] >= 1.5
    assert rec["select_pick"]["verification"]["mismatch_rms"] > 0
    assert isinstance(rec["mismatch_lower_than_select"], bool)
    assert rec["reasons"][0].startswith("chosen:")
    files = write_outputs(serial_run, tmp_path / "out", SCALE)
    assert {"report.json", "candidates.json", "design.json", "pareto-1-40.png"} <= set(files)
    d = load_design(tmp_path / "out" / "design.json")
    assert d == serial_run.results[0].design
    table = json.loads((tmp_path / "out" / "candidates.json").read_text())
    assert len(table["40"]["rows"]) == rec["counts"]["screened"]


def test_bad_input_is_named():
    with pytest.raises(InputError, match="mesh x bounds"):
        search_at_scales(REALISTIC, [SCALE], options=SearchOptions(mesh_x_mm=(20.0, 10.0)),
                         run=RunOptions(serial=True))
    with pytest.raises(InputError, match="objective"):
        search_at_scales(REALISTIC, [SCALE], options=SearchOptions(objective="speed"),
                         run=RunOptions(serial=True))
    with pytest.raises(InputError, match="unknown keys"):
        design_from_dict({"scale": 40, "printer": "generic-350", "net": {}, "cables": [],
                          "colour": "red"})


def test_cli_exit_2_without_scale(capsys):
    from printgen.cli import main

    assert main(["design", str(REALISTIC), "--serial"]) == 2
    assert "--scale" in capsys.readouterr().err


@pytest.mark.parametrize(("extra", "message"), [
    (["--mesh-x-mm", "2:150", "--mesh-y-mm", "1:60"],
     "the search space holds 10,275,520 nets .* over the 500,000"),
    (["--level-step", "1e-6"], "--level-step 1e-06 is outside 0.005 to 1.1"),
    (["--level-step", "nan"], "--level-step nan is outside"),
])
def test_a_search_too_large_is_refused_before_any_work(tmp_path, capsys, extra, message):
    import re

    from printgen.cli import main

    out = tmp_path / "o"
    assert main(["design", str(EXAMPLES / "realistic_barrier.toml"), "--scale", "40",
                 "--serial", "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err) and len(err.strip().splitlines()) == 1, err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_a_search_over_its_time_limit_is_refused_before_any_work(tmp_path, capsys):
    from printgen.cli import main

    out = tmp_path / "o"
    assert main(["design", str(EXAMPLES / "simple_barrier.toml"), "--scale", "40", "--serial",
                 "--time-limit", "5", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "this design search is too big: 228,800 nets to screen and 31 to verify" in err, err
    assert "--time-limit" in err and not out.exists()


def test_solver_batches_group_one_net_graph_per_job_largest_first(design_1_40):
    import dataclasses

    from printgen.search.nets import VerifyTask, solver_batches

    def net(d, **kw):
        return dataclasses.replace(d, net=dataclasses.replace(d.net, **kw))

    fine = net(design_1_40, mesh_x_mm=10.3, mesh_y_mm=4.7)  # four times the nodes
    tasks = [VerifyTask("a", design_1_40), VerifyTask("b", fine),
             VerifyTask("c", net(design_1_40, border_width_mm=2.4)),  # one graph with "a"
             VerifyTask("d", net(fine, material="petg"))]
    jobs = solver_batches(tasks)
    assert [[t.key for t in j.tasks] for j in jobs] == [["b", "d"], ["a", "c"]]
    assert solver_batches(list(reversed(tasks)))[0].tasks[0].key == "d"  # task order kept


@pytest.mark.slow  # four sweeps of a coarse 1:40 model and one of its prototype (~1-3 s)
def test_a_batch_warm_start_keeps_the_cold_scores(design_1_40):
    import dataclasses

    from conftest import coarse_design_1_40

    from printgen.inputs.prototype import load_prototype
    from printgen.run.search import prototype_sweep, verify_batch, verify_task
    from printgen.search.nets import SolverBatch, VerifyShared, VerifyTask

    p = load_prototype(REALISTIC)
    d = coarse_design_1_40(2.0)
    wide = dataclasses.replace(d, net=dataclasses.replace(d.net, border_width_mm=2.4))
    shared = VerifyShared(p, COARSE_STEP)
    shared = dataclasses.replace(shared, prototype_run=prototype_sweep(shared, d))
    cold = [verify_task(shared, VerifyTask(k, x)) for k, x in (("a", d), ("b", wide))]
    first, again, other = verify_batch(shared, SolverBatch((
        VerifyTask("a", d), VerifyTask("a2", d), VerifyTask("b", wide))))
    levels = round(1.1 / COARSE_STEP) + 1
    # the same design started from its own converged states: each level is solved at once
    # (at most one Newton step per level), where the cold path needs several
    assert again.iterations <= levels < first.iterations
    # a start, never the answer: the scores agree to the solver's tolerance (SOLVER_TOL is
    # 1e-7 of the load; the normalised deformations move less than 1e-6 of their peaks)
    for warm, ref in ((first, cold[0]), (again, cold[0]), (other, cold[1])):
        assert warm.mismatch == pytest.approx(ref.mismatch, rel=1e-6)
        for m, v in ref.per_metric.items():
            assert warm.per_metric[m] == pytest.approx(v, rel=1e-6, abs=1e-9)
        assert warm.ok == ref.ok and warm.failed_levels == ref.failed_levels
