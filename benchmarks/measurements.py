"""The measurements behind printgen's tuned constants, rendered from benchmarks/measurements.json
to benchmarks/measurements.md (the numbers live in the JSON; a comment beside a constant
gives its reason and points here).

    python -m benchmarks.measurements          # rewrite measurements.md
    python -m benchmarks.measurements --check  # exit 1 when measurements.md is out of date
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
DATA = HERE / "measurements.json"
PAGE = HERE / "measurements.md"


def load(path: Path = DATA) -> list[dict[str, Any]]:
    """The entries of measurements.json, in file order."""
    return json.loads(path.read_text("utf-8"))["measurements"]


def _cell(value: Any) -> str:
    text = json.dumps(value, ensure_ascii=False) if isinstance(value, dict | list) else str(value)
    return text.replace("|", "\\|")


def _table(rows: list[dict[str, Any]]) -> list[str]:
    """A Markdown table over the union of the rows' keys (first seen first)."""
    keys: list[str] = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    lines = ["| " + " | ".join(k.replace("_", " ") for k in keys) + " |",
             "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(_cell(row.get(k, "")) for k in keys) + " |" for row in rows]
    return lines


def render(entries: list[dict[str, Any]]) -> str:
    """measurements.md: one section per entry (its anchor is the entry's id)."""
    out = ["# Measurements behind the tuned constants", "",
           "Generated from `benchmarks/measurements.json` by `python -m benchmarks.measurements`;"
           " edit the JSON, not this page.", ""]
    for e in entries:
        out += [f'<a id="{e["id"]}"></a>', f"## {e['title']}", "", e["why"], ""]
        if e["constants"]:
            out += _table([{"constant": f"`{k}`", "value": v} for k, v in e["constants"].items()])
            out.append("")
        out.append(f"Measured with: {e['bench']}.")
        if e["conditions"]:
            out.append("Conditions: " + "; ".join(f"{k.replace('_', ' ')} {_cell(v)}"
                                                  for k, v in e["conditions"].items()) + ".")
        out += ["", *_table(e["rows"]), ""]
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="fail when the page is out of date")
    args = ap.parse_args(argv)
    text = render(load())
    if args.check:
        if not PAGE.exists() or PAGE.read_text("utf-8") != text:
            print(f"{PAGE} is out of date: python -m benchmarks.measurements", file=sys.stderr)
            return 1
        return 0
    PAGE.write_text(text, "utf-8")
    print(f"wrote {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
