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
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from printgen.inputs.prototype import Prototype, load_prototype
from printgen.run.options import RunOptions
from printgen.scaling.plan import make_design
from printgen.scaling.record import Design
from printgen.scaling.selection import Selection
from printgen.scaling.selection import select as _select
from printgen.scaling.similitude import ScaledTargets, scale_targets

if TYPE_CHECKING:
    from printgen.calibrate.pipeline import Calibration
    from printgen.calibrate.sample import FitOptions
    from printgen.calibrate.waved import WaveCalibration
    from printgen.inputs.examples import Example
    from printgen.run.make import MakeContext
    from printgen.run.panel import PanelRun
    from printgen.run.search import DesignRun, SearchOptions
    from printgen.run.series import SeriesRun
    from printgen.run.verify import VerifyRun
    from printgen.verification.preprint import Verification
    from printgen.verification.series import NetOptions

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
    """The printable design that `make` writes: the selection's choice, sized for the model
    (the verb `design` is the inverse design search: `search_nets`)."""
    p = prototype_of(prototype)
    t = scale_targets(p, scale)
    return make_design(p, t, _select(p, t, printer=printer))


def make(prototype: str | Path, scale: float, out: str | Path, *,
         printer: str | None = None, load: str | None = None, drag: bool = False,
         step: bool = False, options: RunOptions | None = None,
         progress: Callable[[str], None] | None = None) -> MakeContext:
    """Targets, selection, parts (STL, 3MF, slicer profiles, G-code), the pre-print
    verification under load case `load` (`printgen.barrier.loads`, default hydrostatic;
    `drag=True` is `load="drag"`) and the report, written into the folder `out` as one
    whole run; `options` (`RunOptions`) for the rest (`printer`, `load` and `step` are
    shorthands of its fields)."""
    from printgen.run.make import make as _make

    opts = with_load(run_options(options, printer=printer, step=step or None), load, drag)
    opts = replace(opts, loads=tuple(load_name(x, False) for x in opts.loads))
    return _make(prototype, scale, out, options=opts, progress=progress)


def run_options(options: RunOptions | None = None, **given: Any) -> RunOptions:
    """`options` (default: `RunOptions()`) with each field of `given` that is not None in
    place: a verb's keywords are shorthands of the one options record."""
    return replace(options or RunOptions(), **{k: v for k, v in given.items() if v is not None})


def with_load(options: RunOptions, load: str | None, drag: bool) -> RunOptions:
    """`options` with the load case of `load` (else its own) and the alias `drag` checked
    and resolved into one spec (`load_name`)."""
    given = load if load is not None else (None if drag else options.load)  # drag: "drag"
    return replace(options, load=load_name(given, drag))


def load_name(load: str | None, drag: bool) -> str:
    """The load case of `load` and its alias `drag` (True: "drag"); InputError when they
    disagree or `load` names no case."""
    from printgen.barrier.loads import get_load
    from printgen.errors import InputError

    if drag and load not in (None, "drag"):  # a spec with parameters names its case first
        raise InputError(f"--drag is --load drag, not --load {load}: give one of them")
    return get_load("drag" if drag else load).spec


def verify(prototype: PrototypeLike, scale: float, design: Design | str | Path | None = None,
           *, printer: str | None = None, load: str | None = None,
           drag: bool = False) -> Verification:
    """The pre-print check: prototype and printed model solved under the same relative
    loading, h/h_B = 0 to 1.1, and compared by their normalised deformations. `design` is a
    `Design` or the design.json that `make` wrote; without it, the design `make` would print
    is checked."""
    from printgen.scaling.design_file import load_design
    from printgen.verification.preprint import verify as _verify

    p = prototype_of(prototype)
    if design is None:
        d = plan(p, scale, printer=printer)
    else:
        d = design if isinstance(design, Design) else load_design(design, scale=scale,
                                                                   prototype=p)
    return _verify(p, d, load=load_name(load, drag))


def verify_design(prototype: str | Path, scale: float, design_file: str | Path,
                  out: str | Path, *, measured: str | Path | None = None,
                  fit: str = "stiffness", load: str | None = None, drag: bool = False,
                  force: bool = False, progress: Callable[[str], None] | None = None,
                  time_limit_s: float | None = None,
                  options: RunOptions | None = None) -> VerifyRun:
    """`printgen verify`: the pre-print check of a design.json with its uncertainty band,
    optionally compared with a lab's `measured` loading test and one factor fitted to it,
    written into the folder `out` (see `printgen.run.verify.verify_design`); refused when
    estimated longer than `time_limit_s` (None: the budget's default). `options`
    (`RunOptions`) for the rest (`load`, `force` and `time_limit_s` are shorthands of its
    fields)."""
    from printgen.run.verify import verify_design as _verify_design

    opts = run_options(options, force=force or None, time_limit_s=time_limit_s)
    return _verify_design(prototype, scale, design_file, out, measured=measured, fit=fit,
                          options=with_load(opts, load, drag), progress=progress)


def search_nets(prototype: PrototypeLike, scales: float | Sequence[float], *,
                options: SearchOptions | None = None, scheduler: str | None = None,
                serial: bool = False, workers: int | None = None,
                progress: bool = False, out: str | Path | None = None,
                main_scale: float | None = None, run: RunOptions | None = None) -> DesignRun:
    """The inverse design: the printable net that deforms most like the prototype at each
    scale (screened by the membrane law, the best verified with the solver), on this
    machine's workers, the Dask cluster at `scheduler`, or serially. With `out`, the run's
    folder is checked before the search and written once, whole, after it
    (`DesignRun.files`); its design.json is the net at `main_scale` (default: the first
    scale). `run` (`RunOptions`) for how it runs (`scheduler`, `serial` and
    `workers` are shorthands of its fields)."""
    from printgen.run.search import SearchOptions, check_out, search_at_scales, write_outputs

    how = run_options(run, scheduler=scheduler, serial=serial or None, workers=workers)
    lams = [float(scales)] if isinstance(scales, int | float) else [float(s) for s in scales]
    if out is not None:
        check_out(out, prototype)  # before the search: a refused folder costs nothing
    found = search_at_scales(prototype, lams, options=options or SearchOptions(), run=how,
                             progress=progress)
    if out is not None:
        write_outputs(found, out, lams[0] if main_scale is None else float(main_scale),
                      prototype, how.command)
    return found


def series(prototype: PrototypeLike, scales: Sequence[float] = (1, 10, 30, 50, 100), *,
           materials: Sequence[str] = (), load: str | None = None,
           net: NetOptions | str | None = None, out: str | Path | None = None,
           serial: bool | None = None, scheduler: str | None = None,
           workers: int | None = None, force: bool = False,
           progress: Callable[[str], None] | None = None, bar: bool = False,
           options: RunOptions | None = None) -> SeriesRun:
    """The virtual scale series (Lambert et al. 2023, Fig. 2): the prototype's scene at each
    1:lambda with its material unscaled, with E / lambda and with each of `materials`, under
    load case `load` at h = h_B; normalised deflection, lowering and mid-height elongation,
    the lambda range where each material stays within +-10 % of the prototype, the check
    against the (F/EA)^(1/3) law. `net`: the solver scene's options (NetOptions, or the
    `--solver-net` text). Serial for few cases, on this machine's workers for many, on Dask
    with `scheduler` (the same numbers); written into the folder `out` when given. `options`
    (`RunOptions`) for how it runs (`load`, `serial`, `scheduler`, `workers` and `force` are
    shorthands of its fields)."""
    from printgen.run.series import run_series
    from printgen.verification.series import net_options

    opts = net if not isinstance(net, str | None) else net_options(net)
    how = run_options(options, load=load, serial=serial, scheduler=scheduler,
                      workers=workers, force=force or None)
    return run_series(prototype if isinstance(prototype, Prototype) else Path(prototype),
                      [float(s) for s in scales], materials=tuple(materials), net=opts,
                      out=out, options=how, progress=progress, bar=bar)


def calibrate(paths: Sequence[str | Path], *, material: str,
              options: FitOptions | None = None, **kwargs: Any
              ) -> Calibration | WaveCalibration:
    """Moduli, strength and panel laws of a material from tensile-test exports (see
    `printgen.calibrate.pipeline.calibrate` for every keyword); a waved-strand coupon's
    exports (its sidecar as `specimen_file`) against the beam model of its strands."""
    from printgen.calibrate.pipeline import calibrate as _calibrate

    return _calibrate(paths, material=material, options=options, **kwargs)


def examples() -> dict[str, Path]:
    """The bundled examples: name -> its prototype TOML or its folder of data files."""
    from printgen.inputs.examples import examples as _examples

    return _examples()


def example(name: str, out: str | Path | None = None, *,
            file: str | Path | None = None) -> Example:
    """The bundled example `name` and its files, copied into the new folder `out` when
    given (`printgen example NAME --out DIR`), or a one-file example (a prototype, the
    notebook) written into the new `file` (`printgen example NAME FILE`)."""
    from printgen.inputs.examples import example as _example

    return _example(name, out, file=file)


def init(path: str | Path, *, force: bool = False) -> Path:
    """Write the commented prototype template (every key, its unit, meaning and range) into
    the .toml file `path` (an existing one only with `force`)."""
    from printgen.inputs.template import write_template

    return write_template(path, force=force)


def panel(design_file: str | Path, *, orientations: Sequence[str] | None = None,
          mode: str = "free", wave: tuple[float, int] | None = None) -> list[PanelRun]:
    """The simulated tensile test of the design's printed net panel along each diagonal of
    `orientations` (default: both), its sides `mode` free or blocked (`printgen panel`);
    `wave` (amplitude mm, half-waves between junctions): the net with curved strands."""
    from printgen.run.panel import panel_tests

    return panel_tests(design_file, tuple(orientations) if orientations else None, mode, wave)


def testpieces(design_file: str | Path, out: str | Path, *, orientation: str = "short",
               options: RunOptions | None = None) -> dict[str, Any]:
    """The tensile coupons and the net test panel of the design, written into the folder
    `out` (`printgen testpieces`); `options` (`RunOptions`): `force`, `command`. Their
    record."""
    from printgen.run.testpieces import testpieces as _testpieces

    opts = options or RunOptions()
    return _testpieces(design_file, out, orientation=orientation, force=opts.force,
                       command=opts.command)
