"""`printgen check OUT`: does an output folder still hold the run its manifest describes?

Exit 0 when every file matches its sha256 and size (volatile files only need to exist), 1
with one line per difference (missing, changed or extra files), 2 when OUT is not a printgen
output folder.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from printgen.commands.common import add_json_arg, emit_json
from printgen.outputs import check_folder, read_manifest


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("check", help="verify an output folder against its manifest.json")
    p.add_argument("folder", type=Path, help="a folder written by printgen make")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    manifest = read_manifest(args.folder)
    differences = check_folder(args.folder)
    if args.json:
        emit_json({"folder": str(args.folder), "matches": not differences,
                   "differences": differences,
                   "printgen_version": manifest.get("printgen_version"),
                   "command": manifest.get("command")})
        return 1 if differences else 0
    if differences:
        for line in differences:
            print(f"{args.folder}: {line}")
        print(f"{args.folder}: {len(differences)} difference(s) from its manifest.json")
        return 1
    cmd = " ".join(manifest.get("command") or []) or "printgen.make() from Python"
    print(f"{args.folder}: {len(manifest['files'])} files match manifest.json (printgen "
          f"{manifest.get('printgen_version')}; {cmd})")
    sys.stdout.flush()
    return 0
