"""Synthetic exports from known laws, in every CSV variant, are recovered to 0.5 %.

Each law gives stress (or panel force per width) against specimen strain; the files carry
crosshead displacement (optionally with machine deflection added) or extensometer strain,
small seeded noise and a post-failure drop that the fit must ignore.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from numpy.testing import assert_allclose
from test_calibrate_files import VARIANTS, write_export

from printgen.calibrate.aggregate import summarise
from printgen.calibrate.compliance import from_curve, from_stiffness
from printgen.calibrate.fit import ISO_WINDOW, zero_at_preload
from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.sample import PRELOAD_STEPS, FitOptions
from printgen.errors import CalibrationError

RECOVERY_RTOL = 0.005  # the requirement: known laws recovered to 0.5 %
NOISE = 2e-4  # force noise, fraction of the peak force (seeded), so fits are not exact
# Exact-slope checks: numbers written with 10 digits and the linear interpolation of the
# preload crossing (O(b h^2)) leave far less than this.
EXACT_SLOPE_RTOL = 1e-5
UNCORRECTED_MIN_ERROR = 0.02  # a skipped correction must visibly bias the modulus (> 2 %)

E = 2.0e9  # Pa, a printed PETG-like cable
WIDTH, THICK, GRIP = 2.0e-3, 1.0e-3, 50.0e-3  # m
AREA = WIDTH * THICK
N_POINTS = 1500
STRAIN_MAX = 0.03


def _noisy(force: np.ndarray, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return force + NOISE * force.max() * rng.standard_normal(force.size)


def _with_failure(strain: np.ndarray, force: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Append a post-failure drop (strain keeps rising, force falls) the fit must ignore."""
    tail = np.linspace(0, 1, 40)[1:]
    s = np.concatenate([strain, strain[-1] + 0.002 * tail])
    f = np.concatenate([force, force[-1] * (1 - 0.9 * tail)])
    return s, f


def _write(tmp_path, name, strain, stress, variant, *, machine=None, extensometer=False, seed=0):
    strain, force = _with_failure(strain, _noisy(stress * AREA, seed))
    disp = strain * GRIP + (machine(force) if machine else 0.0)
    ch = {"time": np.arange(force.size) * 0.1, "force": force, "displacement": disp}
    if extensometer:
        ch["strain"] = strain
    return write_export(tmp_path / name, ch, variant)


def _cal(paths, **kw):
    spec = {"width": WIDTH, "thickness": THICK, "grip_distance": GRIP}
    return calibrate(paths, material="synthetic", specimen=spec, **kw)


@pytest.mark.slow
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_linear_law_every_variant(tmp_path, variant):
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    p = _write(tmp_path, "lin", eps, E * eps, variant, seed=1)
    cal = _cal([p])
    assert_allclose(cal.modulus.mean, E, rtol=RECOVERY_RTOL)
    assert_allclose(cal.strength.mean, E * STRAIN_MAX, rtol=RECOVERY_RTOL)
    secant = cal.samples[0].secants[0.01]
    assert_allclose(secant, E, rtol=RECOVERY_RTOL)


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_bilinear_law_every_variant(tmp_path, variant):
    e1, e2, knee = E, 0.25 * E, 0.01
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    sigma = e1 * eps + (e2 - e1) * np.maximum(eps - knee, 0)
    cal = _cal([_write(tmp_path, "bil", eps, sigma, variant, extensometer=True, seed=2)])
    b = cal.samples[0].bilinear
    assert cal.samples[0].strain_source.startswith("extensometer")
    assert_allclose([b.slope1, b.slope2, b.knee], [e1, e2, knee], rtol=RECOVERY_RTOL)
    assert_allclose(cal.modulus.mean, e1, rtol=RECOVERY_RTOL)


@pytest.mark.slow
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_toe_region_zeroed_at_preload(tmp_path, variant):
    """Slack toe: quadratic up to 2 e_t, then E (e - e_t); zeroing at a preload past the toe
    puts the ISO window on the linear part."""
    e_t = 0.002
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    sigma = np.where(eps < 2 * e_t, E * eps**2 / (4 * e_t), E * (eps - e_t))
    p = _write(tmp_path, "toe", eps, sigma, variant, seed=3)
    preload = E * 0.003 * AREA  # N, at strain 0.5 %: past the toe
    cal = _cal([p], options=FitOptions(preload=preload))
    assert_allclose(cal.modulus.mean, E, rtol=RECOVERY_RTOL)
    no_preload = _cal([p]).modulus.mean
    assert abs(no_preload / E - 1) > UNCORRECTED_MIN_ERROR  # the toe biases an unzeroed fit


@pytest.mark.slow
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_constant_machine_stiffness_corrected(tmp_path, variant):
    k = 2000e3  # N/m (2000 N/mm); the specimen's own E A / L is 80 N/mm
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    p = _write(tmp_path, "mc", eps, E * eps, variant, machine=lambda f: f / k, seed=4)
    cal = _cal([p], options=FitOptions(compliance=from_stiffness(k / 1e3)))
    assert_allclose(cal.modulus.mean, E, rtol=RECOVERY_RTOL)
    assert "constant stiffness 2000 N/mm" in cal.samples[0].strain_source
    assert _cal([p]).modulus.mean < E * (1 - UNCORRECTED_MIN_ERROR)


@pytest.mark.slow
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_measured_compliance_curve_subtracted_point_by_point(tmp_path, variant):
    """Nonlinear system compliance (seating then stiffening), measured on a rigid bar."""
    def system(f):
        return f / 1500e3 + 2e-6 * (1 - np.exp(-f / 5.0))  # m: linear + seating term

    bar_force = np.linspace(0, 80.0, 400)
    curve = write_export(tmp_path / "rigid_bar", {"force": bar_force,
                                                 "displacement": system(bar_force)}, variant)
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    p = _write(tmp_path, "cc", eps, E * eps, variant, machine=system, seed=5)
    cal = _cal([p], options=FitOptions(compliance=from_curve(curve)))
    assert_allclose(cal.modulus.mean, E, rtol=RECOVERY_RTOL)
    assert _cal([p]).modulus.mean < E * (1 - UNCORRECTED_MIN_ERROR)


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_tpe_panel_law_recovered(tmp_path, variant):
    """Net panel softening from 30 to 6 kN/m/m at 40 % strain (Lambert et al. 2023):
    kappa = (F / w) / dl, on a 43 mm long, 23 mm wide panel."""
    k1, k2, knee, length, width = 30e3, 6e3, 0.40, 43e-3, 23e-3
    eps = np.linspace(0, 0.8, N_POINTS)
    fw = k1 * length * eps + (k2 - k1) * length * np.maximum(eps - knee, 0)
    strain, force = _with_failure(eps, _noisy(fw * width, 6))
    p = write_export(tmp_path / "panel", {"force": force, "displacement": strain * length},
                     variant)
    cal = calibrate([p], material="tpe-lab", options=FitOptions(window=(0.02, 0.2)),
                    specimen={"kind": "panel", "width": width, "gauge_length": length})
    law = cal.panel
    assert_allclose([law.kappa1.mean, law.kappa2.mean, law.knee.mean], [k1, k2, knee],
                    rtol=RECOVERY_RTOL)
    assert_allclose(cal.samples[0].kappa, k1, rtol=RECOVERY_RTOL)


@pytest.mark.slow
def test_stats_over_samples_and_outlier_flag(tmp_path):
    """Five specimens: mean and sample SD of the fitted moduli; a sixth, 30 % stiffer, flagged."""
    moduli = E * np.array([0.97, 1.0, 1.02, 0.99, 1.01, 1.3])
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    paths = [_write(tmp_path, f"s{i}", eps, m * eps, "comma", seed=10 + i)
             for i, m in enumerate(moduli)]
    cal = _cal(paths)
    assert cal.modulus.n == 6
    assert_allclose(cal.modulus.mean, moduli.mean(), rtol=RECOVERY_RTOL)
    assert_allclose(cal.modulus.sd, np.std(moduli, ddof=1), rtol=RECOVERY_RTOL * 10)
    assert cal.modulus.outliers == (5,)
    # The outlier warning in the table's unit (GPa), not Pa.
    assert any(re.search(r"s5\.csv = 2\.6\d* GPa is an outlier .*median 2\.0\d* GPa", w)
               for w in cal.warnings), cal.warnings
    assert not any("n = " in w for w in cal.warnings)
    # n = 3 with the 30 % stiffer one among them: spread only, said once, nothing flagged.
    few = _cal([*paths[:2], paths[5]])
    assert few.modulus.outliers == ()
    assert [w for w in few.warnings if "n = 3" in w or "outlier" in w or "at least" in w] == [
        ("n = 3: spread only (mean ± SD, no outlier flags); ISO 527-1 asks for at least 5 "
        "specimens, and outliers are flagged from n = 5")]


def test_summarise_basic():
    s = summarise([1.0, 2.0, 3.0, 4.0, 5.0])
    assert (s.mean, s.n, s.outliers, s.warnings) == (3.0, 5, (), ())
    assert_allclose(s.sd, np.sqrt(2.5), rtol=1e-12)  # exact sample SD; only round-off
    # Round-off scatter is not an outlier, however small the MAD.
    assert summarise([0.4, 0.4 + 1e-12, 0.4 - 1e-12, 0.4 + 2e-12, 0.4001]).outliers == ()
    assert summarise([1.0, 1.01, 0.99, 1.0, 1.5]).outliers == (4,)


def test_window_beyond_the_curve_and_missing_grip_fail_clearly(tmp_path):
    eps = np.linspace(0, 0.002, 300)
    p = _write(tmp_path, "short", eps, E * eps, "comma")
    with pytest.raises(CalibrationError, match=r"only \d+ points in the strain window 0.3-0.5 %"):
        _cal([p], options=FitOptions(window=(0.003, 0.005)))
    with pytest.raises(CalibrationError, match="needs the grip distance"):
        calibrate([p], material="x", specimen={"width": WIDTH, "thickness": THICK})


def test_preload_not_reached_and_unknown_roles_fail_clearly(tmp_path):
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    p = _write(tmp_path, "lin", eps, E * eps, "comma")
    with pytest.raises(CalibrationError, match=r"lin\.csv: preload 1e\+06 N never reached"):
        _cal([p], options=FitOptions(preload=1e6))
    with pytest.raises(CalibrationError, match="unknown column role 'torque'"):
        _cal([p], units={"torque": "Nm"})


def test_zero_conventions_at_the_preload():
    """'first': zero at the first sample at or above the preload; 'interpolate': between the
    two samples around it, so the curve starts exactly at the preload."""
    x = np.arange(10) * 1e-3
    y = 10.0 * x  # force, N
    xf, yf, x0f = zero_at_preload(x, y, 0.0255, mode="first")
    assert (x0f, yf[0], xf[0]) == (x[3], y[3], 0.0)
    xi, yi, x0i = zero_at_preload(x, y, 0.0255, mode="interpolate")
    assert_allclose([x0i, yi[0]], [0.00255, 0.0255], rtol=1e-12)  # exact on a straight line
    assert_allclose(xi[1:], x[3:] - 0.00255, rtol=1e-12)
    with pytest.raises(CalibrationError, match="zero convention 'last'"):
        zero_at_preload(x, y, 0.0255, mode="last")


@pytest.mark.parametrize("zero", ["interpolate", "first"])
def test_preload_zero_and_its_sensitivity_against_the_exact_slope(tmp_path, zero):
    """Softening law sigma = a e + b e^2 sampled every h of strain (extensometer). Zeroed at
    strain e0, the least-squares slope over the equally spaced window points u (from u_lo to
    u_hi) is exactly a + 2 b e0 + b (u_lo + u_hi): the modulus, and its change with the
    preload, follow from where each convention puts e0."""
    a, b, h = E, -20 * E, 0.7e-4  # b: 20 % softer at 1 % strain; h off the window's grid
    eps = np.arange(0, STRAIN_MAX, h)
    sigma = a * eps + b * eps**2
    p = write_export(tmp_path / "quad", {"force": sigma * AREA, "strain": eps}, "comma")
    preload = (a * 0.002 + b * 0.002**2) * AREA  # N, reached at 0.2 % strain

    def exact(load: float) -> float:
        root = (-a + np.sqrt(a * a + 4 * b * load / AREA)) / (2 * b)  # strain at the preload
        e0 = eps[np.searchsorted(eps, root - 1e-15)] if zero == "first" else root
        u = eps - e0
        u = u[(u >= ISO_WINDOW[0]) & (u <= ISO_WINDOW[1])]
        return a + 2 * b * e0 + b * (u.min() + u.max())

    cal = _cal([p], options=FitOptions(preload=preload, zero=zero))
    s = cal.samples[0]
    assert_allclose(s.modulus, exact(preload), rtol=EXACT_SLOPE_RTOL)
    assert_allclose(s.preload_moduli, [exact(f * preload) for f in PRELOAD_STEPS],
                    rtol=EXACT_SLOPE_RTOL)
    assert_allclose(cal.preload_change, [exact(f * preload) / exact(preload) - 1
                                         for f in PRELOAD_STEPS], atol=EXACT_SLOPE_RTOL)
