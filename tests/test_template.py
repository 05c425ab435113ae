"""`printgen init` (issue 23): the template names every key of the prototype schema with its
unit and range, loads as written, and loads with every optional table and key switched on."""

from __future__ import annotations

import re

import pytest

from printgen.cli import main
from printgen.inputs.prototype import SCHEMA_TABLES, load_prototype
from printgen.inputs.template import template_text

SWITCH = re.compile(r"^# (\[[\w.]+\]|\w+ = .*)$")  # a commented-out table or key line


def test_template_loads_as_written_and_names_every_key(tmp_path):
    text = template_text()
    p = tmp_path / "t.toml"
    p.write_text(text)
    proto = load_prototype(p)
    assert proto.width == pytest.approx(12.0) and proto.border is None
    for _table, fields in SCHEMA_TABLES:
        for f in fields:
            if f.kind is not dict:
                assert re.search(rf"^# {f.key}: .+", text, re.MULTILINE), f.key


def test_every_optional_table_and_key_switched_on_loads(tmp_path):
    on = "\n".join(SWITCH.sub(r"\1", ln) for ln in template_text().splitlines())
    p = tmp_path / "all.toml"
    p.write_text(on + "\n")
    proto = load_prototype(p)
    assert proto.border is not None and proto.flume is not None
    assert proto.net.panel_law is not None and proto.model.mesh_x_mm == pytest.approx(5.0)


def test_init_writes_the_file_and_refuses_to_overwrite(tmp_path, capsys):
    p = tmp_path / "mine.toml"
    assert main(["init", str(p)]) == 0 and p.read_text() == template_text()
    assert main(["init", str(p)]) == 2
    assert "exists" in capsys.readouterr().err
