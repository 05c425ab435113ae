"""Write or update a material profile's `[measured]` tables from a calibration.

The profile goes to `<dir>/materials/<name>.toml` (dir: --out, else the first PRINTGEN_PROFILES
entry). A new profile `inherits` a bundled one so datasheet and print settings carry over; an
existing one keeps everything but the tables this calibration measured. Before the file is
replaced atomically, the staged profile is loaded with `load_material` to prove it reads back.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import os
import tempfile
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import tomli_w

from printgen import outputs
from printgen.calibrate.pipeline import Calibration
from printgen.calibrate.waved import WaveCalibration, measured_wave_tables
from printgen.errors import CalibrationError, PrintgenError
from printgen.inputs.materials import Material, load_material
from printgen.inputs.profiles import profile_name

SOURCE = "printgen calibrate: tensile tests"
SIG = 6  # significant digits written for measured values
# A printed coupon's modulus and strength lie within this factor of its filament's datasheet
# (voids, bead bonds and orientation lower them a few times at most); beyond it, a unit is
# wrong (kN read as N is a factor 1000) or the profile inherits the wrong material.
DATASHEET_SPREAD = 10.0


def output_dir(out: str | Path | None) -> Path:
    """--out, else the first PRINTGEN_PROFILES directory."""
    if out is not None:
        return Path(out)
    env = [p for p in os.environ.get("PRINTGEN_PROFILES", "").split(os.pathsep) if p]
    if not env:
        raise CalibrationError("nowhere to write the profile: give --out DIR or set "
                               "PRINTGEN_PROFILES (it is written as DIR/materials/NAME.toml)")
    return Path(env[0])


def measured_tables(cal: Calibration | WaveCalibration, *, date: str | None = None
                    ) -> dict[str, dict[str, Any]]:
    """The `[measured.*]` tables (file units) this calibration gives."""
    day = date or dt.date.today().isoformat()
    files = {"source": f"{SOURCE} ({len(cal.files)} files)", "date": day,
             "files": [Path(f).as_posix() for f in cal.files]}
    if isinstance(cal, WaveCalibration):
        return measured_wave_tables(cal, files | {"conditions": cal.conditions})
    prov = files | {"conditions": _conditions(cal)}
    out: dict[str, dict[str, Any]] = {}
    if cal.kind != "panel" and cal.modulus is not None:
        out["tensile_modulus"] = _value(cal.modulus, "gpa", 1e9) | prov | _fit_info(cal)
    if cal.kind == "panel" and cal.panel is not None:
        p = cal.panel
        law = {"knee_strain_percent": [_r(p.knee.mean * 100)],
               "kappa_kn_per_m_per_m": [_r(p.kappa1.mean / 1e3), _r(p.kappa2.mean / 1e3)],
               "panel_length_mm": _r(p.panel_length * 1e3), "n_samples": p.kappa1.n}
        if p.panel_width is not None:
            law["panel_width_mm"] = _r(p.panel_width * 1e3)
        out["panel_law"] = law | prov | _fit_info(cal)
    if cal.kind != "panel" and cal.strength is not None:
        out["failure_stress"] = _value(cal.strength, "mpa", 1e6) | prov
    if not out:
        raise CalibrationError("nothing measured to write (no modulus, strength or panel law)")
    return out


def write_profile(cal: Calibration | WaveCalibration, *, name: str, out: str | Path | None = None,
                  inherits: str | None = None, date: str | None = None) -> tuple[Path, Material]:
    """Write (or update) `<dir>/materials/<name>.toml`; return its path and the loaded material."""
    name = profile_name(name, "--material")
    date = tested_on(date)
    if inherits is not None:
        inherits = profile_name(inherits, "--inherits")
    if cal.groups:
        raise CalibrationError(
            "the files mix specimen orientations ("
            + ", ".join(f"{g.label}: {len(g.files)} files" for g in cal.groups)
            + "); a profile holds one: calibrate and save one orientation at a time (name only "
            "its files, e.g. xy-*)")
    root = output_dir(out)
    if (root / "materials").is_symlink():  # the profile would land wherever the link points
        raise CalibrationError(f"{root / 'materials'} is a symbolic link (to "
                               f"{os.readlink(root / 'materials')}); printgen writes profiles "
                               "only into a real materials folder: give --out the folder the "
                               "link points to, or remove the link")
    path = root / "materials" / f"{name.lower()}.toml"
    data = _existing(path)
    if inherits is not None:
        if inherits.lower() == name.lower():
            raise CalibrationError(f"profile {name!r} cannot inherit itself; name the calibrated "
                                   f"profile differently (e.g. {name}-lab --inherits {inherits})")
        data["inherits"] = inherits
    elif not data:
        raise CalibrationError(f"{path} does not exist yet: give --inherits <bundled material> "
                               "so its datasheet and print settings carry over")
    if "name" not in data:
        data["name"] = name
        data["description"] = (f"{name}: calibrated with printgen calibrate from "
                               f"{len(cal.files)} tensile tests"
                               + (f", inheriting {inherits}" if inherits else ""))
    data.setdefault("measured", {}).update(measured_tables(cal, date=date))
    text, mat = validated_text(data, name=name, root=root, shown=path)
    check_against_datasheet(mat, path)
    mode = _mode(path)
    outputs.write_text(path, text)
    os.chmod(path, mode)
    return path, mat


def tested_on(date: str | None) -> str | None:
    """`date` as an ISO day (YYYY-MM-DD), checked: a real calendar day, not after tomorrow
    (a test not yet run; tomorrow allows for time zones); CalibrationError otherwise."""
    if date is None:
        return None
    try:
        day = dt.date.fromisoformat(date.strip())
    except ValueError:
        raise CalibrationError(f"--date {date!r} is not a calendar day in ISO format "
                               "(YYYY-MM-DD: year, month, day)") from None
    latest = dt.date.today() + dt.timedelta(days=1)
    if day > latest:
        raise CalibrationError(f"--date {day.isoformat()} is after {latest.isoformat()}: give the "
                               "day the coupons were tested")
    return day.isoformat()


def check_against_datasheet(mat: Material, shown: Path) -> None:
    """CalibrationError when a measured modulus or strength is more than DATASHEET_SPREAD
    times off the datasheet value the profile inherits: printing lowers a filament's values
    by voids and bead bonds, never by orders of magnitude, so such a value comes from a wrong
    unit (a force in kN read as N gives 1/1000) or the wrong parent material."""
    for what, got, sheet, unit in (
            ("modulus", mat.measured_modulus, mat.datasheet_modulus, 1e9),
            ("failure stress", mat.measured_failure_stress, mat.datasheet_failure_stress, 1e6)):
        if got is None or sheet <= 0:
            continue
        ratio = got.value / sheet
        if 1 / DATASHEET_SPREAD <= ratio <= DATASHEET_SPREAD:
            continue
        u = "GPa" if unit == 1e9 else "MPa"
        raise CalibrationError(
            f"{shown}: measured {what} {got.value / unit:.4g} {u} is {ratio:.3g} x the datasheet's "
            f"{sheet / unit:.4g} {u} ({mat.datasheet_source}); a printed part lies within "
            f"{DATASHEET_SPREAD:g} x of its filament's datasheet. Nothing written: check the "
            "force unit (--unit force=kN when the file's newtons are kilonewtons, or the "
            "reverse), the section, or --inherits the material the coupons were printed from")


def validated_text(data: dict[str, Any], *, name: str, root: Path | None = None,
                   shown: Path | None = None) -> tuple[str, Material]:
    """The TOML text of material profile `data` called `name`, and the material it loads as:
    staged as materials/<name>.toml and read back with `load_material` (`root`'s profiles,
    then the usual ones, found for its `inherits`); CalibrationError naming `shown` when it
    would not load."""
    text = tomli_w.dumps(data)
    with tempfile.TemporaryDirectory() as tmp:
        staged = Path(tmp) / "materials" / f"{name.lower()}.toml"
        staged.parent.mkdir(parents=True)
        staged.write_text(text, encoding="utf-8")
        with _profiles_first(Path(tmp), *([root] if root is not None else [])):
            try:
                mat = load_material(name)
            except PrintgenError as exc:
                raise CalibrationError(f"calibrated profile {shown or staged.name} would not "
                                       f"load: {exc}") from exc
    return text, mat


def _mode(path: Path) -> int:
    """The mode a plain `open(path, "w")` leaves: an existing file's own, else 0666 less the
    umask (the temp file `outputs.write_text` renames into place is 0600)."""
    if path.is_file():
        return path.stat().st_mode & 0o7777
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def value_sources(cal: Calibration | WaveCalibration, path: Path, mat: Material) -> dict[str, Any]:
    """The written profile's modulus and failure stress, each with its own source: this
    calibration, an earlier one kept in the same file, inherited from a parent profile, or a
    datasheet. A value this calibration did not measure is never called measured here."""
    own = tomllib.loads(path.read_text(encoding="utf-8"))
    wrote = set(measured_tables(cal))
    e, _ = mat.modulus()
    stress, _ = mat.failure_stress()
    return {"modulus_gpa": e / 1e9,
            "modulus_source": _source("tensile_modulus", mat.measured_modulus, wrote, own, cal),
            "failure_stress_mpa": stress / 1e6,
            "failure_stress_source": _source("failure_stress", mat.measured_failure_stress,
                                             wrote, own, cal)}


def _source(key: str, measured: Any, wrote: set[str], own: dict[str, Any],
            cal: Calibration | WaveCalibration) -> str:
    parent = own.get("inherits")
    if key in wrote:
        return f"measured: this calibration ({len(cal.files)} files)"
    why = " (--strength-only)" if key == "tensile_modulus" and cal.strength_samples else ""
    if measured is not None:
        when = f", {measured.date}" if measured.date else ""
        where = ("earlier in this profile" if key in own.get("measured", {})
                 else f"inherited from {parent}")
        return f"{where}: {measured.source}{when}; not measured by this calibration{why}"
    sheet = "this profile's datasheet" if "datasheet" in own else f"datasheet of {parent}"
    return f"{sheet}; not measured by this calibration{why}"


def _existing(path: Path) -> dict[str, Any]:
    if not path.is_file():
        return {}
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise CalibrationError(f"{path}: existing profile is not valid TOML ({exc}); fix or "
                               "remove it") from exc


@contextlib.contextmanager
def _profiles_first(*dirs: Path) -> Iterator[None]:
    """Put `dirs` ahead of PRINTGEN_PROFILES while the staged profile is loaded."""
    old = os.environ.get("PRINTGEN_PROFILES")
    os.environ["PRINTGEN_PROFILES"] = os.pathsep.join([*map(str, dirs), *([old] if old else [])])
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("PRINTGEN_PROFILES", None)
        else:
            os.environ["PRINTGEN_PROFILES"] = old


def _value(s, unit: str, factor: float) -> dict[str, Any]:
    d: dict[str, Any] = {f"value_{unit}": _r(s.mean / factor), "n_samples": s.n}
    if s.sd is not None and s.sd > 0:
        d[f"sd_{unit}"] = _r(s.sd / factor)
    return d


def _fit_info(cal: Calibration) -> dict[str, Any]:
    o = cal.options
    if o.window is not None:
        window = [_r(o.window[0] * 100), _r(o.window[1] * 100)]
    else:
        window = [_r(min(s.linear.lo for s in cal.samples) * 100),
                  _r(max(s.linear.hi for s in cal.samples) * 100)]
    corr = o.compliance.describe() if o.compliance is not None else "none"
    return {"fit_window_percent": window, "correction": corr}


def _conditions(cal: Calibration) -> str:
    o = cal.options
    parts = [cal.conditions] if cal.conditions else []
    parts.append(f"{cal.kind} specimens")
    if cal.samples:
        parts.append("strain from " + "; ".join(cal.strain_sources))
        parts.append("loading branch up to the peak")
        parts.append(f"zeroed at preload {o.preload:g} N" if o.preload is not None
                     else "zeroed at the first point")
        parts.append(f"linear regression over strain {o.window[0] * 100:g}-{o.window[1] * 100:g} %"
                     if o.window is not None else
                     f"automatic steepest window ({o.auto_span:.0%} of the rise to the peak)")
    else:
        parts.append("force only: strength = peak force / nominal cross-section")
    return "; ".join(parts)


def _r(v: float) -> float:
    return float(f"{v:.{SIG}g}")
