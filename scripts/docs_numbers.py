"""The worked numbers of the tutorial (docs/tutorial.md), the physics page (its 1:40 example)
and the README, written from a run of the bundled 1:40 example so that no number there is
typed by hand. Each number sits between markers, `<!--n:KEY-->value<!--/n-->` (invisible in
the rendered page), and KEY is one of NUMBERS, read from the run's report.json.

    python scripts/docs_numbers.py           # a fresh `make` of the example, then rewrite the pages
    python scripts/docs_numbers.py OUT       # the same from OUT, a folder that `printgen make
                                             # examples/realistic_barrier.toml --scale 40` wrote
    python scripts/docs_numbers.py --check OUT   # exit 1 naming each number that differs

tests/test_docs.py checks the pages against the session's own run of the example.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
PAGES = (ROOT / "docs" / "tutorial.md", ROOT / "docs" / "physics.md", ROOT / "README.md")
EXAMPLE = ROOT / "examples" / "realistic_barrier.toml"
SCALE = 40
MARK = re.compile(r"<!--n:([a-z_]+)-->(.*?)<!--/n-->", re.DOTALL)
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")


def _part(r: dict[str, Any], which: str) -> dict[str, Any]:
    """The summary's row of the net or of the border cables."""
    return next(p for p in r["summary"]["parts"] if p["part"].startswith(which))


def _net(r: dict[str, Any], passes: int) -> dict[str, Any]:
    """The selection's first TPE net of one bead across in `passes` passes."""
    return next(c for c in r["selection"]["net"]["ranked"] if c["material"] == "tpe"
                and c["section"]["beads_across"] == 1 and c["section"]["passes"] == passes)


def _both(rec: dict[str, Any]) -> str:
    """'+80 % across, -18 % up': a net's stiffness error in both barrier directions."""
    return (f"{100 * rec['stiffness_error_across']:+.0f} % across, "
            f"{100 * rec['stiffness_error_up']:+.0f} % up")


def _at_1(r: dict[str, Any], quantity: str, which: str) -> float:
    """The compared quantity at h / h_B = 1 (the model's nominal or the prototype's)."""
    return r["verification"]["bands"]["at"]["1"][quantity][which]


def _steel(r: dict[str, Any], variant: str) -> float:
    """The counter-example's deflection / width of the simple barrier at 1:lambda."""
    found = r["verification"]["counterexample"]["deflection"]
    return next(v for k, v in found.items() if k.endswith(variant))


def _duration(seconds: float) -> str:
    from printgen.parts.gcode.estimate import duration

    return duration(seconds)


def _one_line(text: str) -> str:
    return "; ".join(line.strip() for line in text.splitlines() if line.strip())


def _target(r: dict[str, Any], key: str, digits: int) -> str:
    t = r["targets"]["targets"][key]
    return f"{t['model']:.{digits}f} {t['unit']}"


# KEY -> its text from report.json, formatted as the CLI and the report print it.
NUMBERS: dict[str, Callable[[dict[str, Any]], str]] = {
    "cable_ea_target": lambda r: _target(r, "cable_ea", 1),
    "membrane_target": lambda r: _target(r, "membrane_0", 1),
    "froude": lambda r: f"{r['targets']['flow']['froude']:.2f}",
    "discharge": lambda r: f"{1000 * r['targets']['flow']['discharge']:.2f} L/s",
    "cable": lambda r: f"{_part(r, 'border')['material']} {_part(r, 'border')['section']}",
    "cable_error": lambda r: f"{100 * _part(r, 'border')['stiffness_error']:+.1f} %",
    "net": lambda r: f"{_part(r, 'net')['material']} {_part(r, 'net')['section']}",
    "net_error": lambda r: f"{100 * _part(r, 'net')['stiffness_error']:+.0f} %",
    "net_size": lambda r: "{:.1f} x {:.1f} mm".format(*r["assembly"]["net_size_mm"]),
    "nodes_prototype": lambda r: str(r["size"]["nets"]["prototype"]["nodes"]),
    "nodes_model": lambda r: str(r["size"]["nets"]["model"]["nodes"]),
    "cable_ea": lambda r: f"{r['selection']['cable']['ranked'][0]['stiffness']:.0f} N",
    "paper_net_stiffness": lambda r: f"{_net(r, 3)['stiffness']:.0f} N/m",
    "paper_net_error": lambda r: f"{100 * _net(r, 3)['error_low_strain']:+.0f} %",
    "paper_net_error_high": lambda r: f"{100 * _net(r, 3)['error_high_strain']:+.0f} %",
    "net_error_high": lambda r: f"{100 * _net(r, 2)['error_high_strain']:+.0f} %",
    "paper_net_stiffness_across": lambda r: f"{_net(r, 3)['stiffness_across']:.0f} N/m",
    "paper_net_stiffness_up": lambda r: f"{_net(r, 3)['stiffness_up']:.1f} N/m",
    "paper_net_across": lambda r: f"{1 + _net(r, 3)['stiffness_error_across']:.1f}x",
    "paper_net_up": lambda r: f"{1 + _net(r, 3)['stiffness_error_up']:.1f}x",
    "net_errors": lambda r: _both(_part(r, "net")),
    "tpe_net_errors": lambda r: _both(_net(r, 2)),
    "deflection_model": lambda r: f"{_at_1(r, 'deflection', 'nominal'):.3f}",
    "deflection_prototype": lambda r: f"{_at_1(r, 'deflection', 'prototype'):.3f}",
    "strain_mid_model": lambda r: f"{100 * _at_1(r, 'strain_mid', 'nominal'):.1f} %",
    "strain_mid_prototype": lambda r: f"{100 * _at_1(r, 'strain_mid', 'prototype'):.1f} %",
    "steel_deflection": lambda r: f"{_steel(r, 'steel E'):.3f}",
    "scaled_e_deflection": lambda r: f"{_steel(r, 'E scaled by 1/lambda'):.3f}",
    "verdict": lambda r: r["summary"]["verdict"],
    "reason": lambda r: _one_line(r["summary"]["reason"]),
    "band_deflection": lambda r: r["summary"]["band"]["deflection"],
    "sensors": lambda r: r["summary"]["sensors"],
    "next": lambda r: r["summary"]["next"],
    "print_time": lambda r: _duration(r["summary"]["print"]["print_time_s"]),
    "filament": lambda r: f"{r['summary']['print']['filament_mm'] / 1000:.2f} m",
    "mass": lambda r: f"{r['summary']['print']['mass_g']:.1f} g",
    "files": lambda r: str(len(r["files"])),
}


def numbers(out: Path) -> dict[str, str]:
    """Every NUMBERS value of the run in the folder `out`, the run's paths written as the
    tutorial's commands name them (the prototype `proto.toml`, the output folder `o`)."""
    report = json.loads((out / "report.json").read_text("utf-8"))
    return {key: _as_tutorial(value(report), out) for key, value in NUMBERS.items()}


def _as_tutorial(text: str, out: Path) -> str:
    """`text` with the run's output folder written `o` and its prototype `proto.toml`."""
    for folder in {str(out.resolve()), str(out)}:
        text = text.replace(folder, "o")
    text = text.replace(" OUT/", " o/").replace(" OUT-next", " o-next")
    text = text.replace("(OUT: ", "(o: ")
    return re.sub(r"\S*realistic_barrier\.toml", "proto.toml", text)


def marked(text: str) -> list[tuple[str, str]]:
    """(KEY, value) of every marked number of a page, in page order."""
    return [(m.group(1), m.group(2)) for m in MARK.finditer(text)]


def rewrite(text: str, values: dict[str, str]) -> str:
    """`text` with every marked number replaced by its value (an unknown KEY is an error)."""
    def one(m: re.Match[str]) -> str:
        if m.group(1) not in values:
            raise KeyError(f"unknown worked number {m.group(1)!r}: one of {sorted(values)}")
        return f"<!--n:{m.group(1)}-->{values[m.group(1)]}<!--/n-->"
    return MARK.sub(one, text)


def _decimals(number: str) -> int:
    return len(number.split(".", 1)[1]) if "." in number else 0


def agree(page: str, fresh: str) -> bool:
    """True when a page's value says what a fresh run's does: the same words, and each number
    within one unit of its last printed digit. Other versions of numpy or scipy move results
    by up to ~1e-4 (docs/user-guide.md, the manifest), enough to flip a rounded last digit."""
    if NUMBER.sub("#", page) != NUMBER.sub("#", fresh):
        return False
    pairs = zip(NUMBER.findall(page), NUMBER.findall(fresh), strict=True)
    return all(abs(float(a) - float(b)) <= 10.0 ** -_decimals(a) + 1e-12 for a, b in pairs)


def differences(values: dict[str, str], pages: tuple[Path, ...] = PAGES) -> list[str]:
    """'page: KEY: page value != fresh value' for every marked number that disagrees."""
    out = []
    for page in pages:
        for key, value in marked(page.read_text("utf-8")):
            if key not in values or not agree(value, values[key]):
                out.append(f"{page.relative_to(ROOT)}: {key}: {value!r} != "
                           f"{values.get(key, 'no such number')!r}")
    return out


def _fresh_run(tmp: Path) -> Path:
    import printgen

    printgen.make(EXAMPLE, SCALE, tmp / "out")
    return tmp / "out"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", type=Path,
                    help="a make of the 1:40 example (default: a fresh run)")
    ap.add_argument("--check", action="store_true", help="fail when a page's number differs")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="printgen-docs-") as tmp:
        values = numbers(args.out or _fresh_run(Path(tmp)))
    if args.check:
        if found := differences(values):
            print("\n".join(found) + "\nrun python scripts/docs_numbers.py", file=sys.stderr)
            return 1
        return 0
    for page in PAGES:
        page.write_text(rewrite(page.read_text("utf-8"), values), "utf-8")
        print(f"wrote {page.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
