"""The split step (scheme_code.SchemeCode.make_split) of the wells with a split force
(wells.compiled.WellCode.split): V'(q) carried from a step's last kick to the next step's first,
V(q) of the energy test from the last kick's call.  It must give the plain step's bits: the
compiled split step against the step, chained over many steps, for every scheme, damped or not;
and the engine's loops (shared and per-lane, replays, period map) with a split well against the
same arithmetic without its split form."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from safebasins import wells
from safebasins.numerics import engine, schemes, steps
from safebasins.numerics.problem import ensemble_problem
from safebasins.numerics.scheme_code import scheme_code
from safebasins.wells import compiled
from safebasins.wells.numeric import NumericWell

#: wells whose force is f - V'(q) with V' a function of its own (expression and user wells)
SPLIT_WELLS = {"pendulum": "pendulum", "sech2": "sech2", "morse": "morse",
               "mems": {"expression": "q**2/2 - 1/20/(1 - q) + 1/20 + q/20"}}


def _user_well() -> NumericWell:
    """A well from the user's callables (NumericWell): its code is split too."""
    def V(q: float) -> float:
        return 0.5 * q * q - 0.25 * q ** 4

    def dV(q: float) -> float:
        return q - q ** 3
    return NumericWell(V, dV, barriers=(-1.0, 1.0), name="user quartic")


def _bits(*x: float) -> np.ndarray:
    """The bits of x, every NaN as one (a NaN's sign and payload are the hardware's: they follow the
    operand order the compiler picks, as in tests/wells/test_elementary.py)."""
    a = np.array(x, dtype=float)
    return np.where(np.isnan(a), np.nan, a).view(np.int64)


def test_which_codes_are_split() -> None:
    """The quartic's closed form and the polynomial codes fuse f into an fma (no split: their
    loops keep the plain step); expression and user wells split."""
    assert wells.QUARTIC.compiled.split is None
    assert wells.cubic().compiled.split is None
    assert wells.polynomial([0.0, 0.0, 0.5, 0.0, -0.25]).compiled.split is None
    for spec in SPLIT_WELLS.values():
        code = wells.resolve_well(spec).compiled
        assert code.split is not None and code.signed().split is code.split
    assert _user_well().compiled.split is not None


def _states(code: compiled.WellCode) -> list[tuple[float, float]]:
    rng = np.random.default_rng(3)
    lo, hi = code.barriers
    q = rng.uniform(max(lo, -3.0), min(hi, 3.0), 40)
    p = rng.uniform(-1.0, 1.0, 40)
    special = [(0.0, 0.3), (-0.0, -0.2), (1e-300, 0.0), (2.0 ** 31 + 0.5, 0.1), (-1e22, 0.0), (np.inf, 0.0),
               (np.nan, 0.1), (0.2, np.nan)]
    return [*zip(q.tolist(), p.tolist()), *special]


@pytest.mark.parametrize("damped", [False, True])
@pytest.mark.parametrize("integrator", list(schemes.SCHEMES))
@pytest.mark.parametrize("name", [*SPLIT_WELLS, "user"])
def test_split_step_is_the_step_bitwise(name: str, integrator: str, damped: bool) -> None:
    """From every state (random, huge, signed zeros, inf, NaN) and chained over 100 steps, the
    split step's (q, p) are the step's bit for bit (any NaN equal to any NaN), and its (d, v) are
    V'(q), V(q) at the new q: d equals the well's gradient, energy2_from(v) the well's energy2."""
    code = _user_well().compiled if name == "user" else wells.resolve_well(SPLIT_WELLS[name]).compiled
    sc = scheme_code(integrator, damped)
    step = steps.cpu_step(sc.key, code.key)
    split = steps.cpu_split_step(sc.key, code.key)
    fns = compiled.cpu_split(code.key)
    assert split is not None and fns is not None
    gradient = fns[0]
    energy2 = compiled.cpu_functions(code.key)[1]
    S = 32
    c = tuple(schemes.lane_coefficients(0.9, S, integrator, 0.05 if damped else 0.0)[0].tolist())
    tab = 0.3 * schemes.sine_table(S, 0.4, integrator)
    w = steps.wtuple(code.wpar)
    for q0, p0 in _states(code):
        q, p = q0, p0
        qs, ps, d = q0, p0, gradient(w, q0)
        for n in range(100):
            f = tuple(tab[n % S].tolist())
            q, p = step(w, q, p, c, f)
            qs, ps, d, v = split(w, qs, ps, c, f, d)
            assert np.array_equal(_bits(qs, ps), _bits(q, p)), (name, integrator, damped, q0, p0, n)
            assert np.array_equal(_bits(d), _bits(gradient(w, q))), (name, q0, p0, n)
            assert np.array_equal(_bits(steps.ENERGY2_FROM(w, v, p)), _bits(energy2(w, q, p))), (name, q0, p0, n)


def _plain(code: compiled.WellCode) -> compiled.WellCode:
    """The same arithmetic without its split form (the engine's plain loops)."""
    return compiled.WellCode(code.name, code.make, code.wpar, code.abs_tracking, code.source + "\0plain")


@pytest.mark.parametrize(("name", "integrator", "damping"), [("pendulum", "srkn6b", 0.0), ("morse", "rk4", 0.03)])
def test_engine_loops_with_split_step_keep_every_bit(name: str, integrator: str, damping: float) -> None:
    """Escape steps of energy and bound thresholds and the period map of a split well: the split
    loops (shared parameter set and per lane; crossings replayed by the plain scalar step) equal
    the plain loops' bit for bit, and the run is not vacuous (some ICs escape late, some never)."""
    w = wells.resolve_well(SPLIT_WELLS[name])
    Eb = w.barrier_energy
    q, p = np.meshgrid(np.linspace(-1.2, 1.2, 23), np.linspace(-0.7, 0.7, 19), indexing="ij")
    q, p = q.ravel() * (0.6 if name == "morse" else 1.0), p.ravel() * np.sqrt(Eb)
    bounds = np.array([[-0.9, 0.9], [-1.5, 1.6]]) * (0.8 if name == "morse" else 1.0)
    kw = dict(xi_max=[0.6 * Eb, 0.9 * Eb], q_bounds=bounds, cycles=25, steps_per_cycle=32, integrator=integrator,
              well=w, damping=damping)
    for pidx, Omega, F in ((np.zeros(q.size, np.int64), [0.9], [0.12 * Eb]),
                           (np.arange(q.size) % 3, [0.8, 0.9, 1.05], [0.08 * Eb, 0.12 * Eb, 0.2 * Eb])):
        pb = ensemble_problem(q, p, pidx, Omega, F, 0.4, **kw)
        assert pb.code.split is not None
        E, Q, st = engine.run_cpu(pb, threads=2, store=True)
        E0, Q0, st0 = engine.run_cpu(dataclasses.replace(pb, code=_plain(pb.code)), threads=2, store=True)
        assert np.array_equal(E, E0) and np.array_equal(Q, Q0)
        assert st is not None and st0 is not None
        assert np.array_equal(_bits(*st.ravel()), _bits(*st0.ravel()))
        assert (E > 32).any() and (E < 0).any() and (Q > 32).any(), (name, E, Q)
