"""Signals at random moments to printgen commands' process groups, counted.

    python -m benchmarks.signals_at_random make:SIGHUP,design:SIGINT,testpieces:SIGTERM 20 --seed 1

Each run starts `printgen COMMAND ... --out OUT` (OUT holding a previous run) in a session of
its own, sleeps a random 0 to --max-delay seconds, sends the signal to the group and checks:
exit 128 + the signal, exactly one stderr line (the command's "stopped by SIGxxx" line), no
traceback, OUT the previous run or a new one whole, nothing beside it, no process of the
session left. It prints the failures per case; --log FILE keeps each failure's stderr.
Commands: make, design, series, testpieces (of examples/realistic_barrier.toml at 1:40).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from printgen.outputs import check_folder, write_folder  # noqa: E402

PROTOTYPE = str(ROOT / "examples" / "realistic_barrier.toml")
COMMANDS = {"make": ["make", PROTOTYPE, "-s", "40"], "design": ["design", PROTOTYPE, "-s", "40"],
            "series": ["series", PROTOTYPE], "testpieces": ["testpieces", "DESIGN"]}
PREVIOUS = {"previous.txt": "the previous run"}
EXIT_S = 120.0  # a stopped command ends well within this; past it, it is reported as a hang
GONE_S = 5.0  # its workers, fork server and resource tracker end within this


def session(sid: int) -> list[int]:
    """Processes of session `sid` that are not zombies (Linux /proc)."""
    pids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        fields = text[text.rindex(")") + 2:].split()
        if int(fields[3]) == sid and fields[0] != "Z":
            pids.append(int(stat.parent.name))
    return pids


def one_run(command: str, sig: signal.Signals, delay: float, work: Path) -> tuple[list, str]:
    """(problems, stderr) of one run signalled after `delay` seconds."""
    out = work / "out"
    write_folder(out, PREVIOUS)
    argv = [str(work / "design.json") if a == "DESIGN" else a for a in COMMANDS[command]]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-m", "printgen", *argv, "--out", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, env=env, cwd=work)
    time.sleep(delay)
    if proc.poll() is not None:
        return ["ended before the signal"], proc.communicate()[1]
    os.killpg(proc.pid, sig)
    try:
        err = proc.communicate(timeout=EXIT_S)[1]
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        return ["hang"], proc.communicate()[1]
    problems = []
    line = re.compile(rf"printgen {command}: stopped by {sig.name}"
                      r"(; outputs left as they were| after the run was complete: .+)")
    lines = err.splitlines()
    if proc.returncode != 128 + sig:
        problems.append(f"exit {proc.returncode}")
    if len(lines) != 1 or not line.fullmatch(lines[0]):
        problems.append(f"{len(lines)} stderr lines")
    if "Traceback" in err:
        problems.append("traceback")
    if check_folder(out) or not ((out / "previous.txt").exists()
                                 or (out / "manifest.json").exists()):
        problems.append("output folder not whole")
    beside = sorted(p.name for p in work.iterdir() if p.name not in ("out", "design.json"))
    if beside:
        problems.append(f"left beside it: {beside}")
    deadline = time.monotonic() + GONE_S
    while session(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    if session(proc.pid):
        problems.append(f"processes left: {session(proc.pid)}")
        for pid in session(proc.pid):
            os.kill(pid, signal.SIGKILL)
    return problems, err


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("cases", help="COMMAND:SIGNAL,... e.g. make:SIGHUP,design:SIGINT")
    p.add_argument("runs", type=int, help="runs per case")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--max-delay", type=float, default=3.0, help="seconds (default 3)")
    p.add_argument("--log", type=Path, help="write each failure's stderr here")
    args = p.parse_args()
    # a caught signal is reset to the default in the children: nohup's SIG_IGN is not passed on
    signal.signal(signal.SIGHUP, lambda *_: None)
    import printgen

    design = printgen.plan(PROTOTYPE, 40).to_dict()  # testpieces' input
    rng = random.Random(args.seed)
    log = args.log.open("w") if args.log else None
    failed = 0
    for case in args.cases.split(","):
        command, name = case.split(":")
        fails = 0
        for _ in range(args.runs):
            delay = rng.uniform(0, args.max_delay)
            with tempfile.TemporaryDirectory() as d:
                (Path(d) / "design.json").write_text(json.dumps(design))
                problems, err = one_run(command, signal.Signals[name], delay, Path(d))
            if problems and problems != ["ended before the signal"]:
                fails += 1
                if log:
                    log.write(f"== {case} after {delay:.2f} s: {problems}\n{err}\n")
        print(f"{case}: {fails}/{args.runs} failed", flush=True)
        failed += fails
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
