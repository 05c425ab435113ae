"""examples/realistic_1_40.ipynb runs top to bottom (so it cannot rot) and is kept in git
without outputs."""

from __future__ import annotations

import json

import pytest
from conftest import EXAMPLES

NOTEBOOK = EXAMPLES / "realistic_1_40.ipynb"
CELL_TIMEOUT_S = 600  # generous: the verification cell runs two load sweeps


def test_notebook_is_stored_without_outputs():
    nb = json.loads(NOTEBOOK.read_text("utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code and all(not c["outputs"] and c["execution_count"] is None for c in code)


@pytest.mark.slow
def test_notebook_runs():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                                     resources={"metadata": {"path": str(EXAMPLES)}})
    client.execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 2  # the deformation plot and the picture of the net
