"""What each extra of printgen adds to an install, measured, so that the docs' table of extras
(docs/index.md) types no size by hand.

    python scripts/install_sizes.py          # measure here, write the JSON, rewrite the page
    python scripts/install_sizes.py --check  # exit 1 when the page differs from the JSON

The measurement reads the environment it runs in (a development venv with `.[all,test,cad,docs]`):
for each extra, the distributions its requirements pull in (markers evaluated for this
platform), less those of the default set, and the bytes of the files each installed
distribution lists in its RECORD (byte-code caches written later at import are not counted).
An extra whose distributions are not installed here (the `pardiso` and `bench` extras of a
development venv) gets instead the download size of the files `pip install --dry-run` would
fetch for it on this platform, less those installed here, marked as such. The numbers go to
benchmarks/install_sizes.json with the platform and Python they were measured on, and into the
page between `<!--size:EXTRA-->...<!--/size-->` markers.
"""

from __future__ import annotations

import argparse
import json
import platform
import re
import subprocess
import sys
import tempfile
import urllib.request
from importlib import metadata
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parent.parent
JSON = ROOT / "benchmarks" / "install_sizes.json"
PAGE = ROOT / "docs" / "index.md"
MARK = re.compile(r"<!--size:([\w-]+)-->(.*?)<!--/size-->", re.DOTALL)
MB = 1e6  # sizes in decimal megabytes, as `du --si` and PyPI's pages show them


def _installed(name: str) -> metadata.Distribution | None:
    try:
        return metadata.distribution(name)
    except metadata.PackageNotFoundError:
        return None


def _wanted(req: Requirement, extras: set[str]) -> bool:
    """Whether `req` applies on this platform for a distribution asked with `extras`."""
    if req.marker is None:
        return True
    return any(req.marker.evaluate({"extra": e}) for e in (extras or {""}))


def closure(reqs: list[Requirement], extras: set[str] | None = None
            ) -> tuple[dict[str, metadata.Distribution], set[str]]:
    """The installed distributions `reqs` (requirements of a distribution asked with `extras`)
    pull in, by canonical name, and the names of those that are not installed here (their own
    requirements are not followed)."""
    found: dict[str, metadata.Distribution] = {}
    missing: set[str] = set()
    asked: set[tuple[str, frozenset[str]]] = set()
    todo = [(r, set(extras or ())) for r in reqs]
    while todo:
        req, parent_extras = todo.pop()
        if not _wanted(req, parent_extras):
            continue
        name = canonicalize_name(req.name)
        key = (name, frozenset(req.extras))
        if key in asked:
            continue
        asked.add(key)
        dist = _installed(name)
        if dist is None:
            missing.add(name)
            continue
        found[name] = dist
        todo += [(Requirement(r), set(req.extras)) for r in dist.requires or ()]
    return found, missing


def dist_bytes(dist: metadata.Distribution) -> int:
    """The bytes of the files a distribution's RECORD lists (those present on disk)."""
    total = 0
    for f in dist.files or ():
        path = Path(str(dist.locate_file(f)))
        if path.is_file():
            total += path.stat().st_size
    return total


def _bare(req: Requirement) -> str:
    """`req` without its marker (evaluated already), as pip takes it on a command line."""
    extras = f"[{','.join(sorted(req.extras))}]" if req.extras else ""
    return f"{req.name}{extras}{req.specifier}"


def _url_size(url: str) -> int:
    """The size of the file at `url` (its Content-Length, without downloading it)."""
    request = urllib.request.Request(url, method="HEAD")
    with urllib.request.urlopen(request, timeout=30) as response:
        return int(response.headers["Content-Length"])


def _missing_download(reqs: list[Requirement]) -> tuple[int, list[str]]:
    """Download bytes of what pip would install for `reqs` on this platform and is not
    installed here, and those distributions' names (pip resolves: `install --dry-run`)."""
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "report.json"
        subprocess.run([sys.executable, "-m", "pip", "install", "--dry-run", "--quiet",
                        "--ignore-installed", "--report", str(report), *map(_bare, reqs)],
                       check=True)
        items = json.loads(report.read_text("utf-8"))["install"]
    total, names = 0, []
    for item in items:
        name = canonicalize_name(item["metadata"]["name"])
        if _installed(name) is not None:
            continue
        total += _url_size(item["download_info"]["url"])
        names.append(name)
    return total, sorted(names)


def measure() -> dict:
    """Every extra's size (installed, or downloaded where not installed) beside the default set."""
    me = metadata.distribution("printgen")
    reqs = [Requirement(r) for r in me.requires or ()]
    extras = sorted(set(me.metadata.get_all("Provides-Extra") or ()))
    base = [r for r in reqs if r.marker is None]
    default, _ = closure(base)
    rows: dict[str, dict] = {
        "(none)": {"installed_mb": round(sum(map(dist_bytes, default.values())) / MB),
                   "distributions": len(default)}}
    for extra in extras:
        mine = [r for r in reqs if r.marker is not None and r.marker.evaluate({"extra": extra})]
        found, missing = closure(mine, {extra})
        found = {k: v for k, v in found.items() if k not in default and k != "printgen"}
        row = {"installed_mb": round(sum(map(dist_bytes, found.values())) / MB),
               "distributions": len(found)}
        if missing:
            download, names = _missing_download([r for r in mine if _wanted(r, {extra})])
            row.update(download_mb=round(download / MB), not_installed=sorted(names))
        rows[extra] = row
    return {"about": "MB (10^6 bytes) each extra adds to the default set: files of installed "
                     "distributions (RECORD), or wheel downloads from PyPI where not installed",
            "platform": f"{platform.system()} {platform.machine()}",
            "python": platform.python_version(), "extras": rows}


def cell(row: dict) -> str:
    """The table's text for one extra."""
    if "download_mb" in row:
        return f"{row['download_mb']} MB download"
    return f"{row['installed_mb']} MB"


def rewrite(text: str, sizes: dict) -> str:
    """`text` with every size marker filled from `sizes`."""
    def fill(m: re.Match[str]) -> str:
        key = m.group(1)
        if key == "platform":
            value = f"{sizes['platform']}, Python {sizes['python']}"
        else:
            value = cell(sizes["extras"]["(none)" if key == "none" else key])
        return f"<!--size:{key}-->{value}<!--/size-->"
    return MARK.sub(fill, text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="compare the page with the JSON, measure nothing")
    args = parser.parse_args(argv)
    if args.check:
        sizes = json.loads(JSON.read_text("utf-8"))
    else:
        sizes = measure()
        JSON.write_text(json.dumps(sizes, indent=1, sort_keys=True) + "\n", "utf-8")
    text = PAGE.read_text("utf-8")
    new = rewrite(text, sizes)
    if args.check:
        if new != text:
            print(f"{PAGE.relative_to(ROOT)}: sizes differ from {JSON.relative_to(ROOT)}; "
                  "measure again: python scripts/install_sizes.py", file=sys.stderr)
            return 1
        return 0
    PAGE.write_text(new, "utf-8")
    print(json.dumps(sizes["extras"], indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
