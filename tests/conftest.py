"""Shared fixtures: paths, the slicer requirement (CI fails instead of skipping), the whole runs
shared by the xdist workers, and the `slow` mark of the tests that read them."""

from __future__ import annotations

import dataclasses
import os
import pickle
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
EXAMPLES = ROOT / "examples"


def require_tool(name: str) -> str:
    """Return the path of a slicer executable; skip locally, fail under CI, when it is missing."""
    path = shutil.which(name)
    if path:
        return path
    msg = f"{name} not installed (bash scripts/setup.sh --with-slicers installs it)"
    if os.environ.get("PRINTGEN_REQUIRE_SLICERS") or os.environ.get("CI"):
        pytest.fail(msg)
    pytest.skip(msg)


def require_module(name: str):
    """Import an optional package (cadquery for STEP); skip locally, fail under CI, when it
    is missing (scripts/test.sh installs the `cad` extra)."""
    try:
        return __import__(name)
    except ImportError:
        msg = f"{name} not installed (pip install -e '.[cad]'; scripts/test.sh installs it)"
        if os.environ.get("PRINTGEN_REQUIRE_SLICERS") or os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)


def require_shared(rel: str) -> Path:
    """Return a path under ../shared; skip when it is missing, fail instead when
    PRINTGEN_REQUIRE_SHARED=1 (scripts/test.sh beside ../shared, and CI)."""
    path = SHARED / rel
    if path.exists():
        return path
    msg = f"{path} not found (the shared/ folder sits beside the clone)"
    if shared_required():
        pytest.fail(f"{msg}; PRINTGEN_REQUIRE_SHARED=1 makes the ../shared tests mandatory")
    pytest.skip(msg)


def shared_required() -> bool:
    """True when PRINTGEN_REQUIRE_SHARED is set to anything but '' or '0' (CI sets 1)."""
    return os.environ.get("PRINTGEN_REQUIRE_SHARED", "").strip() not in ("", "0")


def reference_design_1_40():
    """The reference's final 1:40 design (barrier-physics.md): TPE diamond net 20.6 x 9.4 mm
    with 0.6 x 0.95 mm strands (three passes), PETG cables 0.9 x 0.6 mm (2 x 2 passes)."""
    from printgen.scaling.record import CableDesign, Design, NetDesign, Section

    net = NetDesign(
        material="tpe", print_style="net-3pass", width_mm=330.0, height_mm=100.0,
        mesh_x_mm=20.6, mesh_y_mm=9.4, strand=Section(0.6, 1, (0.35, 0.30, 0.30)),
        border_width_mm=1.2,
    )
    cable = Section(0.45, 2, (0.30, 0.30))
    cables = tuple(
        CableDesign(name=n, material="petg", print_style="cable-4pass", length_mm=length,
                    section=cable, eyelet_inner_mm=3.0, eyelet_outer_mm=6.0)
        for n, length in (("top", 345.0), ("bottom", 345.0), ("left", 115.0), ("right", 115.0))
    )
    return Design(scale=40.0, printer="generic-350", net=net, cables=cables)


@pytest.fixture
def design_1_40():
    return reference_design_1_40()


def coarse_design_1_40(coarser: float):
    """The reference 1:40 design with its net's mesh `coarser` times coarser each way: the
    same scene on fewer nodes, for fast sweeps."""
    d = reference_design_1_40()
    n = d.net
    return dataclasses.replace(d, net=dataclasses.replace(
        n, mesh_x_mm=n.mesh_x_mm * coarser, mesh_y_mm=n.mesh_y_mm * coarser))


def planned(path: Path, scale: float = 40):
    """(prototype, design) of a prototype file at 1:scale: similitude, selection and the
    design, as `make` plans them."""
    from printgen.inputs.prototype import load_prototype
    from printgen.scaling.plan import make_design
    from printgen.scaling.selection import select
    from printgen.scaling.similitude import scale_targets

    p = load_prototype(path)
    t = scale_targets(p, scale)
    return p, make_design(p, t, select(p, t))


PIECE_FILES = (".stl", ".3mf", ".prusa.ini", ".gcode", ".specimen.toml")  # each test piece's


def piece_files(piece: str) -> set[str]:
    """The files `printgen testpieces` writes for one piece ("coupon", "panel", ...)."""
    return {piece + suffix for suffix in PIECE_FILES}


def write_test_pieces(d, root: Path):
    """`printgen testpieces` of design `d` through its design.json in `root`: (d, the
    record, the output folder)."""
    from printgen.report.jsonout import dumps
    from printgen.run.testpieces import testpieces

    path = root / "design.json"
    path.write_text(dumps(d.to_dict()))
    return d, testpieces(path, root / "out"), root / "out"


PIECE_SLICE_TIMEOUT_S = 300  # s: PrusaSlicer and the checker on one test piece, loaded machine


def slice_check_piece(d, out: Path, piece: str, tmp_path: Path, width: str | None = None
                      ) -> str:
    """Slice test piece `piece` of design `d` (in folder `out`) with PrusaSlicer and check
    the G-code with the shared checker (slice_check.sh) at the net strand's bead, or at
    `width` (mm, as text); assert it passes and return the checker's last line."""
    import os
    import subprocess
    import sys

    from printgen.inputs.materials import load_material

    require_tool("prusa-slicer")
    script = require_shared("tools/gcode/slice_check.sh")
    mat = load_material(d.net.material).print
    env = dict(os.environ, OUT_DIR=str(tmp_path), PYTHON=sys.executable)
    r = subprocess.run(
        ["bash", str(script), str(out / f"{piece}.stl"), str(out / f"{piece}.prusa.ini"),
         "--width", width or f"{d.net.strand.bead_width_mm}", "--area-model", "stadium",
         "--layers", f"{len(d.net.strand.layer_heights_mm)}",
         "--max-flow", f"{mat.max_volumetric_flow_mm3_per_s:g}"],
        capture_output=True, text=True, env=env, timeout=PIECE_SLICE_TIMEOUT_S, check=False)
    last = r.stdout.strip().splitlines()[-1] if r.stdout.strip() else r.stderr
    assert r.returncode == 0, last
    assert last.startswith("SLICE-CHECK OK"), last
    return last


def coarse_simple_file(folder: Path) -> Path:
    """examples/simple_barrier.toml on a mesh twice as coarse (COARSE_SIMPLE), written in
    `folder`: the same scene on fewer nodes."""
    from proto_files import SIMPLE, write_variant

    return write_variant(folder, COARSE_SIMPLE, base=SIMPLE)


SHARED_RUN_WAIT_S = 3600.0  # a whole make on a machine loaded many times over, with slack
POLL_S = 0.2


def shared_run(tmp_path_factory, name: str, build: Callable[[Path], Any]) -> Any:
    """`build(folder)` once per test session, also under pytest-xdist: a session-scoped
    fixture is per worker there, so the first worker to ask builds (into its own temporary
    folder) and pickles the result; the other workers wait for it and load it. The result
    and its folder are read only (a test that changes them copies them first). The files are
    named for the test run (xdist's run id): a --basetemp reused by a later run, whose workers
    empty only their own folders, never hands that run an old result."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        return build(tmp_path_factory.mktemp(name))
    root = tmp_path_factory.getbasetemp().parent  # the session's, above each worker's
    stem = f"{name}.{os.environ.get('PYTEST_XDIST_TESTRUNUID', 'run')}"
    done, failed = root / f"{stem}.pickle", root / f"{stem}.failed"
    try:
        fd = os.open(root / f"{stem}.claim", os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return _wait_for(done, failed)
    os.close(fd)
    try:
        result = build(tmp_path_factory.mktemp(name))
    except BaseException as exc:
        failed.write_text(f"{type(exc).__name__}: {exc}")
        raise
    part = root / f"{stem}.pickle.part"
    part.write_bytes(pickle.dumps(result))
    part.replace(done)  # the waiting workers see the whole file or none
    return result


def _wait_for(done: Path, failed: Path) -> Any:
    deadline = time.monotonic() + SHARED_RUN_WAIT_S
    while not done.exists():
        if failed.exists():
            pytest.fail(f"the shared run failed in another worker: {failed.read_text()}")
        if time.monotonic() > deadline:
            pytest.fail(f"{done.name} not written within {SHARED_RUN_WAIT_S:g} s")
        time.sleep(POLL_S)
    return pickle.loads(done.read_bytes())


@pytest.fixture(scope="session")
def made_1_40(tmp_path_factory):
    """One whole `make` of the 1:40 example (examples/realistic_barrier.toml) per session
    (`shared_run`: one for all xdist workers), (its MakeContext, its output folder), for every
    test that only reads the outputs: a test that changes them copies them or makes its own
    run."""
    return shared_run(tmp_path_factory, "make-1-40", _make_1_40)


def _make_1_40(tmp: Path):
    from proto_files import REALISTIC

    import printgen.run.make as make_mod

    return make_mod.make(REALISTIC, 40, tmp / "out"), tmp / "out"


COARSE_SIMPLE = {("net", "mesh_x_m"): 0.4, ("net", "mesh_y_m"): 0.4,
                 ("model", "mesh_x_mm"): 10.0, ("model", "mesh_y_mm"): 10.0}


@pytest.fixture(scope="session")
def made_simple_drag(tmp_path_factory):
    """One `make` of the simple barrier (no border cables) on a coarse mesh (COARSE_SIMPLE),
    its verification step only, under the drag load case, run inline (PRINTGEN_SERIAL=1: no
    helper process) per session (`shared_run`): (its MakeContext, its output folder, its
    prototype file), for the tests that read the verification step's record and report."""
    return shared_run(tmp_path_factory, "make-simple-drag", _make_simple_drag)


def _make_simple_drag(tmp: Path):
    import printgen.run.make as make_mod
    from printgen.run import api

    path = coarse_simple_file(tmp)
    verify_only = [s for s in make_mod.default_steps() if s[1] is make_mod.verify_step]
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PRINTGEN_SERIAL", "1")
        mp.setattr(make_mod, "helper", None)  # inline: a helper would fail here
        mp.setattr(make_mod, "default_steps", lambda: verify_only)
        ctx = api.make(path, 40, tmp / "out", drag=True)
    return ctx, tmp / "out", path


# A test that reads one of these whole runs is a whole-pipeline test: `slow`, whatever its own
# duration (the first to ask pays for the run).
WHOLE_RUN_FIXTURES = {"made_1_40", "made_simple_drag"}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark `slow` every test that uses a whole run (`pytest -m "not slow"`: CONTRIBUTING.md)."""
    for item in items:
        if WHOLE_RUN_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.slow)


def alive(pid: int) -> bool:
    """True while process `pid` runs (Linux /proc: a zombie counts as ended)."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return text[text.rindex(")") + 2] != "Z"
