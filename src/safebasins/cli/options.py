"""Option values of the command line: parsed here, checked by the library's own checks.

A bad value is rejected while click parses the command line (exit status 2, the option named),
before anything is computed; the checks are the library's (``safebasins.core.checks``, the well's
methods, ``numerics.engine``), imported on use so that ``--help`` stays instant.  Defaults are
read from the library signatures and the pipeline schema, never restated.
"""
from __future__ import annotations

import contextlib
import importlib
import inspect
import math
import re
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import click

if TYPE_CHECKING:
    from safebasins.pipeline.registry import Params
    from safebasins.wells.base import Well

#: a library check: ``check(name, value)``, a well's check also taking the click context, or (option
#: callbacks) ``check(value)``; it returns the value and raises ValueError naming the argument
Check = Callable[..., Any]
#: an option callback ``callback(ctx, param, value)`` returning the parsed value
Callback = Callable[[click.Context, click.Parameter, Any], Any]
#: a click command function, as the option decorators take and return it
Cmd = TypeVar("Cmd", bound=Callable[..., Any])

#: numerics backends (safebasins.numerics.engine.BACKENDS: restated so that --help imports no numba;
#: tests/cli checks that they agree)
BACKENDS = ("cpu", "cuda", "auto")
#: first-harmonic variants (safebasins.wells.quartic.FOURIER_VARIANTS; the same)
FOURIER = ("paper", "exact")
#: library argument name -> CLI option, to name the option in errors raised by the library
OPTION_OF = {"F": "--F", "Omega": "--Omega", "Psi": "--Psi", "xi_max": "--xi-max", "q_max": "--q-max",
             "cycles": "--cycles", "steps_per_cycle": "--steps-per-cycle", "threads": "--threads",
             "xi_ini": "--xi-ini", "gamma_ini": "--gamma-ini", "tol": "--tol", "n_scan": "--n-scan",
             "F_bracket": "--F-bracket", "n_points": "--n-points", "q0": "--grid", "p0": "--grid",
             "xi_top": "--xi-top", "t_eval": "--t-eval", "backend": "--backend", "damping": "--damping",
             "noise": "--noise", "noise_time": "--noise-time", "paths": "--paths", "seed": "--seed",
             "radius_max": "--radius-max", "weights": "--weights"}

_ANGLE = re.compile(r"^([+-]?)(\d+(?:\.\d*)?|\.\d+)?\*?pi(?:/(\d+(?:\.\d*)?))?$", re.IGNORECASE)


def parse_number(text: object, angle: bool = False) -> float:
    """A float; angles may also be written with pi: ``pi``, ``-pi/2``, ``3pi/4``, ``0.5*pi``."""
    if isinstance(text, (int, float)):
        return float(text)
    s = str(text).strip().replace(" ", "")
    m = _ANGLE.match(s) if angle else None
    if m:
        sign = -1.0 if m.group(1) == "-" else 1.0
        den = float(m.group(3) or 1.0)
        if den == 0:
            raise ValueError(f"{text!r} divides by zero")
        return sign * float(m.group(2) or 1.0) * math.pi / den
    try:
        return float(s)
    except ValueError:
        raise ValueError(f"expected a number{' or a multiple of pi (pi, pi/2, -3pi/4)' if angle else ''}, "
                         f"got {text!r}") from None


def lib_check(path: str) -> Check:
    """A library check named ``module:attribute`` (imported on use: --help stays fast)."""
    def check(name: str, value: Any) -> Any:
        import importlib

        mod, _, attr = path.partition(":")
        obj: Any = importlib.import_module(mod)
        for part in attr.split("."):
            obj = getattr(obj, part)
        return obj(name, value)
    return check


NONNEG = lib_check("safebasins.core.checks:check_nonnegative")
POSITIVE = lib_check("safebasins.core.checks:check_positive")
FINITE = lib_check("safebasins.core.checks:check_finite")
#: where the eager --well option leaves the resolved well for the checks of the other options
WELL_META = "safebasins.well"


def current_well(ctx: click.Context | None) -> Well:
    """The well of the command being parsed (--well, resolved before every other option)."""
    well = ctx.meta.get(WELL_META) if ctx is not None else None
    if well is None:
        from safebasins.wells import QUARTIC

        well = QUARTIC
    return well


class WellCheck:
    """A check of the command's well (``Well.<method>(name, value)``): energies below its barrier
    energy, thresholds, displacements; called with the click context (``needs_ctx``)."""

    needs_ctx = True

    def __init__(self, method: str) -> None:
        self.method = method

    def __call__(self, name: str, value: Any, ctx: click.Context | None) -> Any:
        return getattr(current_well(ctx), self.method)(name, value)


def well_check(method: str) -> WellCheck:
    """A check of the command's well (``Well.<method>(name, value)``): energies below its barrier
    energy, thresholds, displacements."""
    return WellCheck(method)


ENERGY = well_check("check_energy")          # [0, E_b)
THRESHOLD = well_check("check_threshold")    # (0, E_b] (below an asymptote: (0, E_b))
DISPLACEMENT = well_check("check_displacement")
#: the undamped slow flow's rule (0, E_b), the band just below E_b counting as at it
analytic_threshold = well_check("check_analytic_threshold")


def analytic_thresholds(ctx: click.Context, pairs: Iterable[tuple[float, float]]) -> None:
    """``(xi_max, damping)`` pairs of a command checked by the one rule of the library: where the
    slow flow is undamped, ``Well.check_analytic_threshold`` (below the barrier energy; its level
    curves need an orbit at xi_max); the damped slow flow and the numerics take xi_max = E_b
    (``Well.check_threshold``, already checked while parsing).  A usage error naming --xi-max."""
    well = current_well(ctx)
    for xi_max, damping in pairs:
        if not damping > 0:
            try:
                well.check_analytic_threshold("xi_max", xi_max)
            except ValueError as exc:
                raise click.BadParameter(str(exc), ctx, param_hint="'--xi-max'") from None


def parse_well(text: object) -> dict[str, Any]:
    """A --well value: a name (quartic, cubic, pendulum, ...), ``polynomial:c0,c1,...``,
    ``expression:<formula in q>``, or the config's own mapping ``{expression: '1 - cos(q)'}``
    (YAML); returns the resolved spec (safebasins.wells.spec_of)."""
    from safebasins import wells

    t = str(text).strip()
    value: object
    if t.startswith("{"):
        import yaml

        try:
            value = yaml.safe_load(t)
        except yaml.YAMLError as exc:
            raise ValueError(f"well: cannot read {t!r} as a mapping ({exc.__class__.__name__})") from None
    elif t.startswith("polynomial:"):
        value = {"polynomial": [parse_number(c) for c in t.removeprefix("polynomial:").split(",") if c.strip()]}
    elif t.startswith("expression:"):
        value = {"expression": t.removeprefix("expression:").strip()}
    else:
        value = t
    return wells.spec_of(value)


def well_callback(ctx: click.Context, param: click.Parameter, value: object) -> dict[str, Any]:
    """--well (eager): the resolved spec; the well itself goes to ctx.meta for the other checks."""
    from safebasins import wells

    try:
        spec = parse_well(value)
        ctx.meta[WELL_META] = wells.from_spec(spec)
    except ValueError as exc:
        raise click.BadParameter(str(exc), ctx, param) from None
    return spec


def fourier_of(ctx: click.Context, fourier: str | None) -> str:
    """The first harmonic of the run: --fourier for the quartic (default 'paper', eq 20 as printed);
    every other well uses its exact one ('paper' is a usage error there)."""
    well = current_well(ctx)
    if well.name == "quartic":
        return fourier or "paper"
    if fourier == "paper":
        raise click.BadParameter(f"'paper' is the quartic's truncated first harmonic (eq 20); the {well.name} well "
                                 "uses its exact first harmonic", ctx, param_hint="'--fourier'")
    return "exact"


class _CheckedNumbers(click.ParamType):
    """Numbers checked by a library check under the library's argument name (:class:`Number`,
    :class:`NumberList`)."""

    def __init__(self, arg: str, check: Check, angle: bool = False) -> None:
        self.arg, self.check, self.angle = arg, check, angle

    def checked(self, value: float, ctx: click.Context | None) -> Any:
        if getattr(self.check, "needs_ctx", False):
            return self.check(self.arg, value, ctx)
        return self.check(self.arg, value)


class Number(_CheckedNumbers):
    """One finite number checked by a library check under the library's argument name."""

    name = "number"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> float:
        try:
            return float(self.checked(parse_number(value, self.angle), ctx))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


class NumberList(_CheckedNumbers):
    """Comma-separated numbers (the option may also be repeated); values must be distinct."""

    name = "list"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> list[float]:
        if isinstance(value, list):
            return value
        try:
            vals = [parse_number(v, self.angle) for v in str(value).split(",") if v.strip()]
            if not vals:
                raise ValueError(f"{self.arg} needs at least one value")
            return [float(self.checked(v, ctx)) for v in vals]
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


class Fields(click.ParamType):
    """Comma-separated fields with a fixed meaning: grid, range, bracket, resolution."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.name = {"grid": "q0min,q0max,p0min,p0max", "range": "start,stop,num", "bracket": "lo,hi",
                     "size": "N|NQxNP"}[kind]

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if not isinstance(value, str):
            return value
        try:
            return getattr(self, "_" + self.kind)(value.replace(" ", ""))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)

    @staticmethod
    def _floats(text: str, n: int, what: str) -> list[float]:
        parts = text.split(",")
        if len(parts) != n:
            raise ValueError(f"expected {n} comma-separated values ({what}), got {text!r}")
        return [float(FINITE(what, parse_number(p))) for p in parts]

    def _grid(self, text: str) -> dict[str, list[float]]:
        q_lo, q_hi, p_lo, p_hi = self._floats(text, 4, "q0min,q0max,p0min,p0max")
        for ax, lo, hi in (("q0", q_lo, q_hi), ("p0", p_lo, p_hi)):
            if not hi > lo:
                raise ValueError(f"empty {ax} interval [{lo}, {hi}]: the max must exceed the min")
        return {"q0": [q_lo, q_hi], "p0": [p_lo, p_hi]}

    def _range(self, text: str) -> dict[str, float | int]:
        parts = text.split(",")
        if len(parts) != 3:
            raise ValueError(f"expected start,stop,num (num points, endpoints included), got {text!r}")
        start, stop = (float(POSITIVE("Omega", parse_number(p))) for p in parts[:2])
        if not re.fullmatch(r"\d+", parts[2]) or int(parts[2]) < 2:
            raise ValueError(f"num must be an integer >= 2, got {parts[2]!r}")
        if not stop > start:
            raise ValueError(f"empty range: stop ({stop}) must be greater than start ({start})")
        return {"start": start, "stop": stop, "num": int(parts[2])}

    def _bracket(self, text: str) -> list[float]:
        lo, hi = (float(NONNEG("F_bracket", v)) for v in self._floats(text, 2, "lo,hi"))
        if not hi > lo:
            raise ValueError(f"empty bracket [{lo}, {hi}]")
        return [lo, hi]

    def _size(self, text: str) -> list[int]:
        m = re.fullmatch(r"(\d+)(?:x(\d+))?", text.lower())
        if not m:
            raise ValueError(f"expected N or NQxNP (points per axis), got {text!r}")
        n = [int(m.group(1)), int(m.group(2) or m.group(1))]
        if min(n) < 3:
            raise ValueError(f"at least 3 points per axis (a basin needs an interior and an edge), got {text!r}")
        return n


def checked(arg: str | None, check: Check) -> Callback:
    """Option callback running a library check that takes (name, value) or (value)."""
    def callback(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
        if value is None:
            return None
        try:
            return check(arg, value) if arg else check(value)
        except ValueError as exc:
            raise click.BadParameter(str(exc), ctx, param) from None
    return callback


def joined(unique: bool) -> Callback:
    """Callback: a repeated list option -> one list; ``unique`` for values that become a coordinate
    (curve lists of `fcr` pair up element by element and may repeat)."""
    def callback(ctx: click.Context, param: click.Parameter, value: Iterable[list[float]]) -> list[float]:
        out = [v for chunk in value for v in chunk]
        for i, v in enumerate(out):
            if unique and v in out[:i]:
                raise click.BadParameter(f"{v!r} is given twice: each value is one point of a coordinate",
                                         ctx, param)
        return out
    return callback


def from_library(func: str, arg: str) -> Callable[[], Any]:
    """Default of ``arg`` of a library function (``"module:function"``), looked up on use: the
    command line never restates a library default."""
    def default() -> Any:
        import importlib

        mod, _, name = func.partition(":")
        return inspect.signature(getattr(importlib.import_module(mod), name)).parameters[arg].default
    return default


def from_schema(kind: str, *path: str) -> Callable[[], Any]:
    """Default of a config key of a pipeline experiment kind (its schema is their one home)."""
    def default() -> Any:
        from safebasins.pipeline.config import load_kinds
        from safebasins.pipeline.registry import KINDS

        load_kinds()
        node = KINDS[kind].schema
        for p in path:
            node = node["properties"][p]
        return node["default"]
    return default


class Deferred(click.Option):
    """An option whose default is looked up on use (``from_library`` / ``from_schema``) and shown
    as its value in --help (click shows callables as "(dynamic)")."""

    def __init__(self, *args: Any, **kw: Any) -> None:
        kw.setdefault("show_default", True)
        super().__init__(*args, **kw)

    def get_default(self, ctx: click.Context, call: bool = True) -> Any:
        return super().get_default(ctx, call=True)


@contextlib.contextmanager
def library_errors() -> Iterator[None]:
    """Library ValueErrors (argument checks name the argument) -> usage errors naming the option."""
    try:
        yield
    except ValueError as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        word = re.match(r"[A-Za-z_]\w*", msg)
        if word and word.group(0) in OPTION_OF:
            raise click.BadParameter(msg, param_hint=f"'{OPTION_OF[word.group(0)]}'") from None
        raise click.UsageError(msg) from None


def out_prefix(ctx: click.Context, param: click.Parameter, value: str) -> str:
    """PREFIX of PREFIX.nc / PREFIX.png: no extension, not a folder."""
    if value.endswith((".nc", ".png")):
        raise click.BadParameter(f"give a prefix without extension (PREFIX.nc and PREFIX.png are written), "
                                 f"got {value!r}", ctx, param)
    if Path(value).is_dir() or not Path(value).name:
        raise click.BadParameter(f"{value!r} is a directory: give a file prefix such as {value.rstrip('/')}/run1",
                                 ctx, param)
    try:
        check_writable(Path(value))
    except OSError as exc:
        raise click.BadParameter(f"cannot write {value}.nc: {exc}", ctx, param) from None
    return value


def check_writable(prefix: Path) -> None:
    """OSError unless PREFIX.nc / PREFIX.png can be written: the nearest existing folder above
    them is a folder in which a file can be created (probed, then removed: read-only mounts and
    permissions alike); checked before anything is computed."""
    import tempfile

    folder = prefix.absolute().parent
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir():
        raise OSError(f"{folder} is a file, not a folder")
    for ext in (".nc", ".png"):
        if prefix.with_name(prefix.name + ext).is_dir():
            raise OSError(f"{prefix}{ext} is a folder")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise OSError(f"no file can be created in {folder} ({exc.strerror or exc})") from None


def cost_guard(kind: str | None, params: Params, allow_expensive: bool, numeric: bool = True,
               steps: float | None = None, reduce: str = "--n, --cycles or the scanned values",
               evaluations: float = 0.0,
               reduce_analytic: str = "--n, --n-points, --n-gamma/--n-xi or the Omega range") -> None:
    """The pipeline's cost guard (safebasins.pipeline.cost, the config schema's default budgets)
    for one command: a usage error naming --allow-expensive above a budget.  ``steps``: the
    trajectory-steps (in quartic steps) counted by a command that has no pipeline kind (``kind``
    is then unused), and ``evaluations`` its slow-flow evaluations; ``reduce``,
    ``reduce_analytic``: the options the messages suggest reducing."""
    from safebasins.pipeline.cost import ANALYTIC_RATE, RATE_PER_CORE, budgets, params_cost

    if allow_expensive:
        return
    if steps is None:
        if kind is None:
            raise ValueError("cost_guard: give the pipeline kind of the run or its trajectory-steps")
        steps, evaluations = params_cost(kind, params, numeric)
    b = budgets()
    core_hours = steps / RATE_PER_CORE / 3600
    if core_hours > b["budget_core_hours"]:
        raise click.UsageError(
            f"this run integrates up to {steps:.2e} trajectory-steps = {core_hours:.3g} core-hours (at "
            f"{RATE_PER_CORE:.1e} steps/s per core), above the budget of {b['budget_core_hours']:g} core-hours: "
            f"reduce {reduce}, or pass --allow-expensive")
    if evaluations > b["budget_analytic_evaluations"]:
        raise click.UsageError(
            f"the analytic part of this run needs {evaluations:.2e} slow-flow evaluations (~"
            f"{evaluations / ANALYTIC_RATE / 3600:.3g} h at {ANALYTIC_RATE:.0e}/s), above the budget of "
            f"{b['budget_analytic_evaluations']:.3g}: reduce {reduce_analytic}, or pass --allow-expensive")


# ----------------------------------------------------------------------------------------------
# options shared by several commands
# ----------------------------------------------------------------------------------------------
def forcing_options(f: Cmd) -> Cmd:
    f = click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
                     help="Forcing phase (rad): a number, pi, pi/2, -3pi/4, ...")(f)
    f = click.option("--Omega", "Omega", type=Number("Omega", POSITIVE), required=True,
                     help="Forcing frequency (> 0).")(f)
    return click.option("--F", "F", type=Number("F", NONNEG), required=True, help="Forcing amplitude (>= 0).")(f)


def grid_options(f: Cmd) -> Cmd:
    f = click.option("--n", "n", type=Fields("size"), default="200", show_default=True,
                     help="Points per axis: N, or NQxNP (q0 x p0); at least 3.")(f)
    return click.option("--grid", "grid", type=Fields("grid"), default=None,
                        help="IC window q0min,q0max,p0min,p0max (endpoints included) [default: the whole well, "
                             "Well.ic_window(): -1,1,-0.75,0.75 for the quartic].")(f)


def damping_option(multiple: bool = False) -> Callable[[Cmd], Cmd]:
    """``--damping`` beta >= 0 of q'' + beta q' + V'(q) = F sin(Omega t + Psi) (0: the paper's
    undamped equation); ``multiple``: a comma list or repeated, one F_cr curve each."""
    text = ("Linear damping beta >= 0 of q'' + beta q' + V'(q) = F sin(Omega t + Psi) (0: the undamped "
            "equation; beta > 0: the damped slow flow and numerics, docs/damping.md)")
    if multiple:
        return click.option("--damping", "damping", type=NumberList("damping", NONNEG), multiple=True,
                            callback=joined(unique=False),
                            help=text + ". A list makes one curve per value, each > 0 [default: 0].")
    return click.option("--damping", "damping", type=Number("damping", NONNEG), default="0", show_default=True,
                        help=text + ".")


def well_option(f: Cmd) -> Cmd:
    return click.option(
        "--well", "well", default="quartic", show_default=True, is_eager=True, callback=well_callback,
        metavar="WELL",
        help="The potential well, as in the config's `well:`: a name (quartic, cubic, pendulum, sech2, morse), "
             "polynomial:c0,c1,c2,... (V = sum c_k q^k), expression:'<formula in q>' (e.g. expression:'1 - cos(q)'), "
             "or a mapping {expression: '...'} (a mapping may add tol: 1e-11, the accuracy of the well's "
             "action-angle tables, for a formula whose rounding does not reach the default 1e-13).")(f)


def no_fourier(fourier: str | None) -> None:
    """A command whose numbers do not use the first harmonic G(xi) (numerics only) refuses
    --fourier rather than ignoring it."""
    if fourier is not None:
        raise click.BadParameter("this command integrates the equation of motion only; the first harmonic "
                                 "is not used", param_hint="'--fourier'")


def common_options(f: Cmd) -> Cmd:
    f = click.option("--allow-expensive", "allow_expensive", is_flag=True,
                     help="Run even above the pipeline's default cost budgets (config keys "
                          "numerics.budget_core_hours, numerics.budget_analytic_evaluations).")(f)
    f = click.option("--verbose", "-v", is_flag=True, help="Log lines of the pipeline build functions on stderr.")(f)
    f = click.option("--quiet", "-q", is_flag=True, help="No progress bar on stderr.")(f)
    f = click.option("--no-plot", "no_plot", is_flag=True, help="Write only the netCDF file.")(f)
    f = click.option("--fourier", type=click.Choice(FOURIER), default=None,
                     help="First harmonic G(xi) of the quartic: eq (20) as printed [default] or the exact sn "
                          "coefficient; every other well uses its exact first harmonic.")(f)
    return well_option(f)


def threads_option(f: Cmd) -> Cmd:
    """--threads: numba threads, checked by the engine."""
    return click.option("--threads", type=int, default=None, callback=checked(None, engine_check("check_threads")),
                        help="Numba threads (default: all; results do not depend on it).")(f)


def steps_option(func: str, what: str = "") -> Callable[[Cmd], Cmd]:
    """--steps-per-cycle, its default the library function ``func``'s; ``what`` ends the help's first clause."""
    return click.option("--steps-per-cycle", "steps_per_cycle", cls=Deferred, type=int,
                        default=from_library(func, "steps_per_cycle"),
                        callback=checked(None, engine_check("check_steps_per_cycle")),
                        help=f"Fixed integrator steps per forcing period{what}.")


def numerics_options(func: str, what: str) -> Callable[[Cmd], Cmd]:
    def deco(f: Cmd) -> Cmd:
        f = click.option("--backend", type=click.Choice(BACKENDS), default="cpu", show_default=True,
                         callback=backend_check,
                         help="Numerics backend: cpu (the reference), cuda (GPU, bitwise equal escapes), auto.")(f)
        f = threads_option(f)
        f = steps_option(func, " (>= 4)")(f)
        return click.option("--cycles", cls=Deferred, type=int, default=from_library(func, "cycles"),
                            callback=checked("cycles", engine_check("check_cycles", "problem")),
                            help=f"Horizon in forcing cycles (EC) {what}.")(f)
    return deco


def backend_check(ctx: click.Context, param: click.Parameter, value: str) -> str:
    """--backend cuda without a usable GPU is a usage error found before anything is computed."""
    if value == "cuda":
        from safebasins.numerics.engine import cuda_engine

        try:
            cuda_engine().require_cuda()
        except (RuntimeError, ImportError) as exc:
            raise click.BadParameter(str(exc), ctx, param) from None
    return value


def engine_check(name: str, module: str = "engine") -> Check:
    """A check of safebasins.numerics.<module> (imports numba: only when the option is used)."""
    def check(*args: Any) -> Any:
        return getattr(importlib.import_module(f"safebasins.numerics.{module}"), name)(*args)
    return check


def out_option(default: str) -> Callable[[Cmd], Cmd]:
    return click.option("--out", "-o", "out", metavar="PREFIX", default=default, show_default=True,
                        callback=out_prefix, help="Output prefix: writes PREFIX.nc and PREFIX.png (folders are "
                                                  "created).")


def grid_params(grid: dict[str, list[float]] | None, n: list[int],
                ctx: click.Context | None = None) -> dict[str, list[float] | list[int]]:
    """The resolved grid of --grid (default: the window of the command's well) and --n."""
    from safebasins.pipeline import values

    if grid is None:
        (q_lo, q_hi), (p_lo, p_hi) = current_well(ctx or click.get_current_context()).ic_window()
        grid = {"q0": [q_lo, q_hi], "p0": [p_lo, p_hi]}
    return values.grid({**grid, "n": n})
