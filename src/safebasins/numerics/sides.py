"""Over which barrier a trajectory escapes: the side of its first barrier crossing.

An escape chart (charts.py) records when an initial condition escapes, not where: the compiled
lanes keep one step per threshold.  :func:`barrier_sides` replays initial conditions with the
engine's own step (the same scheme, forcing table, coefficients and well code, so the same IEEE
operations as the lanes) and returns the sign of the barrier each first goes beyond:
``q > q_right`` (+1) or ``q < q_left`` (-1), 0 when it crosses none within the horizon.  The
energy criterion of a chart counts a barrier crossing as escape, so the first crossing comes at
or after the chart's escape step; the replay runs on past the chart's horizon by ``extra``
cycles for trajectories whose energy escape precedes their crossing.  It adds nothing to the
lanes: charts and their bits are untouched.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from safebasins.core import checks
from safebasins.core.numba_target import package_jit
from safebasins.numerics import engine, schemes
from safebasins.numerics.kernels import run_tasks, specialised
from safebasins.numerics.problem import check_cycles, ensemble_problem
from safebasins.numerics.steps import Floats, Ints, coefs, scaled_row, step, wtuple
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike

__all__ = ["barrier_sides", "RIGHT", "LEFT", "NONE"]

#: sides returned by :func:`barrier_sides`
RIGHT, LEFT, NONE = 1, -1, 0


@package_jit(cache=True, nogil=True)
def _sides(well: int, scheme: int, wpar: Floats, q0: Floats, p0: Floats, coef: Floats, F: float,
           sintab: Floats, n_steps: int, task: int, n_tasks: int, out: Ints, at: Ints) -> None:
    S = sintab.shape[0]
    w = wtuple(wpar)
    cc = coefs(scheme, coef[0])
    ql, qr = wpar[0], wpar[1]
    for i in range(task, q0.shape[0], n_tasks):
        q = q0[i]
        p = p0[i]
        side = 0
        n = 0
        if q > qr:
            side = 1
        elif q < ql:
            side = -1
        while side == 0 and n < n_steps:
            q, p = step(scheme, well, w, q, p, cc, scaled_row(scheme, sintab, n % S, F))
            n += 1
            if q > qr:
                side = 1
            elif q < ql:
                side = -1
            elif not (q == q and p == p):  # NaN before a crossing: no side (never a guess)
                break
        out[i] = side
        at[i] = n if side != 0 else -1


def barrier_sides(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float, Omega: float, Psi: float, *, cycles: int,
                  well: WellLike = None, steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE,
                  integrator: str = engine.DEFAULT_INTEGRATOR, damping: float = 0.0,
                  threads: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """``(side, step)`` of each paired initial condition: the side of its first barrier crossing
    (:data:`RIGHT` = +1: ``q > q_right``; :data:`LEFT` = -1: ``q < q_left``; :data:`NONE` = 0:
    none within ``cycles`` forcing cycles, or the state became NaN first) and the step of that
    crossing (-1: none).  Arguments as :func:`safebasins.numerics.escape_chart`; the trajectory
    is the chart's (same step, bit for bit).  A side without a barrier (``+-inf``: the cubic's
    left) is never crossed; ValueError naming ``well`` for a well without any barrier."""
    qa = checks.check_finite("q0", q0).ravel()
    pa = checks.check_finite("p0", p0).ravel()
    if qa.shape != pa.shape:
        raise ValueError(f"q0 and p0 must be paired initial conditions of equal size, got {qa.size} and {pa.size}")
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    damping = checks.check_damping(damping)
    w = resolve_well(well)
    if not np.isfinite(w.barriers).any():
        raise ValueError(f"well: the {w.name} well has no barrier to cross (barriers {w.barriers})")
    cycles = check_cycles("cycles", cycles)
    schemes.check_integrator(integrator)
    spc = engine.check_step(Omega, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = checks.check_positive_int("threads", threads)
    pb = ensemble_problem(qa, pa, np.zeros(qa.size, np.int64), [Omega], [F], Psi, cycles=cycles,
                          steps_per_cycle=spc, integrator=integrator, well=w, damping=damping)
    side = np.zeros(qa.size, np.int64)
    at = np.full(qa.size, -1, np.int64)
    if qa.size:
        n_tasks = max(1, min(threads, qa.size))
        args = [pb.code.key, pb.scheme.key, pb.code.wpar, pb.q0, pb.p0, pb.coefficients(), float(pb.F[0]),
                pb.sine_table(), int(cycles * spc), 0, n_tasks, side, at]
        entry = specialised(_sides, args)
        run_tasks(lambda t: entry(*args[:9], t, *args[10:]), n_tasks)
    return side, at
