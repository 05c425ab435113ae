"""Type-check printgen/ against its error budget: `mypy printgen` may report at most the count in
scripts/mypy_budget.txt. Prints the count; exits 1 when it rose above the budget (fix the new
errors), 0 otherwise (when it fell, lower the budget in the same commit so it cannot rise back).
`mypy printgen/solver` must be clean: scripts/test.sh runs it on its own.

Usage: python scripts/mypy_budget.py [--budget FILE]   (the python whose mypy is used)
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUDGET = ROOT / "scripts" / "mypy_budget.txt"
FOUND = re.compile(r"^Found (\d+) errors? in \d+ files?", re.MULTILINE)


def read_budget(path: Path = BUDGET) -> int:
    """The allowed error count: the first line of the budget file that is not a comment."""
    for line in path.read_text("utf-8").splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            return int(line.strip())
    raise ValueError(f"{path}: no error count in it")


def count_errors(output: str) -> int:
    """mypy's own total ("Found N errors in M files"), or 0 when it says Success."""
    m = FOUND.search(output)
    if m:
        return int(m.group(1))
    if "Success: no issues found" in output:
        return 0
    raise ValueError(f"mypy gave no count:\n{output}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=Path, default=BUDGET)
    args = ap.parse_args(argv)
    run = subprocess.run([sys.executable, "-m", "mypy", "printgen"], cwd=ROOT,
                         capture_output=True, text=True, check=False)
    errors, budget = count_errors(run.stdout + run.stderr), read_budget(args.budget)
    print(f"mypy printgen: {errors} errors (budget {budget})")
    if errors > budget:
        print(run.stdout, end="")
        print(f"mypy printgen: {errors} errors, above the budget of {budget} in {args.budget}: "
              "fix the new ones", file=sys.stderr)
        return 1
    if errors < budget:
        print(f"mypy printgen: below the budget; lower {args.budget.name} to {errors}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
