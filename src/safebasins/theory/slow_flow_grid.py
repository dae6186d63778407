"""Slow-flow escape classification of one IC grid, for one or many control points.

:func:`safebasins.theory.slow_flow_escapes` is :class:`GridSlowFlow` for one control point.
The analytic integrity map and erosion profiles classify one grid for many control points
``(F, Omega)``: the quantities that depend on the grid and the threshold only (the angle-energy
variables of the ICs, ``J``, ``A`` and ``delta`` at their energies, and ``omega``, ``A'``, ``J``,
``A`` on the xi grid of the slow-flow profile) are then evaluated once (``reuse=True``), and per
control point only what depends on ``(F, Omega)``: the critical points of the profile (Brent's
method), the suffix extrema and the comparisons (:func:`~safebasins.theory.profile.level_escapes`).

Reuse changes no number: the shared quantities are the same functions evaluated on the same
arrays (or on array slices of them: the well functions are elementwise on arrays, which
``tests/theory/test_slow_flow_grid.py`` checks against the points classified one by one).
:meth:`GridSlowFlow.xi_true` is
:func:`safebasins.analysis.phase_invariant.xi_true_analytic` on the shared tables.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from safebasins.core import checks
from safebasins.theory.profile import SlowFlowProfile, level_escapes, xi_grid
from safebasins.theory.types import BoolArray, FloatArray
from safebasins.wells.base import Well

__all__ = ["GridSlowFlow"]

#: nodes of the xi grid of the slow-flow profile (slow_flow_profile's default ``n``)
N_PROFILE = 1500


class _PinnedWell:
    """The well, with ``omega``, ``harmonic_amplitude_derivative``, ``J`` and
    ``harmonic_amplitude`` looked up for pinned arrays (equal arrays: the values the well gives
    for them); for a sorted 1-D array that contains the pinned profile grid, the grid's values
    are reused and only the other points evaluated.  Everything else goes to the well."""

    _NAMES = ("omega", "harmonic_amplitude_derivative", "J", "harmonic_amplitude")

    def __init__(self, well: Well) -> None:
        self._well = well
        self._pinned: dict[str, list[tuple[FloatArray, FloatArray]]] = {k: [] for k in self._NAMES}
        self._base: FloatArray | None = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._well, name)

    def pin(self, name: str, x: ArrayLike) -> None:
        x = np.array(x, float)
        self._pinned[name].append((x, np.asarray(getattr(self._well, name)(x))))

    def pin_base(self, x: ArrayLike) -> None:
        self._base = np.array(x, float)
        for k in ("J", "harmonic_amplitude"):
            self.pin(k, self._base)

    def _lookup(self, name: str, x: ArrayLike) -> Any:
        x = np.asarray(x)
        if x.ndim == 0:
            return getattr(self._well, name)(x)
        for arr, val in self._pinned[name]:
            if arr.shape == x.shape and np.array_equal(arr, x):
                return val.copy()
        b = self._base
        if name in ("J", "harmonic_amplitude") and b is not None and x.ndim == 1 and x.size > b.size:
            pos = np.searchsorted(x, b)
            if pos[-1] < x.size and np.array_equal(x[pos], b):
                out = np.empty(x.shape)
                rest = np.ones(x.size, bool)
                rest[pos] = False
                out[pos] = self._pinned[name][0][1]
                out[rest] = getattr(self._well, name)(x[rest])
                return out
        return getattr(self._well, name)(x)

    def omega(self, E: ArrayLike) -> Any:
        return self._lookup("omega", E)

    def harmonic_amplitude_derivative(self, E: ArrayLike) -> Any:
        return self._lookup("harmonic_amplitude_derivative", E)

    def J(self, E: ArrayLike) -> Any:
        return self._lookup("J", E)

    def harmonic_amplitude(self, E: ArrayLike) -> Any:
        return self._lookup("harmonic_amplitude", E)


class GridSlowFlow:
    """Slow-flow escape classification of the ICs ``(Q, P)`` (one grid) for threshold
    ``xi_max`` and phase ``Psi``, for any number of control points ``(F, Omega)``.

    ``well`` is a resolved well object (one first-harmonic variant); ``xi_max`` and ``Psi``
    validated floats, ``Q`` and ``P`` finite (broadcast).  ``reuse``: tabulate the profile's
    F-independent well values once for many control points (False: the well is asked each time,
    for one control point).  ``escapes(profile(F, Omega))`` is ``theory.slow_flow_escapes(Q, P,
    F, Omega, Psi, xi_max, well=well)`` and :meth:`xi_true` equals
    ``analysis.phase_invariant.xi_true_analytic(F, Omega, xi_max, n_gamma=..., n_xi=...,
    well=well)``, both bit for bit.
    """

    def __init__(self, Q: ArrayLike, P: ArrayLike, Psi: float, xi_max: float, well: Well,
                 reuse: bool = True) -> None:
        self.well = well
        self.xi_max = float(xi_max)
        self._pw: Well | _PinnedWell = well
        if reuse:
            pw = _PinnedWell(well)
            base = xi_grid(0.0, self.xi_max, N_PROFILE)
            inner = base[1:-1] if base[-1] >= well.barrier_energy else base[1:]
            if inner.size >= 2:
                with np.errstate(divide="ignore"):
                    pw.pin("omega", inner)
                pw.pin("harmonic_amplitude_derivative", inner)
            pw.pin_base(base)
            self._pw = pw
        # the ICs: inside the well and below xi_max, their (theta, xi)
        q0 = checks.check_finite("q0", Q)
        p0 = checks.check_finite("p0", P)
        q0, p0 = np.broadcast_arrays(q0, p0)
        self.shape = q0.shape
        H = well.H0(q0, p0)
        self.inside = well.in_well(q0) & (H < self.xi_max)
        theta, xi = well.angle_energy(q0[self.inside], p0[self.inside])
        gamma = theta - float(Psi)
        # the points (gamma, xi) below xi_max and their F-independent parts
        gamma, xi = np.broadcast_arrays(gamma, xi)
        self._n_in = gamma.shape
        self._below = xi < self.xi_max
        x = xi[self._below]
        g = gamma[self._below]
        self._x = x
        self._Jx = well.J(x)
        self._Gx = well.harmonic_amplitude(x)
        self._cos = np.cos(g + well.harmonic_shift(x))
        self._gamma_cache: dict[int, FloatArray] = {}
        self._cos_cache: dict[tuple[int, bytes], FloatArray] = {}

    def profile(self, F: float, Omega: float) -> SlowFlowProfile:
        """``slow_flow_profile(F, Omega, xi_max, well=well)`` (F, Omega validated floats)."""
        prof = SlowFlowProfile(float(F), float(Omega), self.xi_max, self._pw, N_PROFILE)  # type: ignore[arg-type]
        prof.well = self.well
        return prof

    def escapes(self, prof: SlowFlowProfile) -> BoolArray:
        """Bool array over the grid, True = escapes (``slow_flow_escapes``)."""
        sub = np.ones(self._n_in, dtype=bool)
        sub[self._below] = level_escapes(prof, self._x, self._Jx, self._Gx, self._cos)
        out = np.ones(self.shape, dtype=bool)
        out[self.inside] = sub
        return out

    # ------------------------------------------------------------------ xi_true_analytic
    def _gamma(self, n_gamma: int) -> FloatArray:
        n_gamma = checks.check_positive_int("n_gamma", n_gamma)
        n_gamma += n_gamma % 2
        if n_gamma not in self._gamma_cache:
            self._gamma_cache[n_gamma] = 2 * np.pi * np.arange(n_gamma) / n_gamma
        return self._gamma_cache[n_gamma]

    def _circle_escapes(self, gamma: FloatArray, xs: FloatArray, prof: SlowFlowProfile) -> BoolArray:
        """``escapes_on_manifold(gamma[:, None], xs[None, :], ...).any(axis=0)`` for
        ``xs < xi_max`` (the xi-dependent factors evaluated once per circle)."""
        w = self.well
        if prof.F == 0.0:
            return np.zeros(xs.size, dtype=bool)
        shift = w.harmonic_shift(xs)
        key = (gamma.size, shift.tobytes())       # a symmetric well: shift = 0 for every circle
        cosm = self._cos_cache.get(key)
        if cosm is None:
            cosm = np.cos(gamma[:, None] + shift[None, :])
            if len(self._cos_cache) < 8:
                self._cos_cache[key] = cosm
        out: BoolArray = np.any(level_escapes(prof, xs, w.J(xs), w.harmonic_amplitude(xs), cosm), axis=0)
        return out

    def xi_true(self, prof: SlowFlowProfile, *, n_gamma: int = 512, n_xi: int = 400, levels: int = 3) -> float:
        """``xi_true_analytic(F, Omega, xi_max, n_gamma=, n_xi=, levels=, well=well)`` for the
        control point of ``prof``."""
        gamma = self._gamma(n_gamma)
        xi_max = self.xi_max
        n_xi = checks.check_positive_int("n_xi", n_xi)
        lo, hi = 0.0, xi_max * (1 - 1e-12)
        for _ in range(checks.check_positive_int("levels", levels)):
            xs = np.linspace(lo, hi, n_xi)
            k = np.flatnonzero(self._circle_escapes(gamma, xs, prof))
            if k.size == 0:
                return hi if hi >= xi_max * (1 - 1e-9) else lo
            k0 = int(k[0])
            if k0 == 0:
                return lo
            lo, hi = float(xs[k0 - 1]), float(xs[k0])
        return lo
