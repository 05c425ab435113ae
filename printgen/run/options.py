"""How a run runs: one record that the command line builds, the public verbs take and the
helper process receives (`make`'s verification sweeps), for every pipeline (make, verify,
design, series).

What a stage computes has its own record (`SearchOptions`: what the design search explores;
`NetOptions`: the solver scene; `FitOptions`: the tensile fits); this one says what the run is
given beside them: the load cases, which printer, what else to write, where it may write,
how long it may take, where its parallel work runs, and the command line that asked for it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from printgen.barrier.loads import DEFAULT as DEFAULT_LOAD


@dataclass(frozen=True)
class RunOptions:
    """The options of one run (what the command line gives; None: the pipeline's default).

    load : the verification's load case (printgen/barrier/loads, a spec with its parameters)
    loads : the load cases whose expected readings `make` writes side by side (--loads, the
      verification's own included when listed)
    printer : printer profile (None: the prototype's [model] choice)
    step : `make` also writes STEP
    pdf : `make` also prints report.pdf
    paper : report.pdf's page size (a key of `printgen.report.pdf.PAPERS`)
    design_file : `make` prints this design.json instead of the selection's choice
    time_limit_s : refuse runs estimated longer (s); None: each pipeline's default
    force : replace a folder printgen did not write
    command : the command line, recorded in the manifest
    scheduler : a running Dask scheduler (tcp://HOST:PORT) for work that may leave the
      machine; None: this machine's workers (`printgen.executor`)
    workers : worker processes on this machine (None: every core)
    serial : run in this process; None: the pipeline decides (the series by its size)
    """

    load: str = DEFAULT_LOAD
    loads: tuple[str, ...] = ()
    printer: str | None = None
    step: bool = False
    pdf: bool = False
    paper: str = "a4"
    design_file: str | Path | None = None
    time_limit_s: float | None = None
    force: bool = False
    command: list[str] | None = None
    scheduler: str | None = None
    workers: int | None = None
    serial: bool | None = None

    def to_record(self) -> dict[str, Any]:
        """The options as JSON-ready data (paths as text, tuples as lists)."""
        return {"load": self.load, "loads": list(self.loads), "printer": self.printer,
                "step": self.step, "pdf": self.pdf, "paper": self.paper,
                "design_file": None if self.design_file is None else str(self.design_file),
                "time_limit_s": self.time_limit_s, "force": self.force,
                "command": None if self.command is None else list(self.command),
                "scheduler": self.scheduler, "workers": self.workers, "serial": self.serial}
