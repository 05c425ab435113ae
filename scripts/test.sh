#!/usr/bin/env bash
# Set up (slicers included) and run the whole test suite. CI runs exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --with-slicers
export PRINTGEN_REQUIRE_SLICERS=1   # slicer tests fail, not skip, when a slicer is missing
exec .venv/bin/python -m pytest -n auto --dist loadfile "$@"
