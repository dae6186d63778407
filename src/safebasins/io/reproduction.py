"""How close two honest runs on different machines must be, and the verdict on each dataset.

Two runs of the same code and configuration on different machines are not bit for bit equal:
whatever goes through BLAS/LAPACK (OpenBLAS picks its kernel by CPU) or through numpy's own
SIMD loops (``exp``, ``log1p``, ``arccos``, ... differ between AVX2 and AVX-512 paths) differs
in its last bits.  :data:`TOLERANCES` says, variable kind by variable kind, how far two such
runs may differ; :data:`VARIABLE_KINDS` says which variables (names of docs/contracts.md) are
of which kind.  The numbers are measurements (docs/reproduction.md):

* ``slow_flow`` -- analytic values (F_cr, C, energies, fixed points, ...): relative tolerance,
  on the scale of the variable where a value is near zero;
* ``curve`` -- boundary curves (gamma, xi, q0_vertex, ...): on the scale of the variable;
* ``branch`` -- the F_cr branches (MM_0, MM_pi, SM, SMM) and their saddles: like
  ``slow_flow``, and a branch may exist in one run only where it is degenerate (F_cr agrees
  within the slow-flow tolerance: the saddle sits at xi_max, where two mechanisms give the
  same F); ``mechanism`` may change only there;
* ``numeric_threshold`` -- thresholds found by bisection on integrations: the dataset's own
  bisection width (``tol`` absolute, or ``rtol`` relative);
* ``escape_time`` / ``mask`` -- fields over the plane of initial conditions (or the manifold): a
  share of the entries may differ; an entry may change class (escaped or not, safe or not) only
  where its eight neighbours hold both classes, an escape time anywhere both runs escape;
* ``measure`` -- counts, areas, integrity measures and agreements computed from such masks:
  relative tolerance of the same share;
* ``trajectory`` -- integrated orbits (stroboscopic points, rotation numbers, the damped slow
  flow's escape time): relative tolerance, exceeded by a share of the entries at most;
* ``exact`` -- everything else (integers, flags, labels, text, dimension coordinates): equal.

Every NaN or infinity must sit at the same place in both runs (a branch excepted, as above).
Global attributes are compared by the same rules (numbers by the rule of their name's kind,
text exactly); the provenance ones (:data:`safebasins.core.provenance.PROVENANCE_ATTRS`) never count.

:func:`verify_reproduction` compares a new ``results/data`` tree with a reference (a results
archive ``.tar.gz`` of :mod:`safebasins.io.archive`, an extracted crate or a ``results`` /
``results/data`` directory) and returns one :class:`Verdict` per dataset: ``identical``,
``within tolerance`` (with the worst difference against its tolerance), ``differs`` (with the
reasons) or ``missing``.  From the shell::

    safebasins verify-reproduction results/archive/safebasins-results.tar.gz results/data
    python -m safebasins.io.reproduction REFERENCE NEW
"""
from __future__ import annotations

import math
import os
import re
import sys
import tarfile
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, cast

import numpy as np
import xarray as xr

from safebasins.io.archive import PREFIX
from safebasins.io.compare import PROVENANCE_ATTRS, dataset_differences, dataset_files, same_attr
from safebasins.io.netcdf import read
from safebasins.io.verify import check_archive

__all__ = ["Tolerance", "TOLERANCES", "VARIABLE_KINDS", "Difference", "Verdict", "ReproductionReport",
           "variable_kind", "dataset_verdict", "verify_reproduction", "reference_tree", "ReproductionInputError"]

IDENTICAL, WITHIN, DIFFERS, MISSING, EXTRA = "identical", "within tolerance", "differs", "missing", "extra"


@dataclass(frozen=True)
class Tolerance:
    """How far one kind of variable of two honest runs may differ.

    Values: ``|a - b| <= rtol * max(|a|, |b|, floor * S, atol / rtol)``, S the largest finite
    magnitude of the variable in the reference (at least pi for an angle): relative where a value
    is large, on the variable's scale where it is near zero, never finer than ``atol`` (every
    variable is dimensionless and of order one).  ``fraction``: the share of the entries that may
    break that (masks and escape times: may differ at all), ``boundary``: only where the entry's
    neighbours hold both classes.  ``branch``: a NaN may appear or vanish where the dataset's
    ``F_cr`` agrees (a degenerate branch).  ``bisection``: the tolerance is the dataset's own
    bisection width, its attribute ``tol`` (absolute) or ``rtol`` (relative)."""

    rtol: float = 0.0
    floor: float = 0.0
    atol: float = 0.0
    fraction: float = 0.0
    boundary: bool = False
    branch: bool = False
    bisection: bool = False
    meaning: str = ""
    basis: str = ""


#: variable kind -> its tolerance (docs/reproduction.md gives the measurements behind each)
TOLERANCES: dict[str, Tolerance] = {
    "slow_flow": Tolerance(
        rtol=1e-8, floor=1e-6, atol=1e-13,
        meaning="analytic values: F_cr and its inputs, C, saddle and attractor energies, closed-form integrity "
                "measures, fixed points of the stroboscopic map",
        basis="largest difference 3.0e-10 relative (the centre's trace of the stroboscopic map; F values "
              "1.3e-12): the wells' Chebyshev tables are least-squares fits, so their last bits follow the "
              "OpenBLAS kernel"),
    "curve": Tolerance(
        rtol=1e-8, floor=1.0, atol=1e-13,
        meaning="boundary curves (gamma, xi, q0_vertex, p0_vertex, boundary_q0, boundary_p0, chain_q, chain_p), "
                "on the scale of the variable",
        basis="largest difference 1.2e-10 of the variable's scale: arccos amplifies the tables' last bits next "
              "to a curve's end on a ray"),
    "branch": Tolerance(
        rtol=1e-8, floor=1e-6, atol=1e-13, branch=True,
        meaning="F_cr branches (F_MM_0, F_MM_pi, F_SM, F_SMM), their saddles, the mechanism flag",
        basis="largest difference 2.1e-12 relative; a branch may exist in one run only where its F agrees with "
              "the other run's F_cr (a saddle on xi_max, where two mechanisms give the same F)"),
    "numeric_threshold": Tolerance(
        bisection=True,
        meaning="thresholds bisected on integrations: numeric F_cr with its bracket and scan (the dataset's "
                "absolute `tol`), the damped slow flow's F_cr and F_settle (its relative `rtol`)",
        basis="identical across kernels and with the initial condition one ulp away; a trajectory on the knife "
              "edge could move a bisection decision, by the bisection's final width"),
    "escape_time": Tolerance(
        fraction=0.05, boundary=True,
        meaning="escape times over initial conditions (inf: no escape within the horizon)",
        basis="identical across kernels (the engine is bitwise the same on every x86-64 CPU for arithmetic "
              "wells); with F one ulp larger up to 1.0% of the escape times move (Fig 20's displacement "
              "criterion, 11000 cycles), 0.22% change class, each next to a pixel of the other class"),
    "mask": Tolerance(
        fraction=0.02, boundary=True,
        meaning="masks over initial conditions or the manifold (escapes, safe, true_safe, region labels)",
        basis="identical across kernels; a numeric mask changes as its escape times' classes (0.22% with F "
              "one ulp larger), an analytic one only where C is within ~1e-12 of a boundary level"),
    "measure": Tolerance(
        rtol=0.02, floor=1e-3, atol=1e-13,
        meaning="measures of masks: safe counts and areas, GIM/LIM/IF, IoU, pixel agreement, fractality",
        basis="identical across kernels; a change of the masks' share of pixels changes them by as much"),
    "trajectory": Tolerance(
        rtol=1e-6, floor=1e-6, atol=1e-13, fraction=0.02,
        meaning="integrated orbits: stroboscopic q, p, rotation numbers, Birkhoff digits; the damped slow "
                "flow's escape time; the vertices of a saddle's manifolds grown by integration",
        basis="largest difference 6.0e-9 relative (t_escape of the damped slow flow, an adaptive integration "
              "at F_cr; manifold vertices 6.5e-7 under OpenBLAS Haswell, grown from a saddle whose Newton "
              "solve follows the kernel's last bits); an orbit of the chaotic sea started one ulp away "
              "separates, hence a share"),
    "exact": Tolerance(meaning="integers, flags, labels, text, dimension coordinates",
                       basis="no decision on the last bits makes them"),
}

_MEASURES = ("safe_(numeric|analytic|fraction)|A_E|A_q|rel_diff|(mean_)?iou(_mean|_min)?"
             "|pixel_agreement(_mean|_min)?|(GIM|LIM|IF)(_(?!closed)\\w+)?|F_(GIM|LIM|IF)(_true)?|area(_\\w+)?"
             "|r_(global|local)(_\\w+)?|if_[qp]0(_\\w+)?|region_(size|numeric_safe)|fraction(_err)?|n_uncertain"
             "|alpha(_err)?|boundary_dimension|xi_true|xi_inscribed_true")

#: (kind, names as a regular expression over the whole name, global attributes one of which the
#: dataset must carry), tried in order; a float no row names is ``slow_flow``, anything else ``exact``
VARIABLE_KINDS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("escape_time", r"escape_cycle(_\w+)?", ()),
    ("mask", r"escapes(_rm)?|safe|true_safe(_continuous)?|region", ()),
    ("measure", _MEASURES, ()),
    ("numeric_threshold", r"F_cr(_low|_high)?|F_escape_(low|all)|F_settle", ("tol", "rtol")),
    ("branch", r"F_(MM_0|MM_pi|SM|SMM)|xi_saddle(_smm)?|gamma_saddle|mechanism", ()),
    # vertices of manifolds grown by integration (a dataset recording its manifold_rtol): orbits
    ("trajectory", r"[qp]0_vertex", ("manifold_rtol",)),
    ("curve", r"gamma|xi|[qp]0_vertex|boundary_[qp]0|chain_[qp]", ()),
    ("trajectory", r"q|p|rotation_number|birkhoff_digits|t_escape", ()),
)


def variable_kind(name: str, values: np.ndarray, attrs: dict | None = None, *, dimension: bool = False) -> str:
    """The kind (a key of :data:`TOLERANCES`) of a variable or attribute ``name`` holding
    ``values`` in a dataset with global attributes ``attrs``."""
    if dimension:
        return "exact"
    kind = np.asarray(values).dtype.kind
    for k, pattern, needs in VARIABLE_KINDS:
        if re.fullmatch(pattern, name) and (not needs or any(n in (attrs or {}) for n in needs)):
            tol = TOLERANCES[k]
            return k if kind in "fc" or tol.boundary or tol.branch else "exact"
    return "slow_flow" if kind in "fc" else "exact"


@dataclass
class Difference:
    """The worst difference of one variable within its tolerance: ``ratio`` = difference / tolerance."""

    variable: str
    kind: str
    amount: float
    tolerance: float
    what: str            # how ``amount`` is measured ("relative", "of pixels", "absolute")

    @property
    def ratio(self) -> float:
        return self.amount / self.tolerance if self.tolerance > 0 else (0.0 if self.amount == 0 else math.inf)

    def __str__(self) -> str:
        if self.what == "of entries":
            return (f"{self.variable}: {self.amount:.2%} of entries differ (tolerance {self.tolerance:.0%}, "
                    f"{self.kind})")
        return f"{self.variable}: {self.amount:.2g} {self.what} (tolerance {self.tolerance:.2g}, {self.kind})"


@dataclass
class Verdict:
    """The verdict on one dataset: ``status`` (identical, within tolerance, differs, missing, extra),
    the worst difference within tolerance and the reasons it differs."""

    dataset: str
    status: str
    worst: Difference | None = None
    problems: list[str] = field(default_factory=list)

    def lines(self) -> list[str]:
        if self.status == IDENTICAL:
            return [f"identical         {self.dataset}"]
        if self.status == WITHIN:
            worst = f"worst: {self.worst}" if self.worst else "(differences of storage only)"
            return [f"within tolerance  {self.dataset}  {worst}"]
        if self.status == MISSING:
            return [f"MISSING           {self.dataset} (in the reference, not in the new run)"]
        if self.status == EXTRA:
            return [f"extra             {self.dataset} (in the new run only)"]
        return [f"DIFFERS           {self.dataset}"] + [f"    {p}" for p in self.problems]


class _Check:
    """Collects the worst in-tolerance difference and the problems of one dataset."""

    def __init__(self) -> None:
        self.worst: Difference | None = None
        self.problems: list[str] = []

    def within(self, d: Difference) -> None:
        if self.worst is None or d.ratio > self.worst.ratio:
            self.worst = d

    def fail(self, text: str) -> None:
        self.problems.append(text)


def _scale(a: np.ndarray, units: str | None) -> float:
    fin = np.abs(a[np.isfinite(a)])
    s = float(fin.max()) if fin.size else 0.0
    return max(s, math.pi) if units == "rad" else s


def _mixed_neighbourhood(cls: np.ndarray) -> np.ndarray:
    """Entries of a field (classes over its last two dims) whose 8 neighbours, the entry itself
    left out, hold more than one class: a boundary passes there whatever the entry's own class."""
    c = cls.astype(float)
    pad = [(0, 0)] * (c.ndim - 2) + [(1, 1), (1, 1)]
    s = np.pad(c, pad, constant_values=np.nan)
    n0, n1 = c.shape[-2:]
    shifted = np.stack([s[..., di:di + n0, dj:dj + n1] for di in (0, 1, 2) for dj in (0, 1, 2)
                        if (di, dj) != (1, 1)])
    with np.errstate(invalid="ignore"):
        return np.nanmin(shifted, axis=0) != np.nanmax(shifted, axis=0)


def _check_field(name: str, kind: Any, tol: Tolerance, a: Any, b: Any, chk: _Check) -> None:
    """Masks and escape times: equal but for a share of the entries; an entry may change class
    (escaped or not, safe or not, region label) only on a boundary (:func:`_mixed_neighbourhood`
    in either run), an escape time anywhere both runs escape."""
    if a.dtype.kind in "fc":
        same = (a == b) | (np.isnan(a) & np.isnan(b))
        cls_a, cls_b = np.isfinite(a), np.isfinite(b)     # escape times: escaped, or not (inf)
    else:
        same = a == b
        cls_a, cls_b = a, b
    n_diff = int(np.count_nonzero(~same))
    if n_diff == 0:
        return
    flips = cls_a != cls_b
    if flips.any() and a.ndim < 2:
        chk.fail(f"{name}: {int(flips.sum())} of {a.size} entries change class ({kind}: exact without a grid)")
        return
    if flips.any():
        off = int(np.count_nonzero(flips & ~(_mixed_neighbourhood(cls_a) | _mixed_neighbourhood(cls_b))))
        if off:
            chk.fail(f"{name}: {off} entries change class away from any boundary ({kind} may change only where "
                     "its neighbours hold both classes)")
            return
    share = n_diff / a.size
    if share > tol.fraction:
        chk.fail(f"{name}: {n_diff} of {a.size} entries ({share:.2%}) differ, more than the tolerated "
                 f"{tol.fraction:.2%} ({kind})")
        return
    chk.within(Difference(name, kind, share, tol.fraction, "of entries"))


def _check_values(name: str, kind: Any, tol: Tolerance, a: Any, b: Any, units: Any, chk: _Check, *,
                  absolute: float | None = None, allowed: np.ndarray | None = None) -> None:
    """Continuous values: the same NaN/inf pattern (but at ``allowed`` entries) and finite values within
    tolerance (``absolute``: an absolute tolerance instead of the relative one)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    nan_a, nan_b = np.isnan(a), np.isnan(b)
    pattern = (nan_a != nan_b) | (np.isinf(a) != np.isinf(b)) | (np.isinf(a) & np.isinf(b) & (a != b))
    if allowed is not None:
        pattern &= ~allowed
    if pattern.any():
        i = tuple(int(x) for x in np.argwhere(pattern)[0])
        chk.fail(f"{name}: NaN/inf at {int(pattern.sum())} other place(s) (first at index {i}: "
                 f"{a[i]!r} vs {b[i]!r})")
        return
    fin = np.isfinite(a) & np.isfinite(b)
    if not fin.any():
        return
    diff = np.abs(a[fin] - b[fin])
    if absolute is not None:
        bound, amount, what = np.full(diff.shape, absolute), diff, "absolute"
        limit = absolute
    else:
        mag = np.maximum(np.maximum(np.abs(a[fin]), np.abs(b[fin])),
                         max(tol.floor * _scale(a, units), tol.atol / tol.rtol))
        amount, bound, what, limit = diff / mag, np.full(diff.shape, tol.rtol), "relative", tol.rtol
    bad = amount > bound
    if tol.fraction > 0:
        share = bad.sum() / a.size
        if share > tol.fraction:
            chk.fail(f"{name}: {int(bad.sum())} of {a.size} values ({share:.2%}) beyond {what} {limit:.2g} "
                     f"({kind}, a share of {tol.fraction:.2%} may)")
            return
        amount = amount[~bad]
    elif bad.any():
        k = int(np.argmax(amount))
        chk.fail(f"{name}: {what} difference {amount[k]:.3g} > tolerance {limit:.2g} ({kind}; "
                 f"{int(bad.sum())} of {a.size} values)")
        return
    worst = float(amount.max()) if amount.size else 0.0
    if worst > 0:
        chk.within(Difference(name, kind, worst, limit, what))


def _degenerate(old: xr.Dataset, new: xr.Dataset, da: xr.DataArray) -> np.ndarray | None:
    """Entries of a branch variable ``da`` where the datasets' F_cr agree within the slow-flow
    tolerance (finite in both, or NaN in both): there a branch may be found in one run only."""
    if "F_cr" not in old or "F_cr" not in new or not set(old["F_cr"].dims) <= set(da.dims):
        return None
    tol = TOLERANCES["slow_flow"]
    fa = old["F_cr"].broadcast_like(da).transpose(*da.dims).values
    fb = new["F_cr"].broadcast_like(da).transpose(*da.dims).values
    mag = np.maximum(np.maximum(np.abs(fa), np.abs(fb)), max(tol.floor * _scale(old["F_cr"].values, None),
                                                             tol.atol / tol.rtol))
    with np.errstate(invalid="ignore"):
        close = np.abs(fa - fb) <= tol.rtol * mag
    return close | (np.isnan(fa) & np.isnan(fb))


def _compare_variable(name: str, old: xr.Dataset, new: xr.Dataset, chk: _Check) -> None:
    a_da, b_da = old[name], new[name]
    if a_da.dims != b_da.dims or a_da.shape != b_da.shape:
        chk.fail(f"{name}: dims {dict(a_da.sizes)} vs {dict(b_da.sizes)}")
        return
    a, b = np.asarray(a_da.values), np.asarray(b_da.values)
    if a.dtype.kind in "OUS" or b.dtype.kind in "OUS":
        if not np.array_equal(a.astype(str), b.astype(str)):
            chk.fail(f"{name}: {int(np.count_nonzero(a.astype(str) != b.astype(str)))} of {a.size} labels differ")
        return
    if (a.dtype.kind in "fc") != (b.dtype.kind in "fc"):
        chk.fail(f"{name}: dtype {a.dtype} vs {b.dtype}")
        return
    kind = variable_kind(name, a, old.attrs, dimension=name in old.dims)
    tol = TOLERANCES[kind]
    units = a_da.attrs.get("units")
    if tol.boundary:
        _check_field(name, kind, tol, a, b, chk)
    elif tol.bisection:
        if "tol" in old.attrs:
            _check_values(name, kind, tol, a, b, units, chk, absolute=float(old.attrs["tol"]))
        else:
            _check_values(name, kind, Tolerance(rtol=float(old.attrs["rtol"])), a, b, units, chk)
    elif tol.branch:
        allowed = _degenerate(old, new, a_da)
        if a.dtype.kind not in "fc":                       # the mechanism flag
            changed = a != b
            if allowed is not None:
                changed &= ~allowed
            if changed.any():
                chk.fail(f"{name}: {int(changed.sum())} of {a.size} values differ where F_cr differs too")
            return
        _check_values(name, kind, tol, a, b, units, chk, allowed=allowed)
    elif tol.rtol == 0 or a.dtype.kind not in "fc":
        if a.dtype.kind in "fc":
            ne = ~((a == b) | (np.isnan(a) & np.isnan(b)))
        else:
            ne = a != b
        if ne.any():
            chk.fail(f"{name}: {int(ne.sum())} of {a.size} values differ (exact: {TOLERANCES['exact'].meaning})")
    else:
        _check_values(name, kind, tol, a, b, units, chk)


def _compare_attrs(where: str, a: dict, b: dict, ds_attrs: dict, chk: _Check, ignore: Any = ()) -> None:
    for k in sorted(set(a) | set(b)):
        if k in ignore:
            continue
        label = k if where == "<global>" else f"{where}.{k}"
        if k not in a or k not in b:
            chk.fail(f"attribute {label!r} only in {'new' if k in b else 'reference'}")
            continue
        x, y = a[k], b[k]
        if same_attr(x, y):
            continue
        xa, ya = np.asarray(x), np.asarray(y)
        if xa.dtype.kind in "fc" and ya.dtype.kind in "fc" and xa.shape == ya.shape:
            kind = variable_kind(k, xa, ds_attrs)
            kind = kind if kind in ("slow_flow", "measure", "trajectory", "branch") else "slow_flow"
            _check_values(f"attribute {label}", kind, TOLERANCES[kind], xa, ya, None, chk)
        else:
            chk.fail(f"attribute {label!r} differs: {x!r} vs {y!r}")


def dataset_verdict(old: xr.Dataset, new: xr.Dataset, name: str = "<dataset>") -> Verdict:
    """The verdict on ``new`` as a reproduction of ``old`` (see the module docstring)."""
    if not dataset_differences(old, new):
        return Verdict(name, IDENTICAL)
    chk = _Check()
    va, vb = set(map(str, old.variables)), set(map(str, new.variables))
    for n in sorted(va - vb):
        chk.fail(f"variable {n!r} only in the reference")
    for n in sorted(vb - va):
        chk.fail(f"variable {n!r} only in the new run")
    for n in sorted(va & vb):
        if (n in old.coords) != (n in new.coords):
            chk.fail(f"{n}: a coordinate in one run, a data variable in the other")
        _compare_variable(n, old, new, chk)
        _compare_attrs(n, dict(old[n].attrs), dict(new[n].attrs), old.attrs, chk)
    _compare_attrs("<global>", dict(old.attrs), dict(new.attrs), old.attrs, chk, ignore=PROVENANCE_ATTRS)
    if chk.problems:
        return Verdict(name, DIFFERS, chk.worst, chk.problems)
    return Verdict(name, WITHIN, chk.worst)


@dataclass
class ReproductionReport:
    """Verdicts of every dataset of two trees, and problems of the reference archive."""

    verdicts: list[Verdict] = field(default_factory=list)
    archive_problems: list[str] = field(default_factory=list)

    def count(self, status: str) -> int:
        return sum(v.status == status for v in self.verdicts)

    @property
    def reproduced(self) -> bool:
        """True when nothing differs, nothing is missing and the reference archive is intact."""
        return not self.archive_problems and not any(v.status in (DIFFERS, MISSING) for v in self.verdicts)

    def lines(self) -> Iterator[str]:
        for p in self.archive_problems:
            yield f"REFERENCE ARCHIVE: {p}"
        for v in self.verdicts:
            yield from v.lines()
        yield (f"{len(self.verdicts) - self.count(EXTRA)} datasets: {self.count(IDENTICAL)} identical, "
               f"{self.count(WITHIN)} within tolerance, {self.count(DIFFERS)} differ, {self.count(MISSING)} missing"
               + (f", {self.count(EXTRA)} extra" if self.count(EXTRA) else "")
               + (" -> REPRODUCED" if self.reproduced else " -> NOT REPRODUCED"))


class ReproductionInputError(ValueError):
    """A reference or new-run path that cannot be read as results (the message names the argument)."""


def _data_root(path: Path, argument: str) -> Path:
    """``results/data`` of a directory: ``path/data`` when there is one, else ``path``."""
    root = path / "data" if (path / "data").is_dir() else path
    if not dataset_files(root, parts=False):
        raise ReproductionInputError(f"{argument} {os.fspath(path)}: no netCDF datasets (*.nc) below it; give a "
                                     "results archive (.tar.gz), a results/ or results/data/ directory")
    return root


@contextmanager
def reference_tree(path: Any, argument: str = "REFERENCE") -> Iterator[tuple[Path, list[str]]]:
    """``(data root, archive problems)`` of a reference: an archive ``.tar.gz`` (its datasets
    extracted to a temporary directory, removed afterwards), an extracted crate or a results
    directory.  A missing path or a file that is no results archive raises
    :class:`ReproductionInputError` naming ``argument``."""
    path = Path(path)
    if not path.exists():
        raise ReproductionInputError(f"{argument} {os.fspath(path)} does not exist")
    if path.is_dir():
        problems = check_archive(path) if (path / "MANIFEST.sha256").exists() else []
        yield _data_root(path, argument), problems
        return
    try:
        tar = tarfile.open(path)
    except (tarfile.TarError, OSError):
        raise ReproductionInputError(f"{argument} {os.fspath(path)} is not a results archive (a .tar.gz "
                                     "written by the pipeline's archive rule) nor a directory") from None
    with tar, tempfile.TemporaryDirectory(prefix="safebasins-reference-") as tmp:
        members = [m for m in tar.getmembers()
                   if m.isfile() and m.name.startswith(f"{PREFIX}/data/") and m.name.endswith(".nc")]
        if not members:
            raise ReproductionInputError(f"{argument} {os.fspath(path)} holds no datasets under {PREFIX}/data/: "
                                         "not a results archive")
        root = Path(tmp) / "data"
        for m in members:
            target = root / m.name[len(f"{PREFIX}/data/"):]
            if ".." in Path(m.name).parts:
                raise ReproductionInputError(f"{argument} {os.fspath(path)}: member {m.name!r} leaves the archive")
            target.parent.mkdir(parents=True, exist_ok=True)
            with cast(IO[bytes], tar.extractfile(m)) as src, open(target, "wb") as dst:
                dst.write(src.read())
        yield root, check_archive(path)


def verify_reproduction(reference: Any, new: Any, *, parts: bool = False) -> ReproductionReport:
    """Verdict on every dataset of ``new`` (a ``results`` or ``results/data`` directory) against
    ``reference`` (an archive, an extracted crate or a results directory)."""
    new = Path(new)
    if not new.exists():
        raise ReproductionInputError(f"NEW_DIR {os.fspath(new)} does not exist")
    if not new.is_dir():
        raise ReproductionInputError(f"NEW_DIR {os.fspath(new)} is not a directory (give results/ or results/data/)")
    new_root = _data_root(new, "NEW_DIR")
    with reference_tree(reference) as (ref_root, problems):
        a, b = set(dataset_files(ref_root, parts)), set(dataset_files(new_root, parts))
        report = ReproductionReport(archive_problems=problems)
        for f in sorted(a | b):
            if f not in b:
                report.verdicts.append(Verdict(f, MISSING))
            elif f not in a:
                report.verdicts.append(Verdict(f, EXTRA))
            else:
                report.verdicts.append(dataset_verdict(read(ref_root / f), read(new_root / f), f))
    return report


def main(argv: Any = None) -> int:
    """``python -m safebasins.io.reproduction REFERENCE NEW``: 0 when reproduced, 1 when not, 2 on bad input."""
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2 or argv[0] in ("-h", "--help"):
        print("usage: python -m safebasins.io.reproduction REFERENCE NEW\n"
              "  REFERENCE: results archive (.tar.gz), extracted crate, results/ or results/data/\n"
              "  NEW: results/ or results/data/ of the run to check")
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    try:
        report = verify_reproduction(*argv)
    except ReproductionInputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for line in report.lines():
        print(line)
    return 0 if report.reproduced else 1


if __name__ == "__main__":
    sys.exit(main())
