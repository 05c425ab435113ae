"""What a lab takes to the flume, without a `make` (issue 23): print time, filament and mass
from a toolpath against hand arithmetic; the printed model's lengths in mm; the measurement
sheet's raw mm readings read back as the normalised quantities; reproducible SVG figures."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import reference_design_1_40

from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_printer
from printgen.parts.gcode.estimate import duration, print_estimate
from printgen.parts.gcode.toolpath import BORDER, TRAVEL, Toolpath
from printgen.scene.readings import RAW_COLUMNS, FlumeUnits, design_units
from printgen.verification.measured import MeasurementError, read_measured

EXACT = 1e-12  # sums of a few floats
READ_TOL = 1e-9  # numbers written with 10 significant digits and read back


def line_toolpath(length_mm: float, speed: float, travel_mm: float) -> Toolpath:
    """A travel of `travel_mm` then one 0.4 x 0.2 mm bead of `length_mm` at `speed`."""
    xyz = np.array([[0.0, 0.0, 0.2], [travel_mm, 0.0, 0.2], [travel_mm + length_mm, 0.0, 0.2]])
    return Toolpath(xyz, np.array([0.0, 0.0, 0.4]), np.array([0.0, 0.0, 0.2]),
                    np.array([100.0, 100.0, speed]), np.array([0.0, 0.0, 1.0]),
                    np.zeros(3, dtype=int), np.array([TRAVEL, TRAVEL, BORDER]), np.array([0.2]))


def test_print_estimate_is_the_hand_arithmetic():
    printer, mat = load_printer("prusa-mk4"), load_material("petg")
    tp = line_toolpath(50.0, 25.0, 1.0)  # travel under 2 mm: not retracted
    est = print_estimate(tp, printer, mat)
    assert est.seconds == pytest.approx(1.0 / 100.0 + 50.0 / 25.0, rel=EXACT)
    volume = 0.4 * 0.2 * 50.0
    assert est.volume_mm3 == pytest.approx(volume, rel=EXACT)
    assert est.filament_mm == pytest.approx(
        volume / (math.pi * printer.filament_diameter_mm**2 / 4), rel=EXACT)
    assert est.mass_g == pytest.approx(volume * 1e-3 * 1.27, rel=EXACT)  # PETG 1.27 g/cm^3
    long = print_estimate(line_toolpath(50.0, 25.0, 10.0), printer, mat)  # retracted travel
    p = mat.print
    assert long.seconds == pytest.approx(10.0 / 100.0 + 2.0 + 2 * p.retract_length_mm
                                         / p.retract_speed_mm_per_s, rel=EXACT)
    assert duration(3723.4) == "1h 02m 03s" and duration(65) == "1m 05s"
    assert "; filament used [g] = " in "\n".join(est.header_lines())


def test_model_lengths_are_the_design_in_mm():
    d = reference_design_1_40()
    u = design_units(d)
    # the solver net spans a whole number of meshes: within one mesh of the printed size
    assert abs(u.width_mm - d.net.width_mm) < d.net.mesh_x_mm
    assert abs(u.height_mm - d.net.height_mm) < d.net.mesh_y_mm
    # each wire runs along its row, about the net's width (a row zig-zags a little)
    for row, length in u.row_mm.items():
        assert d.net.width_mm * 0.9 < length < d.net.width_mm * 1.5, row


UNITS = FlumeUnits(330.0, 100.0, {"bottom": 330.0, "top": 331.0, "mid": 335.0})


def test_raw_mm_readings_and_water_depth_read_as_normalised(tmp_path):
    p = tmp_path / "sheet.csv"
    p.write_text("# a sheet\nwater_depth_mm,mid_sensor_mm,deflection_mm,top_lowering_mm,"
                 "expected_mid_sensor_nominal_mm,bottom_sensor_mm\n"
                 "50,3.35,10,,1.0,\n100,33.5,33,5,2.0,\n")
    m = read_measured(p, UNITS)
    np.testing.assert_allclose(m.levels, [0.5, 1.0], rtol=READ_TOL)
    np.testing.assert_allclose(m.values["strain_mid"], [0.01, 0.1], rtol=READ_TOL)
    np.testing.assert_allclose(m.values["deflection"], [10 / 330, 0.1], rtol=READ_TOL)
    assert np.isnan(m.values["lowering"][0]) and m.values["lowering"][1] == pytest.approx(0.05)
    assert "strain_bottom" not in m.values  # the empty column of the sheet is left out
    assert m.columns["strain_mid"] == "mid_sensor_mm"


BAD = {
    "depth disagrees": ("h_over_hb,water_depth_mm,mid_sensor_mm\n0.5,70,1\n", "water_depth_mm"),
    "same quantity twice": ("h_over_hb,deflection_mm,deflection_over_width\n0.5,3,0.01\n",
                            "same quantity"),
    "mm beyond a metre": ("h_over_hb,deflection_mm\n0.5,3000\n", "deflection_mm"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_raw_sheets_are_refused_naming_the_column(tmp_path, case):
    text, named = BAD[case]
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(MeasurementError, match=named):
        read_measured(p, UNITS)


def test_raw_columns_need_the_model_lengths(tmp_path):
    p = tmp_path / "raw.csv"
    p.write_text("h_over_hb,mid_sensor_mm\n0.5,1\n")
    with pytest.raises(MeasurementError, match="mid_sensor_mm"):
        read_measured(p)  # without the design there is no length to divide by
    assert set(RAW_COLUMNS) >= {"mid_sensor_mm", "deflection_mm", "top_lowering_mm"}


def test_figures_give_the_same_png_and_svg_twice():
    from printgen.report.plots import _png, _pyplot

    def draw():
        fig, ax = _pyplot().subplots()
        ax.plot([0, 1], [0, 2])
        ax.set_xlabel("relative loading h / h_B (-)")
        return _png(fig)

    a, b = draw(), draw()
    assert bytes(a) == bytes(b) and a.svg == b.svg and a.svg.startswith(b"<?xml")
    assert a.labels == [("", ["relative loading h / h_B (-)", ""])]


def test_summary_of_a_verify_record_without_selection(monkeypatch):
    """`verify` has the design but no selection: the box names the parts without an error."""
    from types import SimpleNamespace

    from printgen.report import summary
    from printgen.report.records import CheckRecords, RunRecords
    from printgen.report.summary import summarize, summary_html

    verdicts = [SimpleNamespace(metric="deflection", text="model stiffer by 20%", levels=3),
                SimpleNamespace(metric="strain_bottom", levels=0,
                                text="no deformation to compare")]
    monkeypatch.setattr(summary, "band_verdicts", lambda values, band: verdicts)
    d = reference_design_1_40()
    v = SimpleNamespace(ok=False, verdict="FAIL", runnable=True, flow=None, sensors=None,
                        headline="model too stiff", mismatches=[],
                        prototype=SimpleNamespace(deformation=SimpleNamespace(values={})))
    run = RunRecords("t", d, steps={"verification": CheckRecords(v, None, 40.0, nested=False)})
    summary = summarize(run, "fitted: stiffness 0.8 x")
    s = summary.to_record()
    assert s["verdict"] == "FAIL" and s["next"] == "fitted: stiffness 0.8 x"
    assert list(s["band"]) == ["deflection"]  # a quantity nothing deforms is not listed
    assert [p["stiffness_error"] for p in s["parts"]] == [None, None]
    box = summary_html(summary)
    assert 'id="summary"' in box and "model stiffer by 20%" in box and "TPE" in box


@pytest.mark.slow
def test_sensor_and_anchor_layout_is_the_scene_in_mm():
    """The layout drawing's positions: the pins on the net's corners, each wire anchored at the
    left end of its row with its potentiometer SENSOR_EXIT x width beyond the right edge in line
    with the row, the row lengths those the readings divide by; its CSV holds the record."""
    import csv
    import io

    from printgen.report.flume_drawing import layout_csv, layout_figure, layout_rows
    from printgen.report.plots import _png, axis_labels
    from printgen.scene import build_scene
    from printgen.scene.flume import flume_layout
    from printgen.scene.readings import flume_units
    from printgen.scene.scenes import SENSOR_EXIT

    s = build_scene(reference_design_1_40())
    lay = flume_layout(s)
    w, h = lay.width_mm, lay.height_mm
    assert w == pytest.approx(s.width * 1e3, rel=EXACT) and h == pytest.approx(s.height * 1e3,
                                                                              rel=EXACT)
    assert sorted(map(tuple, lay.pins_mm.round(9))) == [(0, 0), (0, h), (w, 0), (w, h)]
    assert set(lay.held_mm) == {"left", "right"}  # walls: the side sheets hold the sides
    units = flume_units(s)
    for sensor in lay.sensors:
        z = sensor.anchor_mm[1]
        assert sensor.anchor_mm[0] == pytest.approx(0.0, abs=EXACT)
        assert sensor.potentiometer_mm == pytest.approx((w * (1 + SENSOR_EXIT), z), rel=EXACT)
        assert sensor.along_row_mm == pytest.approx(units.row_mm[sensor.row], rel=EXACT)
        assert np.allclose(sensor.route_mm[:, 1], z)  # the row is level at rest
    rec = lay.to_record()
    rows = list(csv.DictReader(io.StringIO(layout_csv(rec))))
    wires = {r["item"]: r for r in rows if r["item"].endswith(" wire")}
    for sensor in rec["sensors"]:
        r = wires[f"{sensor['row']} wire"]
        assert [float(r[k]) for k in ("x_mm", "z_mm", "x_to_mm", "z_to_mm")] == pytest.approx(
            [*sensor["anchor_mm"], *sensor["potentiometer_mm"]], rel=READ_TOL)
    assert len(layout_rows(rec)) == 4 + 2 + 2 * 3  # pins, held edges, wire ends
    fig = layout_figure(rec, lay.strands_mm)
    labels = axis_labels(fig)
    _png(fig)
    assert all(name.endswith("(mm)") for _, names in labels for name in names)


def test_the_sheets_note_is_one_cell_to_a_csv_reader(made_1_40):
    """A reader without comment handling (pandas.read_csv's default) sees the note as one
    cell, not a row of sentence fragments that shifts the header."""
    import csv

    _, out = made_1_40
    with open(out / "measurement-sheet.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert len(rows[0]) == 1 and rows[1][0] == "h_over_hb"
