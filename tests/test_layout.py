"""The layout by stage (shared/design.md, docs/development.md "Where things live"): data moves down
the flow run -> report -> verification -> scene and parts -> scaling -> inputs and barrier -> ground
floor; a lower stage never imports a higher one, and solver/ never imports printgen. Imports are
read with `ast`, so a lazy import inside a function counts as much as one at the top of a module."""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import pytest
from conftest import ROOT

# Rank of each part of printgen: a module may import only parts of equal or lower rank.
RANK = {
    "solver": 0,  # the cable-net solver: numpy and scipy only, nothing else of printgen
    "errors": 0, "units": 0, "outputs": 0, "executor": 0, "trace": 0, "version": 0,  # ground floor
    "inputs": 1,
    "barrier": 1,  # beside inputs: the net patterns and load cases, as data
    "calibrate": 2,  # tensile exports -> material profiles: feeds inputs, sits beside scaling
    "scaling": 2,
    "search": 2,  # the design search: screens nets over scaling, verified by a runner it is handed
    "parts": 3,
    "scene": 4,  # the solver scenes: beside parts in the flow, above scaling (APART keeps them so)
    "verification": 5,
    "report": 6,
    "run": 7,
    "commands": 8, "cli": 8, "__main__": 8, "__init__": 8,  # the CLI and the public verbs
}
APART = {("scene", "parts")}  # (importer, imported) of the same floor: siblings, not stacked
OUTSIDE = {"benchmarks": 8}  # a source checkout's folders: only the CLI may reach them
TOP_LEVEL_MODULES_MAX = 8  # at most 8 modules at printgen/'s top level


def part_of(module: str) -> str:
    """'printgen.verification.preprint' -> 'verification'; 'printgen' -> '__init__'."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def imported_modules(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in the file, relative ones resolved."""
    tree = ast.parse(path.read_text("utf-8"), filename=str(path))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            out.append((node.lineno, base))
            out += [(node.lineno, f"{base}.{a.name}") for a in node.names
                    if base == "printgen"]  # `from printgen import outputs`
        elif isinstance(node, ast.Call) and _is_import_module(node) and node.args:
            out.append((node.lineno, _literal_prefix(node.args[0])))
    return out


def _is_import_module(node: ast.Call) -> bool:
    """`importlib.import_module(...)` or `import_module(...)`."""
    f = node.func
    return (isinstance(f, ast.Attribute) and f.attr == "import_module") or \
        (isinstance(f, ast.Name) and f.id == "import_module")


def _literal_prefix(arg: ast.expr) -> str:
    """The module a dynamic import names, as far as it is literal: "benchmarks.bench_" of
    f"benchmarks.bench_{name}"."""
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return arg.value
    if isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
        return str(arg.values[0].value)
    return "?"


def layout_violations(root: Path) -> list[str]:
    """Every import in root/printgen that runs up the flow, and any printgen import in
    root/printgen/solver but of the solver itself, as 'file:line: what'."""
    bad = []
    for path in sorted((root / "printgen").rglob("*.py")):
        rel = path.relative_to(root)
        module = ".".join(rel.with_suffix("").parts)
        package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
        mine = part_of(module.removesuffix(".__init__"))
        for line, name in imported_modules(path, package):
            if mine == "solver" and name.startswith("printgen") and part_of(name) != "solver":
                bad.append(f"{rel}:{line}: solver imports {name}")
                continue
            top = name.split(".")[0]
            if top in OUTSIDE and RANK.get(mine, -1) < OUTSIDE[top]:
                bad.append(f"{rel}:{line}: {mine} (rank {RANK.get(mine)}) imports {name} "
                           f"(outside printgen, rank {OUTSIDE[top]})")
                continue
            if name == "printgen" or not name.startswith("printgen."):
                continue
            theirs = part_of(name)
            if RANK.get(theirs, 99) > RANK.get(mine, -1) or (mine, theirs) in APART:
                bad.append(f"{rel}:{line}: {mine} (rank {RANK.get(mine)}) imports {name} "
                           f"({theirs}, rank {RANK.get(theirs)})")
    return bad


def test_no_import_runs_up_the_flow():
    assert layout_violations(ROOT) == []


def test_the_benchmarks_import_of_the_bench_command_is_seen():
    """commands/bench.py loads benchmarks/bench_<name>.py with importlib: the check reads it."""
    path = ROOT / "printgen" / "commands" / "bench.py"
    names = [n for _, n in imported_modules(path, "printgen.commands")]
    assert "benchmarks.bench_" in names


def test_every_part_has_a_rank():
    """A new top-level module or folder must be placed in the flow (added to RANK)."""
    names = {p.stem for p in (ROOT / "printgen").iterdir()
             if (p.suffix == ".py" or (p.is_dir() and (p / "__init__.py").exists()))}
    assert names - set(RANK) == set()


def test_top_level_stays_small():
    modules = sorted(p.name for p in (ROOT / "printgen").glob("*.py"))
    assert len(modules) <= TOP_LEVEL_MODULES_MAX, modules


@pytest.mark.slow
@pytest.mark.parametrize(("victim", "line", "expected"), [
    ("printgen/inputs/schema.py", "from printgen.run.make import make\n", "inputs (rank 1)"),
    ("printgen/parts/geometry/cable.py", "    from printgen.verification import preprint\n",
     "printgen.verification"),
    ("printgen/solver/laws.py", "import printgen.units\n", "solver imports printgen.units"),
    ("printgen/scene/scenes.py", "    from printgen.verification.preprint import sweep\n",
     "scene (rank 4) imports printgen.verification"),
    ("printgen/scene/mount.py", "from printgen.parts.geometry import cable\n",
     "scene (rank 4) imports printgen.parts"),
    ("printgen/scaling/record.py", "from printgen.scene.scenes import BarrierScene\n",
     "scaling (rank 2) imports printgen.scene"),
    ("printgen/run/budget.py", "    importlib.import_module('benchmarks.bench_make')\n",
     "outside printgen"),
])
def test_a_wrong_import_is_caught(tmp_path, victim, line, expected):
    """The check fails on a deliberately wrong import in a copy of the tree."""
    shutil.copytree(ROOT / "printgen", tmp_path / "printgen",
                    ignore=shutil.ignore_patterns("__pycache__"))
    target = tmp_path / victim
    text = target.read_text("utf-8")
    if line.startswith(" "):  # a lazy import inside a function body
        line = "def _lazy():\n" + line
    target.write_text(text + "\n\n" + line)
    found = layout_violations(tmp_path)
    assert len(found) == 1 and expected in found[0], found
