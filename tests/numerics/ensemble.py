"""Tests' shorthand for one CPU ensemble: engine.integrate of problem.ensemble_problem."""
from __future__ import annotations

from safebasins.numerics import engine
from safebasins.numerics.problem import ensemble_problem


def run_ensemble(q0, p0, pidx, Omega, F, Psi, *, threads=None, backend="cpu", **kw):
    """(steps_E, steps_Q) in the caller's threshold order."""
    return engine.integrate(ensemble_problem(q0, p0, pidx, Omega, F, Psi, **kw), backend, threads=threads)
