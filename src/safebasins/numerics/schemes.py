"""Integration schemes as data: a scheme is one constant, everything else is derived from it.

Equation: q' = p, p' = -beta p - V'(q) + F sin(Omega t + Psi).  A scheme is either

* a :class:`Splitting`: a kick-first splitting ``B(b_1) A(a_1) B(b_2) ... A(a_m) B(b_{m+1})`` of
  the drift ``A(a): q += a h p`` and the kick ``B(b): p += b h (-V'(q) + f(t_k))`` at the kick's
  sub-time t_k (time drifts with q: extended phase space).  With damping every drift becomes the
  exact flow of q' = p, p' = -beta p over a h: ``q += d p, p *= e`` with
  ``d = (1 - e^{-beta a h}) / beta``, ``e = e^{-beta a h}`` (conformal symplectic: the same
  splitting of an extended Hamiltonian in (q, e^{beta t} p), same order; docs/damping.md); or
* a :class:`RungeKutta`: an explicit Runge-Kutta tableau of the first-order system, its weights
  written as one scale times small integers (the sums are then exact doublings, the same IEEE
  operations on every target); damping enters every stage's force as ``-beta P_i``.

From the constant come: the compiled step of the CPU lanes and of the CUDA kernels
(scheme_code.py generates its source once), the per-parameter-set coefficients
(:func:`lane_coefficients`), the forcing table at the force sub-times (:func:`sine_table`), the
stability limit for the harmonic oscillator (:func:`stability_limit`) and the step limit the
engine accepts (:func:`step_limit`).  Adding a scheme is one constant in :data:`SCHEMES` plus its
test (order of convergence and energy error, tests/numerics/test_schemes.py).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

__all__ = ["Splitting", "RungeKutta", "Scheme", "SRKN6B", "RK4", "FOREST_RUTH", "SCHEMES", "DEFAULT_SCHEME",
           "STABILITY_FRACTION", "scheme_of", "check_integrator", "integrator_text", "lane_coefficients",
           "sine_table", "step_sizes", "stability_limit", "step_limit"]


def _unique(values: tuple[float, ...]) -> tuple[float, ...]:
    """The distinct values in order of first appearance (a palindromic scheme's coefficients once)."""
    out: list[float] = []
    for v in values:
        if v not in out:
            out.append(v)
    return tuple(out)


@dataclass(frozen=True)
class Splitting:
    """A kick-first splitting ``B(b_1) A(a_1) ... A(a_m) B(b_{m+1})`` (module docstring)."""

    name: str
    title: str
    order: int
    drift: tuple[float, ...]
    kick: tuple[float, ...]
    #: the kick sub-times as fractions of a step: 0, a_1, a_1 + a_2, ..., the last exactly 1
    kick_times: tuple[float, ...] = field(init=False)

    def __post_init__(self) -> None:
        if len(self.kick) != len(self.drift) + 1 or not self.drift:
            raise ValueError(f"{self.name}: a kick-first splitting has one kick more than drifts, "
                             f"got {len(self.kick)} kicks and {len(self.drift)} drifts")
        for what, coefs in (("drift", self.drift), ("kick", self.kick)):
            if not math.isclose(math.fsum(coefs), 1.0, rel_tol=0.0, abs_tol=1e-14):
                raise ValueError(f"{self.name}: the {what} coefficients must sum to 1, got {math.fsum(coefs)!r}")
        times = np.concatenate([[0.0], np.cumsum(self.drift)])
        times[-1] = 1.0
        object.__setattr__(self, "kick_times", tuple(float(t) for t in times))

    @property
    def damped_title(self) -> str:
        return (f"conformal symplectic {self.title}: drifts q += d_k p, p *= e_k with d_k = (1 - exp(-beta a_k h))"
                "/beta, e_k = exp(-beta a_k h), the exact flow of p' = -beta p folded into each drift")

    @property
    def force_evaluations(self) -> int:
        return len(self.kick)

    @property
    def times(self) -> tuple[float, ...]:
        """The distinct force sub-times (the forcing table's columns)."""
        return _unique(self.kick_times)

    @property
    def drift_values(self) -> tuple[float, ...]:
        return _unique(self.drift)

    @property
    def kick_values(self) -> tuple[float, ...]:
        return _unique(self.kick)

    def n_coef(self, damped: bool) -> int:
        """Coefficients per parameter set: h a (or d) per distinct drift, h b per distinct kick (and
        e per distinct drift when damped)."""
        nd = len(self.drift_values)
        return nd + len(self.kick_values) + (nd if damped else 0)

    def harmonic_matrix(self, x: float) -> np.ndarray:
        """The one-step map of q'' = -q with h = x (undamped, unforced): a 2 x 2 matrix."""
        M = np.eye(2)
        for k, b in enumerate(self.kick):
            M = np.array([[1.0, 0.0], [-b * x, 1.0]]) @ M
            if k < len(self.drift):
                M = np.array([[1.0, self.drift[k] * x], [0.0, 1.0]]) @ M
        return M


@dataclass(frozen=True)
class RungeKutta:
    """An explicit Runge-Kutta tableau for y' = (p, -beta p - V'(q) + f(t)): stage i at time
    c_i h from ``Y_i = y + h sum_j a_ij K_j`` (one product per nonzero a_ij), the step
    ``y += h * weight_scale * sum_i weights_i K_i`` (module docstring)."""

    name: str
    title: str
    order: int
    a: tuple[tuple[float, ...], ...]
    weights: tuple[int, ...]
    weight_scale: float
    c: tuple[float, ...]

    def __post_init__(self) -> None:
        s = len(self.weights)
        if len(self.a) != s or len(self.c) != s or any(len(row) != i for i, row in enumerate(self.a)):
            raise ValueError(f"{self.name}: a must be strictly lower triangular (row i has i entries) with one row, "
                             f"weight and node per stage")
        if any(w not in (1, 2) for w in self.weights):
            raise ValueError(f"{self.name}: weights are written as weight_scale times 1 or 2 (exact doublings)")
        if not math.isclose(self.weight_scale * sum(self.weights), 1.0, rel_tol=1e-15):
            raise ValueError(f"{self.name}: the weights must sum to 1")
        for i, row in enumerate(self.a):
            if not math.isclose(math.fsum(row), self.c[i], abs_tol=1e-15):
                raise ValueError(f"{self.name}: row {i} of a must sum to c_{i}")

    @property
    def damped_title(self) -> str:
        return f"{self.title} of q' = p, p' = -V'(q) - beta p + f"

    @property
    def force_evaluations(self) -> int:
        return len(self.weights)

    @property
    def times(self) -> tuple[float, ...]:
        return _unique(self.c)

    @property
    def stage_values(self) -> tuple[float, ...]:
        """The distinct nonzero a_ij (each a coefficient h a_ij)."""
        return _unique(tuple(v for row in self.a for v in row if v != 0.0))

    def n_coef(self, damped: bool) -> int:
        """h a per distinct nonzero a_ij, h * weight_scale (and beta when damped)."""
        return len(self.stage_values) + 1 + (1 if damped else 0)

    def amplification(self, z: complex) -> complex:
        """The stability function R(z) of the tableau (z = h lambda)."""
        s = len(self.weights)
        K = np.zeros(s, dtype=complex)
        for i in range(s):
            K[i] = z * (1.0 + sum(self.a[i][j] * K[j] for j in range(i)))
        return complex(1.0 + self.weight_scale * sum(w * k for w, k in zip(self.weights, K)))


Scheme = Splitting | RungeKutta

# --- the constants ---------------------------------------------------------------------------
_A1 = 0.245298957184271
_A2 = 0.604872665711080
_B1 = 0.0829844064174052
_B2 = 0.396309801498368
_B3 = -0.0390563049223486
#: Blanes & Moan (2002), SRKN_6^b (their Table 3): symmetric, 7 kicks + 6 drifts, order 4
SRKN6B = Splitting(
    name="srkn6b", title="Blanes-Moan SRKN6b (symplectic RKN, order 4, 6 force evaluations/step)", order=4,
    drift=(_A1, _A2, 0.5 - (_A1 + _A2), 0.5 - (_A1 + _A2), _A2, _A1),
    kick=(_B1, _B2, _B3, 1.0 - 2.0 * (_B1 + _B2 + _B3), _B3, _B2, _B1))

#: classic Runge-Kutta, order 4 (not symplectic)
RK4 = RungeKutta(
    name="rk4", title="classic RK4 (order 4, not symplectic, 4 force evaluations/step)", order=4,
    a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)), weights=(1, 2, 2, 1), weight_scale=1.0 / 6.0,
    c=(0.0, 0.5, 0.5, 1.0))

_THETA = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
#: Forest & Ruth (1990) in its velocity (kick-first) form: symmetric, 4 kicks + 3 drifts, order 4
FOREST_RUTH = Splitting(
    name="forest-ruth", title="Forest-Ruth (symplectic, order 4, 3 force evaluations/step)", order=4,
    drift=(_THETA, 1.0 - 2.0 * _THETA, _THETA),
    kick=(0.5 * _THETA, 0.5 * (1.0 - _THETA), 0.5 * (1.0 - _THETA), 0.5 * _THETA))

#: every scheme the engines integrate with, by name (the ``integrator`` argument)
SCHEMES: dict[str, Scheme] = {s.name: s for s in (SRKN6B, RK4, FOREST_RUTH)}
DEFAULT_SCHEME = SRKN6B.name


def scheme_of(integrator: str | Scheme) -> Scheme:
    """The scheme of an ``integrator`` name (or a scheme object); ValueError naming integrator."""
    if isinstance(integrator, (Splitting, RungeKutta)):
        return integrator
    try:
        return SCHEMES[integrator]
    except (KeyError, TypeError):
        raise ValueError(f"integrator must be one of {sorted(SCHEMES)}, got {integrator!r}") from None


def check_integrator(integrator: str) -> str:
    """The integrator name, checked (ValueError naming integrator)."""
    return scheme_of(integrator).name


def integrator_text(integrator: str, damping: float = 0.0) -> str:
    """The integrator of a dataset in words (its damped variant for damping > 0)."""
    s = scheme_of(integrator)
    return s.damped_title if damping > 0 else s.title


def step_sizes(Omega: npt.ArrayLike, steps_per_cycle: int) -> np.ndarray:
    """h = T / S per parameter set."""
    Om = np.atleast_1d(np.asarray(Omega, dtype=float))
    h: np.ndarray = 2.0 * np.pi / (Om * steps_per_cycle)
    return h


def lane_coefficients(Omega: npt.ArrayLike, steps_per_cycle: int, integrator: str | Scheme = DEFAULT_SCHEME,
                      damping: float = 0.0) -> np.ndarray:
    """Per-parameter-set step coefficients (n, scheme.n_coef(damped)), the products the step uses:

    * splitting: h a_k per distinct drift (damped: d_k = -expm1(-beta a_k h) / beta), h b_k per
      distinct kick, then (damped) e_k = exp(-beta a_k h) per distinct drift;
    * Runge-Kutta: h a_ij per distinct nonzero a_ij, h * weight_scale, then (damped) beta.
    """
    s = scheme_of(integrator)
    h = step_sizes(Omega, steps_per_cycle)[:, None]
    damped = damping > 0.0
    if isinstance(s, Splitting):
        drift = h * np.array(s.drift_values)[None, :]
        kick = h * np.array(s.kick_values)[None, :]
        if not damped:
            return np.ascontiguousarray(np.concatenate([drift, kick], axis=1))
        x = -damping * drift
        return np.ascontiguousarray(np.concatenate([-np.expm1(x) / damping, kick, np.exp(x)], axis=1))
    cols = [h * np.array(s.stage_values + (s.weight_scale,))[None, :]]
    if damped:
        cols.append(np.full((h.shape[0], 1), float(damping)))
    return np.ascontiguousarray(np.concatenate(cols, axis=1))


def sine_table(steps_per_cycle: int, Psi: float, integrator: str | Scheme = DEFAULT_SCHEME) -> np.ndarray:
    """sin(Omega t + Psi) at the scheme's distinct force sub-times of every step of one period,
    shape (S, len(scheme.times)): Omega t_k = 2 pi (s + c_k) / S, so one table serves every
    Omega and F."""
    times = np.array(scheme_of(integrator).times)
    s = np.arange(steps_per_cycle, dtype=float)[:, None] + times[None, :]
    return np.ascontiguousarray(np.sin(2.0 * np.pi * s / steps_per_cycle + Psi))


def _stable(s: Scheme, x: float) -> bool:
    """The scheme is stable for q'' = -q at h = x (|eigenvalues| <= 1, up to rounding)."""
    if isinstance(s, Splitting):
        return abs(float(np.trace(s.harmonic_matrix(x)))) <= 2.0 + 1e-12
    return abs(s.amplification(1j * x)) <= 1.0 + 1e-12


def _stable_many(s: Scheme, x: np.ndarray) -> np.ndarray:
    """``_stable`` at every h = x[i] at once (the scan below takes thousands of points, and the
    first chart of a process pays for it)."""
    if isinstance(s, Splitting):
        m = np.zeros((x.size, 2, 2))
        m[:, 0, 0] = m[:, 1, 1] = 1.0
        for k, b in enumerate(s.kick):
            m[:, 1, :] -= (b * x)[:, None] * m[:, 0, :]
            if k < len(s.drift):
                m[:, 0, :] += (s.drift[k] * x)[:, None] * m[:, 1, :]
        return np.abs(m[:, 0, 0] + m[:, 1, 1]) <= 2.0 + 1e-12
    n = len(s.weights)
    z = 1j * x
    K = np.zeros((n, x.size), dtype=complex)
    for i in range(n):
        K[i] = z * (1.0 + sum(s.a[i][j] * K[j] for j in range(i)))
    R = 1.0 + s.weight_scale * sum(w * k for w, k in zip(s.weights, K))
    return np.abs(R) <= 1.0 + 1e-12


@functools.cache
def stability_limit(integrator: str | Scheme) -> float:
    """The largest h omega for which the scheme is stable on the harmonic oscillator q'' = -omega^2 q
    (from 0 up: the first loss of stability), to 1e-12: SRKN6b 3.163, RK4 2 sqrt 2, Forest-Ruth
    1.573."""
    s = scheme_of(integrator)
    dx, chunk = 1e-3, 4096
    x = 0.0
    while True:
        # the scan's points, summed as a loop of x += dx would (cumsum adds in order)
        xs = np.cumsum(np.concatenate(([x], np.full(chunk, dx))))
        bad = np.flatnonzero(~_stable_many(s, xs[1:]))
        if bad.size:
            x = float(xs[bad[0]])
            break
        x = float(xs[-1])
        if x > 100.0:
            raise ValueError(f"{s.name}: no stability limit below h omega = 100")
    lo, hi = x, x + dx
    while hi - lo > 1e-12:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _stable(s, mid) else (lo, mid)
    return lo


#: the engine accepts steps up to this fraction of the scheme's stability limit (h omega_max):
#: there the schemes of order 4 keep a phase error per step of order 1e-3 and no trajectory is
#: near the blow-up that a step at the limit itself would allow
STABILITY_FRACTION = 0.5


def step_limit(integrator: str | Scheme) -> float:
    """The largest h * max(Omega, omega_max) the engine accepts for the scheme:
    STABILITY_FRACTION of its stability limit."""
    return STABILITY_FRACTION * stability_limit(integrator)
