"""Ground floor: what printgen writes and how it reads its inputs.

- `files`: single files written atomically; inputs read only when regular and not too large.
- `lock`: the lock beside an output folder (flock, or an exclusive lock file elsewhere).
- `manifest`: `manifest.json`, the check of a folder against it, and whether a folder is
  printgen's own.
- `folder`: a whole run staged and swapped in as one folder, and the checks that keep a run
  from touching anything outside it.
"""

from printgen.outputs.files import (
    INPUT_LIMIT_BYTES,
    InputFileError,
    OutputError,
    describe_os_error,
    os_error_exit_code,
    read_input,
    read_input_text,
    write_bytes,
    write_text,
)
from printgen.outputs.folder import (
    check_destination,
    check_inputs_outside,
    staged_dir,
    tracking_swaps,
    write_folder,
)
from printgen.outputs.lock import LockError, folder_lock
from printgen.outputs.manifest import (
    MANIFEST,
    TIMINGS,
    check_folder,
    file_digest,
    folder_files,
    foreign_entry,
    read_manifest,
    write_manifest,
)

__all__ = ["INPUT_LIMIT_BYTES", "MANIFEST", "TIMINGS", "InputFileError", "LockError",
           "OutputError", "check_destination", "check_folder", "check_inputs_outside",
           "describe_os_error", "file_digest", "folder_files", "folder_lock", "foreign_entry",
           "os_error_exit_code", "read_input", "read_input_text", "read_manifest", "staged_dir",
           "tracking_swaps", "write_bytes", "write_folder", "write_manifest", "write_text"]
