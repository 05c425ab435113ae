"""`manifest.json`: what a printgen output folder holds, and whether a folder is one.

The manifest lists every file's sha256 and size, plus what the caller adds (version, inputs,
command line), the `volatile` file whose bytes differ between identical runs (only the timings
may be), and `manifest_sha256`, a digest of the manifest's own content (every key but that
one, as canonical JSON), so that an edit of the manifest itself (a file moved to `volatile`, the
version or command changed) is found by `check_folder` like an edit of any file.

A folder is printgen's own (`foreign_entry` is None) when its manifest reads against this
schema and the folder holds exactly the files it lists: no other file, folder, link or special
file. Only such a folder is replaced whole by a new run without --force.
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
from pathlib import Path
from typing import Any

from printgen.errors import InputError
from printgen.outputs.files import kind_of, read_input

MANIFEST = "manifest.json"
MANIFEST_FORMAT = 2  # 2: manifest_sha256 added (format 1 folders are read, and reported)
FORMATS = (1, 2)
TIMINGS = "timings.json"  # the one file allowed to be volatile
DIGEST_KEY = "manifest_sha256"
MANIFEST_LIMIT_BYTES = 8 << 20  # a run writes ~50 files (~10 kB of manifest)
CHUNK_BYTES = 1 << 20  # read size when hashing files


def file_digest(path: Path) -> dict[str, Any]:
    """{"sha256": hex, "bytes": size} of one regular file."""
    h, size = hashlib.sha256(), 0
    with open(path, "rb") as fh:
        while chunk := fh.read(CHUNK_BYTES):
            h.update(chunk)
            size += len(chunk)
    return {"sha256": h.hexdigest(), "bytes": size}


def walk(folder: Path) -> tuple[list[str], dict[str, str]]:
    """(regular files, {other entry: what it is}) under `folder`, as relative POSIX paths,
    sorted; links are not followed (a link is an entry, never its target), folders are listed
    among the others as 'a folder'."""
    files: list[str] = []
    others: dict[str, str] = {}
    todo = [(Path(folder), "")]
    while todo:
        here, prefix = todo.pop()
        with os.scandir(here) as it:
            for e in it:
                rel = prefix + e.name
                mode = e.stat(follow_symlinks=False).st_mode
                if stat.S_ISREG(mode):
                    files.append(rel)
                elif stat.S_ISDIR(mode):
                    others[rel] = "a folder"
                    todo.append((Path(e.path), rel + "/"))
                else:
                    others[rel] = "a symbolic link" if stat.S_ISLNK(mode) else kind_of(mode)
    return sorted(files), dict(sorted(others.items()))


def folder_files(folder: Path) -> list[str]:
    """Relative POSIX paths of every regular file under `folder` (links not followed)."""
    return walk(folder)[0]


def manifest_digest(manifest: dict[str, Any]) -> str:
    """sha256 of the manifest's canonical JSON without its own digest."""
    body = {k: v for k, v in manifest.items() if k != DIGEST_KEY}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def write_manifest(folder: Path, meta: dict[str, Any], volatile: tuple[str, ...]) -> dict:
    """Write `manifest.json`: meta, the volatile name, every other file's digest, and the
    manifest's own digest. Volatile files are listed by name only, so that identical runs give
    identical manifests."""
    if any(v != TIMINGS for v in volatile):
        raise ValueError(f"only {TIMINGS} may be volatile, got {volatile}")
    files = {rel: file_digest(folder / rel) for rel in folder_files(folder)
             if rel != MANIFEST and rel not in volatile}
    manifest = {**meta, "format": MANIFEST_FORMAT, "files": files, "volatile": list(volatile)}
    manifest[DIGEST_KEY] = manifest_digest(manifest)
    text = json.dumps(manifest, indent=2, sort_keys=True) + "\n"
    (folder / MANIFEST).write_text(text, encoding="utf-8")
    return manifest


def read_manifest(folder: Path) -> dict[str, Any]:
    """The manifest of an output folder, checked against the schema; InputError naming what is
    wrong when the folder or its manifest is missing, not a regular file, or not printgen's."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder} is not a folder; give a printgen output folder")
    path = folder / MANIFEST
    if not os.path.lexists(path):
        raise InputError(f"{folder} has no {MANIFEST}: it is not a printgen output folder "
                         "(or was written before manifests existed); run make again")
    if path.is_symlink():
        raise InputError(f"{path} is a symbolic link, not printgen's manifest; the folder was "
                         "altered")
    raw = read_input(path, "manifest", limit=MANIFEST_LIMIT_BYTES)
    try:
        data = json.loads(raw.decode("utf-8"))
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:  # JSON, digits, nesting
        raise InputError(f"{path} is not valid JSON ({type(exc).__name__}: "
                         f"{' '.join(str(exc).split())[:120]}); the folder was altered") from None
    problem = schema_problem(data)
    if problem:
        raise InputError(f"{path}: {problem}; it is not a printgen manifest (or was altered)")
    return data


def schema_problem(data: Any) -> str | None:
    """What makes `data` not a printgen manifest, or None."""
    if not isinstance(data, dict):
        return f"expected a JSON object, got {type(data).__name__}"
    fmt = data.get("format")
    if isinstance(fmt, bool) or fmt not in FORMATS:
        return f"format {fmt!r} is not one of {', '.join(map(str, FORMATS))}"
    files = data.get("files")
    if not isinstance(files, dict):
        return "no 'files' table"
    for rel, entry in files.items():
        if not _entry_ok(entry) or not _relative_ok(rel):
            return (f"file entry {rel[:80]!r}: {_short(entry)} is not "
                    "{'sha256': hex, 'bytes': size}")
    volatile = data.get("volatile", [])
    if not isinstance(volatile, list) or any(v != TIMINGS for v in volatile):
        return f"volatile = {_short(volatile)}: only [{TIMINGS!r}] may be volatile"
    command = data.get("command")
    if command is not None and not (isinstance(command, list)
                                    and all(isinstance(c, str) for c in command)):
        return f"command = {_short(command)} is not a list of strings"
    if not isinstance(data.get("printgen_version", ""), str):
        return "'printgen_version' is not text"
    if fmt >= 2 and not isinstance(data.get(DIGEST_KEY), str):
        return f"no {DIGEST_KEY!r} (format {fmt} has one)"
    return None


def _short(value: Any) -> str:
    """repr of a value read from the manifest, cut to one short line."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 80 else text[:77] + "..."


def _entry_ok(entry: Any) -> bool:
    return (isinstance(entry, dict) and set(entry) == {"sha256", "bytes"}
            and isinstance(entry["sha256"], str) and len(entry["sha256"]) == 64
            and isinstance(entry["bytes"], int) and not isinstance(entry["bytes"], bool)
            and entry["bytes"] >= 0)


def _relative_ok(rel: Any) -> bool:
    parts = rel.split("/") if isinstance(rel, str) else [""]
    return rel != MANIFEST and all(p not in ("", ".", "..") for p in parts) and "\\" not in rel


def check_folder(folder: Path) -> list[str]:
    """What differs between `folder` and its manifest: one line per difference (a file
    missing, changed or extra; an extra folder, link or special file; the manifest's own
    content edited), [] when it matches."""
    folder = Path(folder)
    m = read_manifest(folder)
    out = []
    if m["format"] < 2:
        out.append(f"{MANIFEST}: format {m['format']} carries no digest of its own content "
                   "(written by an older printgen); run make again to get one")
    elif m[DIGEST_KEY] != manifest_digest(m):
        out.append(f"changed: {MANIFEST} (its content does not match its {DIGEST_KEY}: the "
                   "manifest itself was edited)")
    files, others = walk(folder)
    present = set(files) - {MANIFEST}
    for rel, want in sorted(m["files"].items()):
        if rel not in present:
            what = f" ({others[rel]} in its place)" if rel in others else ""
            out.append(f"missing: {rel}{what}")
            continue
        got = file_digest(folder / rel)
        if got != want:
            out.append(f"changed: {rel} ({got['bytes']} bytes, sha256 {got['sha256'][:12]}; "
                       f"manifest: {want['bytes']} bytes, {want['sha256'][:12]})")
    volatile = set(m.get("volatile", []))
    out += [f"missing: {rel} (volatile)" for rel in sorted(volatile - present)]
    out += [f"extra: {rel}" for rel in sorted(present - set(m["files"]) - volatile)]
    out += [f"extra: {rel} ({what})" for rel, what in _foreign_others(m, others)]
    return out


def _foreign_others(m: dict[str, Any], others: dict[str, str]) -> list[tuple[str, str]]:
    """Entries that are not regular files and not a folder holding a listed file."""
    listed = [*m["files"], *m.get("volatile", [])]
    parents = {"/".join(rel.split("/")[:i]) for rel in listed for i in range(1, rel.count("/") + 1)}
    return [(rel, what) for rel, what in others.items()
            if not (what == "a folder" and rel in parents)]


def foreign_entry(folder: Path) -> str | None:
    """None when `folder` is printgen's own output (a manifest of this schema, and nothing in
    the folder but the files it lists), else the first foreign entry, with why."""
    if not os.path.lexists(Path(folder) / MANIFEST):
        first = min(os.listdir(folder), default=None)
        return None if first is None else f"{first} (the folder has no {MANIFEST})"
    try:
        m = read_manifest(folder)
    except InputError as exc:
        return f"{MANIFEST} ({exc})"
    files, others = walk(folder)
    allowed = {MANIFEST, *m["files"], *m.get("volatile", [])}
    extra = [f"{rel} (not in its {MANIFEST})" for rel in files if rel not in allowed]
    extra += [f"{rel} ({what})" for rel, what in _foreign_others(m, others)]
    return min(extra, default=None)


def edited_files(folder: Path) -> list[str]:
    """The files of printgen's own output `folder` whose bytes differ from its manifest: a
    lab's readings typed into the measurement sheet, notes added to a CSV. [] when none (or
    when the folder has no manifest that reads: `foreign_entry` answers for it)."""
    try:
        m = read_manifest(Path(folder))
    except InputError:
        return []
    return [rel for rel, want in sorted(m["files"].items())
            if (Path(folder) / rel).is_file() and not (Path(folder) / rel).is_symlink()
            and file_digest(Path(folder) / rel) != want]
