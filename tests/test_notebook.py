"""The example notebook (examples/realistic_1_40.ipynb, shipped as `printgen example notebook`)
runs top to bottom from a folder of its own (so it cannot rot, and needs no clone), and is kept
in git without outputs."""

from __future__ import annotations

import json

import pytest
from conftest import EXAMPLES

from printgen.cli import main

NOTEBOOK = EXAMPLES / "realistic_1_40.ipynb"
CELL_TIMEOUT_S = 600  # generous: the verification cell runs two load sweeps


def code_cells(path) -> list[dict]:
    return [c for c in json.loads(path.read_text("utf-8"))["cells"] if c["cell_type"] == "code"]


def test_notebook_is_stored_without_outputs():
    code = code_cells(NOTEBOOK)
    assert code and all(not c["outputs"] and c["execution_count"] is None for c in code)


def test_notebook_reads_only_the_package(tmp_path, capsys):
    """`printgen example notebook FILE` writes it byte for byte; it names no path of a clone
    (it reads the bundled prototype through `printgen.example`)."""
    assert main(["example", "notebook", str(tmp_path / "nb.ipynb")]) == 0
    assert (tmp_path / "nb.ipynb").read_bytes() == NOTEBOOK.read_bytes()
    source = "".join("".join(c["source"]) for c in code_cells(NOTEBOOK))
    assert "examples/" not in source and "Path(" not in source and "ROOT" not in source
    assert 'printgen.example("realistic")' in source
    assert main(["example", "notebook", str(tmp_path / "nb.ipynb")]) == 2  # never replaced
    assert "nb.ipynb exists; name a new file" in capsys.readouterr().err


@pytest.mark.slow
def test_notebook_runs(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.chdir(tmp_path)
    assert main(["example", "notebook"]) == 0  # the default name, in the current folder
    nb = nbformat.read(tmp_path / "realistic_1_40.ipynb", as_version=4)
    client = nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 3  # the six panels, the two of one's own axes, the net
    tables = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert any("Verification" in t and ("PASS" in t or "FAIL" in t) for t in tables)
    assert any("mid_height_elongation_model_pct" in t for t in tables)  # the curves' table
