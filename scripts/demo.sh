#!/usr/bin/env bash
# Set up printgen and run it on the bundled 1:40 example (the realistic barrier).
# Usage: bash scripts/demo.sh [OUTDIR]   (default out/realistic-1-40)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
out="${1:-out/realistic-1-40}"
.venv/bin/printgen make examples/realistic_barrier.toml --scale 40 --out "$out"
