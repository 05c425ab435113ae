"""printgen in a notebook: every public result has a short repr and an HTML table of its verdict
and key numbers; the verification curves come as rows or a pandas DataFrame named and scaled as
curves.csv; the plot helpers return a Figure or draw on the axes given."""

from __future__ import annotations

import csv
import sys

import numpy as np
import pytest
from conftest import EXAMPLES

import printgen
from printgen.errors import InputError, PrintgenError
from printgen.outputs.display import MAX_REPR_CHARS, Summary, frame
from printgen.verification.measured import LEVEL_COLUMN

REALISTIC = EXAMPLES / "realistic_barrier.toml"
# curves.csv holds 8 significant digits (printgen.report.labfiles.DIGITS): the table's values
# are the unrounded numbers
CSV_RTOL = 1e-7
CSV_ATOL = 1e-6  # labfiles.NOISE: smaller values are written as 0


def shows_short(result: object, *words: str) -> str:
    """`result`'s repr (checked short, with `words`) and its HTML table (checked a table)."""
    text = repr(result)
    assert len(text) <= MAX_REPR_CHARS, (type(result).__name__, len(text))
    html = result._repr_html_()
    assert html.startswith("<div>") and "<table>" in html and len(html) < 4 * MAX_REPR_CHARS
    for w in words:
        assert w in text and w in html, (w, text)
    return text


def test_every_public_name_resolves_and_import_stays_light():
    """`import printgen` loads no numpy, matplotlib, pandas or setuptools-scm: each public
    name is imported when first used."""
    import subprocess

    from conftest import ROOT

    code = ("import sys, printgen; print(sorted(m for m in ('numpy', 'matplotlib', 'pandas', "
            "'setuptools_scm') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, check=True)
    assert done.stdout.strip() == "[]"
    assert {"plot_curves", "plot_net", "__version__"} <= set(printgen.__all__)
    assert all(getattr(printgen, name, None) is not None for name in printgen.__all__)
    assert {"plot_curves", "plot_net"} <= set(dir(printgen))


def test_summary_is_cut_and_escaped():
    s = Summary("T <1:40>", tuple((f"row {i}", "x" * 80) for i in range(100)), "PASS")
    assert len(s.text()) == MAX_REPR_CHARS and s.text().endswith("...")
    assert "T &lt;1:40&gt;" in s.html() and "<1:40>" not in s.html()
    assert s.text().startswith("T <1:40>: PASS\n  row 0: ")


def test_a_table_without_pandas_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas raises ImportError
    with pytest.raises(PrintgenError, match=r"pip install 'printgen\[table\]'"):
        frame([{"a": 1.0}], "the curves")


def test_targets_selection_and_design_show_short():
    t = shows_short(printgen.targets(REALISTIC, 40), "at 1:40", "border cable axial")
    assert "E*A: 706.9 N" in t  # the 24 mm steel cable's E*A / lambda^3, as the notebook asserts
    shows_short(printgen.select(REALISTIC, 40), "generic-350", "tpu-85a")
    shows_short(printgen.plan(REALISTIC, 40), "Design at 1:40", "top cable")


@pytest.mark.slow
def test_a_make_run_shows_its_verdict_and_curves(made_1_40):
    ctx, out = made_1_40
    v = ctx.records.check.verification
    shows_short(ctx, v.verdict, "levels compared")
    shows_short(v, v.verdict, "mid-height deflection / width")
    rows = ctx.curve_rows()
    with open(out / "curves.csv", newline="", encoding="utf-8") as f:
        written = list(csv.DictReader(f))
    assert len(rows) == len(written)
    for name in written[0]:  # every curves.csv column the table has, the same numbers
        if name in rows[0]:
            assert_close([r[name] for r in rows], [float(w[name]) for w in written], name)
    band = [c for c in rows[0] if "_band_" in c]
    assert len(band) == 2 * 5 and "mid_height_elongation_band_max_pct" in band
    assert list(rows[0])[:3] == [LEVEL_COLUMN, "bottom_cable_elongation_prototype_pct",
                                 "bottom_cable_elongation_model_pct"]
    plain = v.curve_rows()  # the verification alone: no band, its own levels
    assert not [c for c in plain[0] if "_band_" in c]
    assert [r[LEVEL_COLUMN] for r in plain] == list(v.model.deformation.levels)
    pd = pytest.importorskip("pandas")
    table = ctx.curves_table()
    assert isinstance(table, pd.DataFrame) and list(table.columns) == list(rows[0])
    assert table.to_dict("records") == rows


def assert_close(got: list[float], want: list[float], name: str) -> None:
    np.testing.assert_allclose(got, want, rtol=CSV_RTOL, atol=CSV_ATOL, err_msg=name)


@pytest.mark.slow
def test_plot_helpers_return_a_figure_or_draw_on_the_axes(made_1_40):
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure

    ctx, _ = made_1_40
    whole = printgen.plot_curves(ctx)
    assert isinstance(whole, Figure) and len(whole.axes) == 6
    assert whole.axes[0].collections  # the band, shaded
    fig = Figure()
    ax = fig.add_subplot()
    assert printgen.plot_curves(ctx, ax, metric="strain_mid") is fig
    assert ax.get_ylabel() == "mid-height elongation (%)"
    model = ax.lines[1].get_ydata()  # drawn in %, as curves.csv holds it
    assert_close(list(model), [r["mid_height_elongation_model_pct"]
                               for r in ctx.records.check.verification.curve_rows()], "mid")
    net = printgen.plot_net(ctx)
    assert net.axes[0].lines and "mesh 20.6 x 9.4 mm" in net.axes[0].get_title()
    with pytest.raises(InputError, match="metric 'nope'; expected one of deflection"):
        printgen.plot_curves(ctx, metric="nope")
    with pytest.raises(InputError, match="plot_curves takes a Verification"):
        printgen.plot_curves(ctx.design)
    import matplotlib.pyplot as plt

    assert not plt.get_fignums()  # nothing left open in pyplot


@pytest.mark.slow
def test_the_other_results_show_short(tmp_path, made_1_40):
    """search_nets, series, calibrate and panel on tiny inputs (seconds each)."""
    from proto_files import SIMPLE, write_variant

    tiny = write_variant(tmp_path, {("barrier", "width_m"): 2.0, ("barrier", "height_m"): 1.0,
                                    ("net", "mesh_x_m"): 0.25, ("net", "mesh_y_m"): 0.25},
                         base=SIMPLE)
    shows_short(printgen.series(tiny, [1, 100], materials=["petg"], serial=True), "1, 100")
    found = printgen.search_nets(tiny, 40, serial=True,
                                 options=_search_options(objective="stiffness",
                                                         materials=("tpe",)))
    shows_short(found, "1:40 (stiffness")
    for run in printgen.panel(made_1_40[1] / "design.json"):
        shows_short(run, "diagonal", "strain")
    shows_short(printgen.calibrate(_coupons(tmp_path), material="petg-lab",
                                   specimen={"kind": "cable", "width": 0.9e-3,  # m
                                             "thickness": 0.6e-3, "grip_distance": 0.05}),
                "petg-lab", "modulus")


def _search_options(**kw):
    from printgen.run.search import SearchOptions

    return SearchOptions(**kw)


def _coupons(folder):
    """Three exports of a PETG cable, E = 1.30 GPa, 0.9 x 0.6 mm, 50 mm between the grips
    (scripts/test_wheel.sh's)."""
    area, gauge_mm, modulus = 0.9e-3 * 0.6e-3, 50.0, 1.30e9  # m2, mm, Pa
    eps = np.linspace(0.0, 0.02, 200)
    paths = []
    for i, s in enumerate((0.99, 1.0, 1.01)):
        rows = [f"{modulus * s * area * e:.5f},{e * gauge_mm:.6f}" for e in eps]
        paths.append(folder / f"coupon{i}.csv")
        paths[-1].write_text("Load (N),Extension (mm)\n" + "\n".join(rows) + "\n")
    return paths


GUARD_SCRIPT = '''
import math, os
import printgen.executor.start as start
from printgen.executor.local import run_jobs
start.start_method = lambda plat=None: "spawn"  # as on macOS and Windows
print(run_jobs([(math.sqrt, (4.0,), {}), (math.sqrt, (9.0,), {})]))
'''


@pytest.mark.slow
@pytest.mark.parametrize("how", ["unguarded", "serial", "guarded"])
def test_the_main_guard_message_is_true(tmp_path, how):
    """A script without `if __name__ == "__main__":` is refused before its workers start, by a
    message naming the script, the start method and both ways out; each way out works: the
    guard (the spawned workers run the script again, its calls skipped) or PRINTGEN_SERIAL=1
    (no worker at all)."""
    import os
    import subprocess
    import textwrap

    from conftest import ROOT

    from printgen.executor.start import cores

    if cores() < 2:
        pytest.skip("one core: printgen starts no worker")
    body = GUARD_SCRIPT
    if how == "guarded":
        body = 'if __name__ == "__main__":\n' + textwrap.indent(body, "    ")
    script = tmp_path / "my_run.py"
    script.write_text(body)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.pop("PRINTGEN_SERIAL", None)
    if how == "serial":
        env["PRINTGEN_SERIAL"] = "1"
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          env=env, timeout=300)
    if how == "unguarded":
        assert done.returncode == 1 and not done.stdout
        for words in ("my_run.py runs printgen's parallel work", "(spawn: how workers start on "
                      "macOS and Windows)", 'if __name__ == "__main__":',
                      "Python API section of docs/user-guide.md", "PRINTGEN_SERIAL=1"):
            assert words in done.stderr, (words, done.stderr)
    else:
        assert done.returncode == 0 and done.stdout.strip() == "[2.0, 3.0]", done.stderr


def test_calibrate_stays_callable_once_its_package_is_imported():
    """Importing printgen.calibrate's modules (as printgen itself does) makes the package the
    attribute `printgen.calibrate`: it must still be the verb."""
    import printgen
    import printgen.calibrate.reader  # noqa: F401

    with pytest.raises(TypeError, match="material"):
        printgen.calibrate([])  # the verb's own signature: `material` is required
