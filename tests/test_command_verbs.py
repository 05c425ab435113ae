"""Every command is parsing plus one call of a public verb: the commands reach the stages only
through `printgen.run.api` (the verbs `printgen/__init__.py` exposes lazily)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import printgen
from printgen.cli import main

COMMANDS = Path(printgen.__file__).parent / "commands"
# what a command may import of printgen: the verbs, the shared parsing/printing helpers, and
# the choices its parser offers (`run.panel`'s modes and diagonals)
ALLOWED = {"printgen.run", "printgen.run.api", "printgen.commands.common", "printgen.run.panel"}


@pytest.mark.parametrize("name", ["example", "init", "panel", "testpieces"])
def test_command_imports_only_the_verbs(name):
    tree = ast.parse((COMMANDS / f"{name}.py").read_text())
    used = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module
            and n.module.startswith("printgen")}
    assert used <= ALLOWED, used - ALLOWED


@pytest.mark.parametrize("verb", ["example", "examples", "init", "panel", "testpieces"])
def test_the_commands_verbs_are_public(verb):
    assert verb in printgen.VERBS and callable(getattr(printgen, verb))


def test_example_verbs_list_find_and_copy(tmp_path):
    found = printgen.examples()
    assert "realistic" in found
    ex = printgen.example("realistic_barrier.toml")
    assert ex.name == "realistic" and not ex.is_folder and ex.files == (found["realistic"],)
    folder = next(n for n, p in found.items() if p.is_dir())
    copied = printgen.example(folder, out=tmp_path / "copy")
    assert copied.is_folder and all(f.parent == tmp_path / "copy" for f in copied.files)


def test_init_verb_refuses_an_existing_file(tmp_path, capsys):
    path = printgen.init(tmp_path / "p.toml")
    assert path.read_text().startswith("# printgen prototype file")
    assert main(["init", str(path)]) == 2
    assert "exists" in capsys.readouterr().err
