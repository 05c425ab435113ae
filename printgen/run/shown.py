"""How the runs' results show themselves (repr, a notebook's table: `printgen.outputs.display`):
the verdict, the design and the key numbers of a `make`, `verify`, `design` or `series` run,
never their arrays or records (`record`, `to_record()` and the fields hold those)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from printgen.outputs.display import Summary

if TYPE_CHECKING:
    from printgen.run.make import MakeContext
    from printgen.run.search import DesignRun
    from printgen.run.series import SeriesRun
    from printgen.run.verify import VerifyRun
    from printgen.scaling.record import Design
    from printgen.verification.preprint import Verification

MAX_ROWS = 12  # rows of a summary listing per-item lines (scales, sentences): the rest counted


def net_line(d: Design) -> str:
    """The printed net in one line: material, pattern, mesh and strand."""
    n = d.net
    return (f"{n.material} {n.pattern}, mesh {n.mesh_x_mm:g} x {n.mesh_y_mm:g} mm, strand "
            f"{n.strand.width_mm:g} x {n.strand.thickness_mm:g} mm")


def check_rows(v: Verification | None) -> list[tuple[str, str]]:
    """The verification's levels and verdict sentences (none when it did not run)."""
    if v is None:
        return [("verification", "not run")]
    return [("levels compared", f"{v.compared} of {v.asked or v.compared}"),
            *(("verdict", line) for line in v.headlines)]


def files_row(files: list[str]) -> tuple[str, str]:
    shown = ", ".join(files[:4]) + (f", ... ({len(files)} files)" if len(files) > 4 else "")
    return ("files", shown or "none written")


def make_summary(ctx: MakeContext) -> Summary:
    check = ctx.records.check
    v = check.verification if check is not None else None
    rows = [("prototype", ctx.prototype.name), ("net", net_line(ctx.design)),
            ("cables", str(len(ctx.design.cables))), *check_rows(v), files_row(ctx.files)]
    return Summary(f"MakeContext: printgen make at 1:{ctx.design.scale:g}", tuple(rows),
                   v.verdict if v is not None else "")


def verify_summary(run: VerifyRun) -> Summary:
    v = run.verification
    rows = [("prototype", run.prototype.name), ("net", net_line(run.design)),
            ("band", f"{len(run.band.variants)} variants")]
    rows += check_rows(v)
    if run.measurement is not None:
        rows.append(("measured test", run.measurement.path))
    if run.fit is not None:
        rows.append(("fit", f"{run.fit.kind} factor {run.fit.value:.3g}"))
    rows.append(files_row(run.files))
    return Summary(f"VerifyRun: printgen verify at 1:{run.design.scale:g}", tuple(rows),
                   v.verdict)


def design_summary(run: DesignRun) -> Summary:
    rows = [("where", run.where)]
    for r in run.results[:MAX_ROWS]:
        found = net_line(r.design) if r.design is not None else "no printable net: " + (
            "; ".join(r.reasons) or "none found")
        rows.append((f"1:{r.scale:g} ({r.objective}, {len(r.screened)} screened)", found))
    if len(run.results) > MAX_ROWS:
        rows.append(("more scales", str(len(run.results) - MAX_ROWS)))
    rows.append(files_row(run.files))
    return Summary("DesignRun: printgen design", tuple(rows))


def series_summary(run: SeriesRun) -> Summary:
    s = run.series
    rows = [("prototype", s.prototype), ("scales", ", ".join(f"{x:g}" for x in s.scales)),
            ("cases", f"{len(run.results)} solved ({run.where})")]
    rows += [(name, text) for name, text in list(s.sentences.items())[:MAX_ROWS]]
    rows.append(files_row(run.files))
    return Summary("SeriesRun: printgen series", tuple(rows))
