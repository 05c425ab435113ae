#!/usr/bin/env bash
# printgen as a user installs it: build the wheel from this clone, install it into a
# fresh venv outside the clone, and from an empty folder run --version, profiles list, example,
# the example notebook, make, check and calibrate --inherits petg on a generated export; then
# the same profile lookup through the clone's editable install. scripts/test.sh runs it before the suite.
# The fresh venv gets no dependencies of its own (pip --no-deps --no-index): a .pth file puts the
# clone's .venv site-packages after its own (what --system-site-packages does for the system
# Python), so the check is fast and needs no network. Only the wheel's printgen is importable
# there: the editable install's .pth hooks are not processed from a directory added that way.
# Usage: bash scripts/test_wheel.sh   (PYTHON=... to use another venv's python)
set -euo pipefail
cd "$(dirname "$0")/.."
clone=$PWD
py=${PYTHON:-$clone/.venv/bin/python}
start=$SECONDS
tmp=$(mktemp -d "${TMPDIR:-/tmp}/printgen-wheel.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "test_wheel: $*" >&2; exit 1; }

# 1. The wheel, built from a copy of the clone's files (tracked and new, not ignored), so that
# a stale build/ folder cannot leak into it. The copy has no .git: it is given the clone's
# version (setuptools-scm's, from git), which the installed `printgen --version` must show.
"$py" -c 'import setuptools_scm' 2>/dev/null \
  || fail "setuptools-scm is not installed in $py (pip install -e '.[all,test]')"
version=$(cd "$clone" && "$py" -m setuptools_scm 2>/dev/null) \
  || fail "setuptools-scm cannot name this clone's version (is it a git checkout?)"
mkdir "$tmp/src"
git ls-files -z --cached --others --exclude-standard \
  | while IFS= read -r -d '' f; do [[ -e $f ]] && printf '%s\0' "$f"; done \
  | xargs -0 cp --parents -t "$tmp/src"
SETUPTOOLS_SCM_PRETEND_VERSION_FOR_PRINTGEN=$version \
  "$py" -m pip wheel -q --no-deps --no-build-isolation --no-index -w "$tmp/dist" "$tmp/src" \
  >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log" >&2; fail "building the wheel failed"; }
wheel=$(ls "$tmp"/dist/printgen-*.whl)
built=$SECONDS
for f in printgen/profiles/materials/petg.toml printgen/profiles/printers/generic-350.toml \
         printgen/examples/realistic_barrier.toml printgen/examples/paper_1_40/measured.csv \
         printgen/examples/realistic_1_40.ipynb \
         printgen/py.typed printgen/solver/py.typed; do
  unzip -l "$wheel" "$f" >/dev/null || fail "$f missing from $(basename "$wheel")"
done
unzip -l "$wheel" '*.dist-info/licenses/LICENSE' >/dev/null || fail "LICENSE missing from the wheel"

# 2. A fresh venv outside the clone, the wheel without its dependencies, the clone's .venv
# packages behind it.
"$py" -m venv --without-pip "$tmp/venv"
site=$("$tmp/venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
"$py" -c 'import sys; print("\n".join(p for p in sys.path if p.endswith(("site-packages",
           "dist-packages"))))' >"$site/_printgen_test_deps.pth"
"$py" -m pip --python "$tmp/venv/bin/python" install -q --no-deps --no-index "$wheel" \
  >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log" >&2; fail "installing the wheel failed"; }

installed=$SECONDS

# 3. A user's empty folder: no PYTHONPATH, no clone in sight.
mkdir "$tmp/work"
cd "$tmp/work"
unset PYTHONPATH PRINTGEN_PROFILES
pg="$tmp/venv/bin/printgen"
where=$("$tmp/venv/bin/python" -c 'import printgen; print(printgen.__file__)')
[[ $where == "$site"/* ]] || fail "printgen imports from $where, not from the wheel in $site"
[[ $("$pg" --version) == "printgen $version" ]] \
  || fail "the wheel says $("$pg" --version), not the clone's version $version"
"$pg" profiles list >profiles.txt || { cat profiles.txt; fail "profiles list failed"; }
grep -q petg profiles.txt && grep -q generic-350 profiles.txt \
  || { cat profiles.txt; fail "profiles list lacks the bundled profiles"; }
if "$pg" bench make --out b >bench.txt 2>&1; then fail "bench is offered by the wheel"; fi
"$pg" example realistic >proto.toml
cmp -s proto.toml "$clone/examples/realistic_barrier.toml" || fail "example realistic differs"
"$pg" example paper_1_40 --out paper >/dev/null || fail "example paper_1_40 --out failed"
cmp -s paper/design.json "$clone/examples/paper_1_40/design.json" || fail "example paper_1_40 differs"
# the example notebook, written by the wheel and run by its Python (nbclient, a python3 kernel
# started with this venv's interpreter: the wheel's printgen), from this folder
"$pg" example notebook >/dev/null || fail "example notebook failed"
cmp -s realistic_1_40.ipynb "$clone/examples/realistic_1_40.ipynb" || fail "the notebook differs"
"$tmp/venv/bin/python" - <<'EOF' || fail "the example notebook failed to run from the wheel"
import nbclient, nbformat
nb = nbformat.read("realistic_1_40.ipynb", as_version=4)
nbclient.NotebookClient(nb, timeout=600, kernel_name="python3").execute()
errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs
          if o.output_type == "error"]
assert not errors, errors
EOF
"$pg" make proto.toml --scale 40 --out o >make.txt 2>&1 || { cat make.txt; fail "make failed"; }
"$pg" check o
grep -q '"solver_backend"' o/manifest.json || fail "manifest.json records no solver backend"

# 4. calibrate on three generated exports of a PETG cable (E = 1.30 GPa, 0.9 x 0.6 mm, 50 mm).
"$tmp/venv/bin/python" - <<'EOF'
import numpy as np
area, gauge_mm, modulus = 0.9e-3 * 0.6e-3, 50.0, 1.30e9  # m2, mm, Pa
eps = np.linspace(0.0, 0.02, 200)
for i, scale in enumerate((0.99, 1.0, 1.01)):
    rows = [f"{modulus * scale * area * e:.5f},{e * gauge_mm:.6f}" for e in eps]
    open(f"coupon{i}.csv", "w").write("Load (N),Extension (mm)\n" + "\n".join(rows) + "\n")
EOF
"$pg" calibrate coupon0.csv coupon1.csv coupon2.csv --material petg-lab --kind cable \
  --width-mm 0.9 --thickness-mm 0.6 --grip-distance-mm 50 --inherits petg --out my-profiles \
  >calibrate.txt 2>&1 || { cat calibrate.txt; fail "calibrate failed"; }
PRINTGEN_PROFILES=my-profiles "$pg" profiles show petg-lab --json >petg-lab.json
grep -q '"measured_modulus"' petg-lab.json || { cat petg-lab.json; fail "no measured modulus"; }

# 5. The editable install of this clone (setup.sh's) finds the same profiles from anywhere.
editable=$("$py" -c 'import printgen; print(printgen.__file__)' 2>&1 || true)
if [[ $editable == "$clone"/* ]]; then
  "$(dirname "$py")/printgen" profiles list --kind printers | grep -q generic-350 \
    || fail "the editable install lists no bundled printer"
  "$(dirname "$py")/printgen" example simple | cmp -s - "$clone/examples/simple_barrier.toml" \
    || fail "the editable install's example simple differs"
else
  echo "test_wheel: the editable check skipped: $py imports printgen from $editable"
fi
echo "test_wheel: $(basename "$wheel") ($(unzip -Z1 "$wheel" | wc -l) files) installed outside" \
     "the clone: profiles, example, notebook, make, check, calibrate OK in $((SECONDS - start)) s" \
     "(build $((built - start)) s, venv and install $((installed - built)) s, commands" \
     "$((SECONDS - installed)) s)"
