"""The names `printgen.verification` imports from the executor's local pool, until those
modules import `printgen.executor.local` themselves: nothing is defined here."""

from printgen.executor.local import (  # noqa: F401 (re-exported)
    check_deadline,
    collect,
    report_progress,
    run_jobs,
    shared_pool,
    submit_jobs,
)
