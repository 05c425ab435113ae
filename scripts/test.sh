#!/usr/bin/env bash
# Set up (slicers included) and run the whole test suite. CI runs exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --with-slicers
# The test tools (the `test` extra: pytest, ruff, mypy, nbclient, setuptools-scm, ...) and
# cadquery for the STEP tests (the `cad` extra, ~250 MB): the suite installs them, setup.sh (what
# demo.sh runs) does not.
if ! .venv/bin/python -c "import cadquery, pytest, nbclient, setuptools_scm" 2>/dev/null; then
  .venv/bin/python -m pip install -q -e ".[all,test,cad]" >.venv/setup-test.log 2>&1 \
    || { cat .venv/setup-test.log >&2; echo "test: installing the test and cad extras failed" >&2
         exit 1; }
fi
# The documentation site's strict build (tests/test_docs.py) needs the `docs` extra, outside `all`.
if ! .venv/bin/python -c "import mkdocs, material, mkdocstrings_handlers.python" 2>/dev/null; then
  .venv/bin/python -m pip install -q -e ".[all,docs]" >.venv/setup-docs.log 2>&1 \
    || { cat .venv/setup-docs.log >&2; echo "test: installing the docs extra failed" >&2; exit 1; }
fi
export PRINTGEN_REQUIRE_DOCS=1   # the site's build fails, not skips, when MkDocs is missing
# The wheel, installed outside the clone and used from an empty folder: what a user installs.
bash scripts/test_wheel.sh
export PRINTGEN_REQUIRE_SLICERS=1   # slicer tests fail, not skip, when a slicer is missing
# ../shared tests (G-code checker, tensile exports) fail, not skip, when ../shared sits beside the
# clone or PRINTGEN_REQUIRE_SHARED=1 is given (.ci/run); a clone with nothing beside it skips them.
export PRINTGEN_REQUIRE_SHARED="${PRINTGEN_REQUIRE_SHARED:-$([[ -d ../shared ]] && echo 1 || echo 0)}"
# Lint and types, then every test (no marker filter: the `slow` ones too). Each step runs even
# when one before it failed, so one run shows every problem; the script fails if any did.
failed=()
.venv/bin/ruff check . || failed+=("ruff check")
.venv/bin/python -m mypy printgen/solver --follow-imports=silent || failed+=("mypy printgen/solver")
.venv/bin/python scripts/mypy_budget.py || failed+=("mypy printgen (scripts/mypy_budget.txt)")
.venv/bin/python -m pytest -n auto --dist loadfile "$@" || failed+=("pytest")
if ((${#failed[@]})); then
  printf 'test: failed: %s\n' "${failed[@]}" >&2
  exit 1
fi
