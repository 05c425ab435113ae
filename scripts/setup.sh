#!/usr/bin/env bash
# Set up printgen on a fresh Debian 12 machine: system slicers and chromium (when root), a venv
# in .venv, and printgen with the `all` extra (every feature, no test tools: scripts/test.sh adds
# the `test` extra). Safe to run again: it skips what is already there.
# Usage: bash scripts/setup.sh [--with-slicers]
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ "${1:-}" == "--with-slicers" ]]; then
  need=()
  command -v prusa-slicer >/dev/null || need+=(prusa-slicer)
  command -v CuraEngine >/dev/null || need+=(cura-engine)
  command -v chromium >/dev/null || need+=(chromium)  # tests/test_browser.py opens the report
  if ((${#need[@]})); then
    if [[ $(id -u) -ne 0 ]]; then
      echo "setup: ${need[*]} missing; run as root or: sudo apt-get install ${need[*]}" >&2
      exit 2
    fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}"
  fi
  # CuraEngine's printer definitions live in the big 'cura' package: take only its files.
  if [[ ! -f /opt/cura-pkg/usr/share/cura/resources/definitions/fdmprinter.def.json ]]; then
    tmp=$(mktemp -d)
    (cd "$tmp" && { apt-get download cura >/dev/null 2>&1 \
        || { apt-get update -qq && apt-get download cura >/dev/null; }; } \
        && dpkg-deb -x cura_*_all.deb /opt/cura-pkg)
    rm -rf "$tmp"
  fi
fi

if [[ ! -x .venv/bin/python ]]; then
  python3 -m venv .venv
fi
# pip's and setuptools' chatter goes to a log, shown only when the install fails.
log=.venv/setup.log
if ! { .venv/bin/python -m pip install -q --upgrade pip \
       && .venv/bin/python -m pip install -q -e ".[all]"; } >"$log" 2>&1; then
  cat "$log" >&2
  echo "setup: pip install failed (log above, also in $log)" >&2
  exit 1
fi
