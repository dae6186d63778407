"""The well of a compiled ensemble: which kernel path integrates it, its escape criteria, and
the checks of thresholds against it.

Supported wells (``well=`` of the numerics API):

* ``None`` or a :class:`~safebasins.wells.quartic.QuarticWell` (``QUARTIC``, the default):
  the paper's ``V = q^2/2 - q^4/4`` in closed form (kernel flag ``steps.QUARTIC``, or
  ``QUARTIC_SIGNED`` when asymmetric displacement bounds are requested);
* a polynomial well: any well object with ``coefficients`` ``c_0 .. c_n`` (``V = sum c_k q^k``,
  ``c_0 = c_1 = 0``, ``n <= 8``; e.g. :class:`~safebasins.wells.polynomial.PolynomialWell`) and
  ``barriers``, ``barrier_energy`` (kernel flag ``steps.POLY4`` for ``n <= 4``, ``POLY8`` for
  ``n <= 8``: Horner with run-time coefficients, one compiled kernel per class).

Other wells (a :class:`~safebasins.wells.numeric.NumericWell` from Python callables) have no
compiled force: ValueError naming ``well``.

Escape criteria (wells.base): energy ``H0 = p^2/2 + V(q) > xi_max`` or ``q`` beyond a barrier
(``q > q_right`` or ``q < q_left``; a side without barrier, ``+-inf``, never escapes that
way); displacement ``|q| > q_max`` (symmetric, ``q_max``) or ``q < lo`` or ``q > hi``
(a bound pair ``(lo, hi)`` of ``q_bounds``, e.g. the turning points
``well.turning_points(xi_max)``: :func:`displacement_bounds`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from safebasins.checks import as_array, value_repr
from safebasins.numerics import steps
from safebasins.wells.quartic import QUARTIC, QuarticWell

__all__ = ["EngineWell", "resolve_well", "displacement_bounds"]


@dataclass(frozen=True)
class EngineWell:
    """A well as the compiled engine sees it (see the module docstring)."""

    well: object
    name: str
    closed_form: bool                   # the quartic's closed-form kernel path
    poly_class: int | None              # steps.POLY4 / POLY8 for a polynomial well
    coefficients: tuple | None          # c_0 .. c_n (polynomial wells)
    barriers: tuple                     # (q_left, q_right), +-inf where there is none
    barrier_energy: float
    wpar: np.ndarray                    # steps.well_parameters

    # ---------------------------------------------------------------- kernel flag
    def flag(self, signed):
        """The kernel flag: QUARTIC (|q| maxima) unless `signed` bounds are needed, or the
        polynomial class."""
        if self.closed_form:
            return steps.QUARTIC_SIGNED if signed else steps.QUARTIC
        return self.poly_class

    # ---------------------------------------------------------------- checks
    def check_xi_max(self, name, xi_max):
        """Energy thresholds in (0, barrier_energy]."""
        if self.closed_form:
            return self.well.check_threshold(name, xi_max)
        a = as_array(name, xi_max)
        if ((a <= 0) | (a > self.barrier_energy)).any():
            raise ValueError(f"{name} must lie in (0, {self.barrier_energy!r}] (up to the barrier energy of the "
                             f"well {self.name!r}), got {value_repr(a)}")
        return a

    def check_q_max(self, name, q_max):
        """Symmetric displacement thresholds |q| > q_max with q_max in (0, nearest barrier]."""
        if self.closed_form:
            return self.well.check_displacement(name, q_max)
        a = as_array(name, q_max)
        lim = min(-self.barriers[0], self.barriers[1])
        if ((a <= 0) | (a > lim)).any():
            raise ValueError(f"{name} must lie in (0, {lim!r}] (|q| > q_max beyond a barrier of the well "
                             f"{self.name!r} at {self.barriers}), got {value_repr(a)}")
        return a

    def check_q_bounds(self, name, q_bounds):
        """Displacement bound pairs (lo, hi) as an (n, 2) float array: lo < 0 < hi, inside the
        barriers (q_left <= lo, hi <= q_right; +-inf only on a side without barrier).  A
        single pair may be given as (lo, hi)."""
        a = as_array(name, q_bounds)
        if a.size == 0:
            return np.zeros((0, 2))
        if a.ndim == 1:
            a = a[None, :]
        if a.ndim != 2 or a.shape[1] != 2:
            raise ValueError(f"{name} must be pairs (lo, hi): shape (n, 2) or (2,), got shape {a.shape}")
        lo, hi = a[:, 0], a[:, 1]
        if not ((lo < 0) & (hi > 0)).all():
            raise ValueError(f"{name} must satisfy lo < 0 < hi (the well bottom q = 0 inside), got {a.tolist()}")
        ql, qr = self.barriers
        if (lo < ql).any() or (hi > qr).any():
            raise ValueError(f"{name} must lie inside the barriers of the well {self.name!r}, "
                             f"{ql!r} <= lo and hi <= {qr!r}; got {a.tolist()}")
        return a

    # ---------------------------------------------------------------- descriptions
    def potential(self):
        if self.closed_form:
            return "q^2/2 - q^4/4"
        terms = [f"{'-' if c < 0 else '+'} {abs(c)!r} q^{k}" for k, c in enumerate(self.coefficients) if c != 0.0]
        return " ".join(terms).removeprefix("+ ")

    def barrier_text(self):
        ql, qr = self.barriers
        if self.closed_form:
            return "|q| > 1"
        parts = []
        if np.isfinite(ql):
            parts.append(f"q < {ql!r}")
        if np.isfinite(qr):
            parts.append(f"q > {qr!r}")
        return " or ".join(parts)

    def energy_criterion(self):
        """The energy criterion in words, naming the well."""
        return (f"well {self.name!r}, V(q) = {self.potential()}: H0 = p^2/2 + V(q) > xi_max or "
                f"{self.barrier_text()} (beyond a barrier)")

    def attrs(self):
        """Dataset attributes naming the well."""
        out = {"well": self.name, "well_potential": self.potential(),
               "well_barriers": np.array(self.barriers, dtype=float),
               "well_barrier_energy": float(self.barrier_energy)}
        if self.coefficients is not None:
            out["well_coefficients"] = np.array(self.coefficients, dtype=float)
        return out


def resolve_well(well=None):
    """The :class:`EngineWell` of ``well`` (None: the paper's quartic); ValueError naming
    ``well`` for a well the compiled engine cannot integrate."""
    if well is None:
        well = QUARTIC
    if isinstance(well, QuarticWell):
        return EngineWell(well, well.name, True, None, None, (-1.0, 1.0), float(well.barrier_energy),
                          steps.well_parameters()[1])
    coefficients = getattr(well, "coefficients", None)
    if coefficients is None:
        raise ValueError(f"well must be the quartic (a QuarticWell, or None) or a polynomial well with "
                         f"`coefficients` (e.g. safebasins.wells.polynomial.PolynomialWell): the compiled engine "
                         f"has no force for {type(well).__name__} {getattr(well, 'name', '')!r}")
    try:
        c = np.trim_zeros(np.asarray(coefficients, dtype=float), "b")
        barriers = tuple(float(b) for b in well.barriers)
        Eb = float(well.barrier_energy)
    except (TypeError, ValueError, AttributeError) as exc:
        raise ValueError(f"well: a polynomial well needs numeric coefficients, barriers and barrier_energy "
                         f"({exc})") from exc
    if c.ndim != 1 or c.size < 3 or not np.isfinite(c).all() or c[0] != 0 or c[1] != 0 or not c[2] > 0:
        raise ValueError(f"well: coefficients must be finite c_0 = 0, c_1 = 0, c_2 > 0, ..., got {coefficients!r}")
    if len(barriers) != 2 or not (barriers[0] < 0 < barriers[1]) or np.isnan(barriers).any():
        raise ValueError(f"well: barriers must be (q_left < 0 < q_right), got {barriers!r}")
    if not (np.isfinite(Eb) and Eb > 0):
        raise ValueError(f"well: barrier_energy must be finite and > 0, got {Eb!r}")
    dc = np.arange(1, c.size) * c[1:]
    for b in barriers:            # a barrier is a maximum of V: V'(q_b) = 0
        if np.isfinite(b):
            scale = np.sum(np.abs(dc) * np.abs(b) ** np.arange(dc.size))
            if abs(np.polynomial.polynomial.polyval(b, dc)) > 1e-9 * scale:
                raise ValueError(f"well: the barrier q = {b!r} is not a root of V' of the coefficients {c.tolist()}")
    try:
        cls, wpar = steps.well_parameters(barriers, c)
    except ValueError as exc:
        raise ValueError(f"well: {exc}") from exc
    return EngineWell(well, str(getattr(well, "name", "polynomial")), False, cls, tuple(c.tolist()), barriers, Eb,
                      wpar)


def displacement_bounds(xi_max, well=None):
    """Displacement bound pairs from energy levels: ``(q_minus(xi), q_plus(xi))``, the turning
    points of the unforced orbit of energy xi (``well.turning_points``; eq (4) for the quartic,
    where they are ``-+q_max(xi)``), as an (n, 2) array for ``q_bounds``."""
    ew = resolve_well(well)
    xi = np.atleast_1d(ew.check_xi_max("xi_max", xi_max)).astype(float).ravel()
    lo, hi = ew.well.turning_points(xi)
    return np.stack([np.asarray(lo, float).ravel(), np.asarray(hi, float).ravel()], axis=-1)
