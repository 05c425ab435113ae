"""printgen's public verbs: what the CLI commands call, and what a notebook or script calls.

Each verb takes a prototype (a TOML path or an already loaded `Prototype`) and the scale
lambda, and returns the same dataclasses the CLI prints. `printgen/__init__.py` exposes them
lazily, so `import printgen` stays fast::

    import printgen
    t = printgen.targets("examples/realistic_barrier.toml", 40)
    s = printgen.select("examples/realistic_barrier.toml", 40)
    v = printgen.verify("examples/realistic_barrier.toml", 40)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from printgen.design.plan import make_design
from printgen.design.record import Design
from printgen.design.selection import Selection
from printgen.design.selection import select as _select
from printgen.design.similitude import ScaledTargets, scale_targets
from printgen.inputs.prototype import Prototype, load_prototype

if TYPE_CHECKING:
    from printgen.calibrate.pipeline import Calibration
    from printgen.calibrate.sample import FitOptions
    from printgen.run.make import MakeContext, MakeOptions
    from printgen.run.search import DesignRun, SearchOptions
    from printgen.run.series import SeriesRun
    from printgen.run.verify import VerifyRun
    from printgen.verification.series import NetOptions
    from printgen.verification.verify import Verification

PrototypeLike = str | Path | Prototype


def prototype_of(prototype: PrototypeLike) -> Prototype:
    """A loaded prototype: `prototype` itself, or the TOML file it names."""
    return prototype if isinstance(prototype, Prototype) else load_prototype(prototype)


def targets(prototype: PrototypeLike, scale: float) -> ScaledTargets:
    """Similitude targets of the model at 1:`scale` (lengths 1/lambda, forces lambda^-3, ...),
    with the Pi groups of both barriers and the Froude/Reynolds check of the model flow."""
    return scale_targets(prototype_of(prototype), scale)


def select(prototype: PrototypeLike, scale: float, *, printer: str | None = None,
           materials: Sequence[str] | None = None) -> Selection:
    """Every material x pass layout for the border cables and the net, ranked against the
    targets at 1:`scale`; `printer` and `materials` name profiles (default: the prototype's)."""
    p = prototype_of(prototype)
    return _select(p, scale_targets(p, scale), printer=printer,
                   materials=tuple(materials) if materials else None)


def plan(prototype: PrototypeLike, scale: float, *, printer: str | None = None) -> Design:
    """The printable design that `make` writes: the selection's choice, sized for the model.
    (Named `plan`, not `design`: `printgen.design` is the design stage's package.)"""
    p = prototype_of(prototype)
    t = scale_targets(p, scale)
    return make_design(p, t, _select(p, t, printer=printer))


def make(prototype: str | Path, scale: float, out: str | Path, *,
         printer: str | None = None, load: str | None = None, drag: bool = False,
         step: bool = False, options: MakeOptions | None = None,
         progress: Callable[[str], None] | None = None) -> MakeContext:
    """Targets, selection, parts (STL, 3MF, slicer profiles, G-code), the pre-print
    verification under load case `load` (`printgen.barrier.loads`, default hydrostatic;
    `drag=True` is `load="drag"`) and the report, written into the folder `out` as one
    whole run; `options` (`printgen.run.make.MakeOptions`) for the rest."""
    import dataclasses

    from printgen.run.make import MakeOptions
    from printgen.run.make import make as _make

    opts = options or MakeOptions()
    given = load if load is not None else (None if drag else opts.load)  # drag=True: "drag"
    opts = dataclasses.replace(opts, load=load_name(given, drag),
                               loads=tuple(load_name(x, False) for x in opts.loads),
                               step=step or opts.step)
    return _make(prototype, scale, out, printer=printer, options=opts, progress=progress)


def load_name(load: str | None, drag: bool) -> str:
    """The load case of `load` and its alias `drag` (True: "drag"); InputError when they
    disagree or `load` names no case."""
    from printgen.barrier.loads import get_load
    from printgen.errors import InputError

    if drag and load not in (None, "drag"):  # a spec with parameters names its case first
        raise InputError(f"--drag is --load drag, not --load {load}: give one of them")
    return get_load("drag" if drag else load).spec


def verify(prototype: PrototypeLike, scale: float, design_: Design | str | Path | None = None,
           *, printer: str | None = None, load: str | None = None,
           drag: bool = False) -> Verification:
    """The pre-print check: prototype and printed model solved under the same relative
    loading, h/h_B = 0 to 1.1, and compared by their normalised deformations. `design_` is a
    `Design` or the design.json that `make` wrote; without it, the design `make` would print
    is checked."""
    from printgen.design.design_file import load_design
    from printgen.verification.verify import verify as _verify

    p = prototype_of(prototype)
    if design_ is None:
        d = plan(p, scale, printer=printer)
    else:
        d = design_ if isinstance(design_, Design) else load_design(design_, scale=scale, prototype=p)
    return _verify(p, d, load=load_name(load, drag))


def verify_design(prototype: str | Path, scale: float, design_file: str | Path,
                  out: str | Path, *, measured: str | Path | None = None,
                  fit: str = "stiffness", load: str | None = None, drag: bool = False,
                  force: bool = False, progress: Callable[[str], None] | None = None,
                  time_limit_s: float | None = None) -> VerifyRun:
    """`printgen verify`: the pre-print check of a design.json with its uncertainty band,
    optionally compared with a lab's `measured` loading test and one factor fitted to it,
    written into the folder `out` (see `printgen.run.verify.verify_design`); refused when
    estimated longer than `time_limit_s` (None: the budget's default)."""
    from printgen.run.verify import verify_design as _verify_design

    return _verify_design(prototype, scale, design_file, out, measured=measured, fit=fit,
                          load=load_name(load, drag), force=force, progress=progress,
                          time_limit_s=time_limit_s)


def search_nets(prototype: PrototypeLike, scales: float | Sequence[float], *,
                options: SearchOptions | None = None, scheduler: str | None = None,
                serial: bool = False, workers: int | None = None,
                progress: bool = False, out: str | Path | None = None,
                main_scale: float | None = None) -> DesignRun:
    """The inverse design: the printable net that deforms most like the prototype at each
    scale (screened by the membrane law, the best verified with the solver), on a local Dask
    cluster, the cluster at `scheduler`, or serially. With `out`, the run's folder is checked
    before the search and written once, whole, after it (`DesignRun.files`); its design.json
    is the net at `main_scale` (default: the first scale)."""
    from printgen.run.search import SearchOptions, check_out, search_at_scales, write_outputs

    lams = [float(scales)] if isinstance(scales, int | float) else [float(s) for s in scales]
    if out is not None:
        check_out(out, prototype)  # before the search: a refused folder costs nothing
    run = search_at_scales(prototype, lams, options=options or SearchOptions(),
                           scheduler=scheduler, serial=serial, workers=workers,
                           progress=progress)
    if out is not None:
        write_outputs(run, out, lams[0] if main_scale is None else float(main_scale),
                      prototype)
    return run


def series(prototype: PrototypeLike, scales: Sequence[float] = (1, 10, 30, 50, 100), *,
           materials: Sequence[str] = (), load: str | None = None,
           net: NetOptions | str | None = None, out: str | Path | None = None,
           serial: bool | None = None, scheduler: str | None = None,
           workers: int | None = None, force: bool = False,
           progress: Callable[[str], None] | None = None, bar: bool = False) -> SeriesRun:
    """The virtual scale series (Lambert et al. 2023, Fig. 2): the prototype's scene at each
    1:lambda with its material unscaled, with E / lambda and with each of `materials`, under
    load case `load` at h = h_B; normalised deflection, lowering and mid-height elongation,
    the lambda range where each material stays within +-10 % of the prototype, the check
    against the (F/EA)^(1/3) law. `net`: the solver scene's options (NetOptions, or the
    `--solver-net` text). Serial for few cases, on Dask for many (the same numbers); written
    into the folder `out` when given."""
    from printgen.run.series import run_series
    from printgen.verification.series import net_options

    opts = net if not isinstance(net, str | None) else net_options(net)
    return run_series(prototype if isinstance(prototype, Prototype) else Path(prototype),
                      [float(s) for s in scales], materials=tuple(materials), load=load,
                      net=opts, out=out, serial=serial, scheduler=scheduler, workers=workers,
                      force=force, progress=progress, bar=bar)


def calibrate(paths: Sequence[str | Path], *, material: str,
              options: FitOptions | None = None, **kwargs: Any) -> Calibration:
    """Moduli, strength and panel laws of a material from tensile-test exports (see
    `printgen.calibrate.pipeline.calibrate` for every keyword)."""
    from printgen.calibrate.pipeline import calibrate as _calibrate

    return _calibrate(paths, material=material, options=options, **kwargs)
