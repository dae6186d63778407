"""One ensemble run, described and checked once: what every backend integrates.

:func:`ensemble_problem` validates the arguments of an ensemble (initial conditions, parameter
sets, thresholds, scheme, well, damping, horizon) and returns an :class:`EnsembleProblem`; the
backends (the CPU lanes, engine.py; the CUDA kernels, cuda_engine.py) take it as it is and return
the first-crossing steps in the problem's sorted threshold order, which
:meth:`EnsembleProblem.caller_order` puts back in the caller's order (engine.integrate).

Thresholds: ``xi_max`` energies (escape when H0 > xi_max, or q beyond a barrier) and the
displacement bound pairs (lo, hi) made of the q_max thresholds (-q_max, q_max) followed by the
q_bounds pairs; the engines watch only the next uncrossed threshold of each trajectory, so the
energies are sorted ascending and the bound pairs nested from the inside out (a pair that is not
nested with the others is refused, naming q_max / q_bounds).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from safebasins.core import checks
from safebasins.numerics import schemes
from safebasins.numerics.scheme_code import SchemeCode, scheme_code
from safebasins.wells.compiled import WellCode
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike

__all__ = ["EnsembleProblem", "ensemble_problem", "displacement_pairs", "engine_code", "check_cycles"]


def check_cycles(name: str, cycles: float) -> int:
    """A positive integer number of forcing cycles (an integral float is accepted)."""
    if isinstance(cycles, (float, np.floating)) and float(cycles).is_integer() and cycles >= 1:
        cycles = int(cycles)
    return checks.check_positive_int(name, cycles)


def displacement_pairs(q_max: npt.ArrayLike = (), q_bounds: npt.ArrayLike = ()
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The displacement thresholds as bound pairs (lo, hi): q_max -> (-q_max, q_max), then the
    q_bounds pairs; returns (lo, hi, order, signed): `order` sorts them nested from the inside
    out (hi ascending, lo descending; stable), `signed` = some pair is not symmetric.
    ValueError naming q_max / q_bounds when two pairs are not nested (neither contains the
    other: the engine watches only the next uncrossed bound of each trajectory)."""
    qm = np.asarray(q_max, dtype=float).ravel()
    qb = np.asarray(q_bounds, dtype=float).reshape(-1, 2) if np.size(q_bounds) else np.zeros((0, 2))
    lo = np.concatenate([-qm, qb[:, 0]])
    hi = np.concatenate([qm, qb[:, 1]])
    order = np.lexsort((-lo, hi))
    if lo.size and not (np.diff(lo[order]) <= 0).all():
        name = "q_bounds" if qb.shape[0] else "q_max"
        pairs = [(float(a), float(b)) for a, b in zip(lo[order], hi[order])]
        raise ValueError(f"{name}: the displacement bounds (q_max as (-q_max, q_max) and q_bounds) must be nested, "
                         f"each pair inside the next; got {pairs}")
    return lo, hi, order, bool((lo != -hi).any())


def engine_code(well: WellLike, q_max: npt.ArrayLike = (), q_bounds: npt.ArrayLike = ()) -> WellCode:
    """The compiled form the engines integrate ``well`` in: its abs(q)-tracking form only when every
    displacement bound is symmetric (displacement_pairs)."""
    code = resolve_well(well).compiled
    return code.signed() if displacement_pairs(q_max, q_bounds)[3] else code


@dataclass(frozen=True, eq=False)
class EnsembleProblem:
    """A checked ensemble run (module docstring): trajectory i starts at (q0[i], p0[i]) and is
    forced with Omega[pidx[i]], F[pidx[i]]; thresholds are stored sorted (``thrE2`` = 2 xi_max
    ascending, the bound pairs ``lo``, ``hi`` nested inside out) with the permutations back to the
    caller's order."""

    q0: np.ndarray
    p0: np.ndarray
    pidx: np.ndarray
    Omega: np.ndarray
    F: np.ndarray
    Psi: float
    thrE2: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    order_E: np.ndarray
    order_Q: np.ndarray
    code: WellCode
    scheme: SchemeCode
    damping: float
    cycles: int
    steps_per_cycle: int
    stop_any: bool
    #: a stochastic term of the equation (none yet: every run is deterministic)
    noise: None = None

    @property
    def n(self) -> int:
        return int(self.q0.size)

    @property
    def integrator(self) -> str:
        return self.scheme.name

    def coefficients(self) -> np.ndarray:
        """The scheme's step coefficients per parameter set (schemes.lane_coefficients)."""
        return schemes.lane_coefficients(self.Omega, self.steps_per_cycle, self.scheme.scheme, self.damping)

    def step_sizes(self) -> np.ndarray:
        return schemes.step_sizes(self.Omega, self.steps_per_cycle)

    def sine_table(self) -> np.ndarray:
        return schemes.sine_table(self.steps_per_cycle, self.Psi, self.scheme.scheme)

    def caller_order(self, steps_E: np.ndarray, steps_Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """First-crossing steps in the sorted threshold order -> the caller's order."""
        out_E = np.empty_like(steps_E)
        out_E[:, self.order_E] = steps_E
        out_Q = np.empty_like(steps_Q)
        out_Q[:, self.order_Q] = steps_Q
        return out_E, out_Q


def ensemble_problem(q0: npt.ArrayLike, p0: npt.ArrayLike, pidx: npt.ArrayLike, Omega: npt.ArrayLike,
                     F: npt.ArrayLike, Psi: float, *, xi_max: npt.ArrayLike = (), q_max: npt.ArrayLike = (),
                     q_bounds: npt.ArrayLike = (), cycles: float, steps_per_cycle: int,
                     stop_any: bool = False, integrator: str = schemes.DEFAULT_SCHEME, well: WellLike = None,
                     damping: float = 0.0) -> EnsembleProblem:
    """The checked description of an ensemble run (EnsembleProblem); ValueError naming the argument.

    q0, p0, pidx: one entry per trajectory (pidx indexes the parameter sets Omega, F); Psi the
    forcing phase; xi_max, q_max, q_bounds the thresholds (module docstring; not checked against
    the well here: the public functions do that with the well's own checks); cycles the horizon
    in forcing periods of steps_per_cycle steps; stop_any: a trajectory stops at its first
    crossing; integrator: a name of schemes.SCHEMES; well: any form wells.resolve_well reads;
    damping: beta >= 0 (the scheme's damped variant for beta > 0)."""
    name = schemes.check_integrator(integrator)
    q0 = np.ascontiguousarray(q0, dtype=float).ravel()
    p0 = np.ascontiguousarray(p0, dtype=float).ravel()
    pidx = np.ascontiguousarray(pidx, dtype=np.int64).ravel()
    Omega = np.ascontiguousarray(np.atleast_1d(np.asarray(Omega, dtype=float))).ravel()
    F = np.ascontiguousarray(np.atleast_1d(np.asarray(F, dtype=float))).ravel()
    if p0.size != q0.size or pidx.size != q0.size:
        raise ValueError(f"q0, p0 and pidx must have the same size, got {q0.size}, {p0.size}, {pidx.size}")
    if Omega.size != F.size:
        raise ValueError(f"Omega and F must have one value per parameter set, got sizes {Omega.size} and {F.size}")
    if q0.size and (pidx.min() < 0 or pidx.max() >= Omega.size):
        raise ValueError(f"pidx must index the {Omega.size} parameter set(s)")
    damping = checks.check_damping(damping)
    xi = np.asarray(xi_max, dtype=float).ravel()
    lo, hi, order_Q, _ = displacement_pairs(q_max, q_bounds)
    order_E = np.argsort(xi, kind="stable")
    return EnsembleProblem(
        q0=q0, p0=p0, pidx=pidx, Omega=Omega, F=F, Psi=float(Psi),
        thrE2=np.ascontiguousarray(2.0 * xi[order_E]), lo=np.ascontiguousarray(lo[order_Q]),
        hi=np.ascontiguousarray(hi[order_Q]), order_E=order_E, order_Q=order_Q,
        code=engine_code(well, q_max, q_bounds), scheme=scheme_code(name, damping > 0.0), damping=damping,
        cycles=check_cycles("cycles", cycles),
        steps_per_cycle=checks.check_positive_int("steps_per_cycle", steps_per_cycle),
        stop_any=bool(stop_any))
