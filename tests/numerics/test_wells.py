"""The engine in any well: the quartic path unchanged (stored numbers of the quartic-only engine), the polynomial path
(Horner from run-time coefficients) against the quartic and against scipy's DOP853, asymmetric
displacement bounds, the signed lane machinery, bad input.

Compiled kernels used here: the quartic's closed form (shared with the other numerics tests), the
degree-4 polynomial code (the cubic and the quartic as coefficients) and the quartic's signed
tracking (asymmetric bounds); the degree-8 code only through its Horner arithmetic and
final_states (small compiles).
"""
from __future__ import annotations

import hashlib
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from numba import njit
from scipy.integrate import solve_ivp

from safebasins.numerics import (critical_forcing_numeric, displacement_bounds, escape_chart,
                                 escape_chart_batch, kernels, steps, stroboscopic_map)
from safebasins.wells import compiled
from safebasins.wells.polynomial import PolynomialWell, cubic
from safebasins.numerics import schemes
from tests.numerics.ensemble import run_ensemble

# ---------------------------------------------------------------------------------------------
# the quartic, bitwise: references computed with the engine BEFORE the well flag (commit f85d441)
# ---------------------------------------------------------------------------------------------
Q0, P0 = np.linspace(-0.9, 0.9, 6), np.linspace(-0.5, 0.5, 5)
KW = dict(xi_max=(0.2, 0.12), q_max=(0.8,), cycles=20, steps_per_cycle=16)
Z = [0, 0, 0, 0, 0]
# escape steps (-1: none) of escape_chart(Q0, P0, 0.0876, 0.95, pi, **KW): energy (2, 6, 5), displacement (1, 6, 5)
REF_E = [[Z, [0, 35, 66, 62, 0], [14, 43, 46, 44, 56], [10, 21, 28, 23, 24], [0, 4, 7, 6, 0], Z],
         [Z, Z, [0, 35, 37, 30, 0], [0, 12, 19, 14, 0], Z, Z]]
REF_Q = {"srkn6b": [[Z, [2, 40, 74, 66, 83], [24, 49, 49, 51, -1], [15, 24, 33, 35, -1], [6, 8, 18, 11, 2], Z]],
         "rk4": [[Z, [2, 40, 74, 66, 83], [24, 49, 50, 51, -1], [15, 24, 33, 35, -1], [6, 8, 18, 11, 2], Z]]}
# escape_chart_batch(Q0, P0, [0.0876, 0.05], [0.95, 0.8], pi, **KW): the second control point
# (the first equals REF_E / REF_Q): energy, displacement
REF_B = {"srkn6b": ([[Z, [0, 71, 52, 39, 0], [131, -1, -1, 43, 28], [19, -1, -1, 30, 15], [0, 6, 12, 7, 0], Z],
                     [Z, Z, [0, -1, -1, 28, 0], [0, -1, -1, 19, 0], Z, Z]],
                    [[Z, [2, 79, 56, 49, 58], [134, -1, -1, 47, 34], [22, -1, -1, 39, 26], [5, 15, 16, 17, 2], Z]]),
         "rk4": ([[Z, [0, 74, 52, 39, 0], [132, -1, -1, 43, 28], [19, -1, -1, 30, 15], [0, 6, 12, 7, 0], Z],
                  [Z, Z, [0, -1, -1, 28, 0], [0, -1, -1, 19, 0], Z, Z]],
                 [[Z, [2, 79, 56, 49, 58], [142, -1, -1, 47, 34], [30, -1, -1, 39, 26], [5, 15, 16, 17, 2], Z]])}
# stroboscopic_map of 4 ICs, 30 periods (xi_max 0.22, q_max 0.85): sha256 of the iterates (q, p), escape steps
MAP_ICS = (np.array([0.1, 0.3, -0.6, 0.5]), np.array([0.2, -0.1, 0.3, 0.4]))
REF_MAP = {"srkn6b": "dc0c7905dd13109915ba8275ad32664ea442d9b9c43a8f06f56bb0355921c9b0",
           "rk4": "af5f63e11f1e98d1788173ad7756da0506afa051b1e3648e9cc5251d40baecb9"}
REF_MAP_STEPS = [31, 21, 69, 6]
#: the iterates themselves (their sha256 is REF_MAP: the file holds the old engine's numbers)
MAP_FILE = Path(__file__).with_name("quartic_map_reference.npz")
# critical_forcing_numeric([0.85, 0.95], 0.2, cycles=100, n_scan=11, F_bracket=(0, 0.2), tol=1e-3, S=16)
REF_FCR = {"srkn6b": (["0x1.899999999999ap-5", "0x1.e000000000000p-6"],
                      ["0x1.899999999999ap-5", "0x1.1666666666667p-5"]),
           "rk4": (["0x1.899999999999ap-5", "0x1.e000000000000p-6"], ["0x1.899999999999ap-5", "0x1.2333333333334p-5"])}


def _steps(cycles, S=16):
    s = np.asarray(cycles) * S
    return np.where(np.isinf(s), -1, s).astype(int)


def _same_up_to_knife_edges(now, ref):
    """Escape steps against ones stored from another machine: the engine's arithmetic is IEEE
    (explicit fma, no libm) but the forcing table is np.sin from the platform's libm, whose last
    bit may differ, and a trajectory on a knife edge then escapes a few steps earlier or later.
    At most 5% of the entries may differ and at most 2% change between escaping and not (the
    reproduction tolerances of escape times and masks, docs/reproduction.md; measured here: 0)."""
    now, ref = np.asarray(now), np.asarray(ref)
    assert now.shape == ref.shape
    assert (now != ref).mean() <= 0.05, (now.tolist(), ref.tolist())
    assert ((now < 0) != (ref < 0)).mean() <= 0.02, (now.tolist(), ref.tolist())


@pytest.mark.parametrize("integrator", ["srkn6b", "rk4"])
def test_quartic_results_unchanged(integrator):
    """Chart (shared lanes), batch (per-lane path), map (stored iterates, stop_any) and F_cr
    bisection of the quartic against the numbers of the engine before the well flag, within the
    tolerances a last-bit difference of the platform's sin allows (_same_up_to_knife_edges; the
    map's iterates within 1e-9 relative, F_cr within the bisection's tol).  Bit-for-bit equality of
    refactors is checked on one machine (scripts/engine_arrays.py, scripts/compare_results.py)."""
    ch = escape_chart(Q0, P0, 0.0876, 0.95, np.pi, integrator=integrator, **KW)
    _same_up_to_knife_edges(_steps(ch["escape_cycle_energy"].values), REF_E)
    _same_up_to_knife_edges(_steps(ch["escape_cycle_displacement"].values), REF_Q[integrator])
    assert ch.attrs["well"] == "quartic" and "quartic" in ch.attrs["escape_criteria"]
    b = escape_chart_batch(Q0, P0, [0.0876, 0.05], [0.95, 0.8], np.pi, integrator=integrator, **KW)
    assert np.array_equal(b["escape_cycle_energy"].values[0], ch["escape_cycle_energy"].values)   # same process
    _same_up_to_knife_edges(_steps(b["escape_cycle_energy"].values[1]), REF_B[integrator][0])
    _same_up_to_knife_edges(_steps(b["escape_cycle_displacement"].values[1]), REF_B[integrator][1])
    m = stroboscopic_map(*MAP_ICS, 0.0876, 0.95, np.pi, n_iter=30, xi_max=0.22, q_max=0.85, steps_per_cycle=16,
                         integrator=integrator)
    it = np.stack([m["q"].values, m["p"].values])
    ref = np.load(MAP_FILE)[integrator]
    assert np.array_equal(np.isnan(it), np.isnan(ref))
    np.testing.assert_allclose(it, ref, rtol=1e-9, atol=1e-12, equal_nan=True)
    assert hashlib.sha256(ref.tobytes()).hexdigest() == REF_MAP[integrator]      # the stored iterates
    assert _steps(m["escape_cycle"].values).tolist() == REF_MAP_STEPS
    kw = dict(cycles=100, n_scan=11, F_bracket=(0.0, 0.2), tol=1e-3, steps_per_cycle=16, integrator=integrator)
    for crit, ref_F in zip(("energy", "displacement"), REF_FCR[integrator]):
        f = critical_forcing_numeric([0.85, 0.95], 0.2, criterion=crit, **kw)
        np.testing.assert_allclose(f["F_cr"].values, [float.fromhex(x) for x in ref_F], rtol=0, atol=1e-3)


# ---------------------------------------------------------------------------------------------
# the polynomial path
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def wells():
    return SimpleNamespace(cubic=cubic(), quartic=PolynomialWell([0.0, 0.0, 0.5, 0.0, -0.25], name="quartic-poly"))


def _within_one_step(a, b, S):
    a, b = np.asarray(a), np.asarray(b)
    assert np.array_equal(np.isinf(a), np.isinf(b)), (a, b)
    f = np.isfinite(a)
    assert (np.abs(a[f] - b[f]) <= 1.0 / S + 1e-12).all(), np.abs(a[f] - b[f]).max()


@pytest.mark.parametrize("integrator", ["srkn6b", "rk4"])
def test_quartic_as_polynomial_agrees_within_one_step(wells, integrator):
    """V = [0, 0, 0.5, 0, -0.25] by Horner (degree-4 code) against the closed-form quartic path:
    the same physics, other rounding; every pixel of every threshold within one step.  Also the
    per-lane path (two control points) and asymmetric bounds (signed quartic vs polynomial)."""
    q, p = np.linspace(-0.95, 0.95, 12), np.linspace(-0.6, 0.6, 10)
    kw = dict(xi_max=(0.2, 0.12, 0.25), q_max=(0.8, 1.0), cycles=40, steps_per_cycle=16, integrator=integrator)
    a = escape_chart(q, p, 0.0876, 0.95, np.pi, **kw)
    b = escape_chart(q, p, 0.0876, 0.95, np.pi, well=wells.quartic, **kw)
    assert b.attrs["well"] == "quartic-poly" and "q^4" in b.attrs["well_potential"]
    for v in ("escape_cycle_energy", "escape_cycle_displacement"):
        _within_one_step(a[v].values, b[v].values, 16)
    assert np.isfinite(a["escape_cycle_energy"].values).mean() > 0.3
    bounds = ((-0.75, 0.79), (-0.95, 0.9))     # asymmetric, nested with the q_max
    a = escape_chart_batch(q, p, [0.0876, 0.05], [0.95, 0.8], np.pi, q_bounds=bounds, **kw)
    b = escape_chart_batch(q, p, [0.0876, 0.05], [0.95, 0.8], np.pi, q_bounds=bounds, well=wells.quartic, **kw)
    for v in ("escape_cycle_energy", "escape_cycle_displacement", "escape_cycle_bounds"):
        _within_one_step(a[v].values, b[v].values, 16)
    c = escape_chart(q, p, 0.0876, 0.95, np.pi, q_bounds=bounds, **kw)
    np.testing.assert_array_equal(c["escape_cycle_bounds"].values, a["escape_cycle_bounds"].values[0])


@pytest.mark.parametrize("npar", [1, 2])
def test_signed_tracking_equals_abs_tracking_bitwise(npar):
    """The signed lane machinery (max q and max -q, split maxima loop: the quartic code's signed
    variant) with symmetric bounds makes exactly the |q| path's decisions: every escape step equal
    (shared and per-lane paths)."""
    q = np.linspace(-1, 1, 30)
    Q, P = (a.ravel() for a in np.meshgrid(q, q, indexing="ij"))
    N, S = Q.size, 16
    out = []
    code = compiled.quartic_code()
    for flag in (code, code.signed()):
        oE = np.full((N, 2), -1, np.int64)
        oQ = np.full((N, 2), -1, np.int64)
        hi = np.array([0.8, 1.0])
        kernels.ensemble(Q, P, np.arange(N) % npar, np.repeat(schemes.lane_coefficients(0.95, S), npar, 0),
                         np.repeat(schemes.step_sizes(0.95, S), npar), np.full(npar, 0.0876),
                         schemes.sine_table(S, np.pi),
                         2 * np.array([0.12, 0.2]), hi, 40, False, 2, 64, oE, oQ, np.empty((0, 0, 2)), False,
                         well=flag, thrQlo=-hi)
        out.append((oE, oQ))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    np.testing.assert_array_equal(out[0][1], out[1][1])
    assert (out[0][0] > 0).any() and (out[0][1] < 0).any()


def dop853_cubic(q0, p0, F, Omega, Psi, xi_max, bounds, cycles):
    """First escape times (cycles; inf: none) in V = q^2/2 - q^3/3 by DOP853 with event location:
    energy H0 > xi or q > 1 (the barrier; terminal), bounds q > hi or q < lo."""
    T = 2 * math.pi / Omega

    def H(q, p):
        return 0.5 * p * p + 0.5 * q * q - q ** 3 / 3.0

    def rhs(t, y):
        return [y[1], y[0] * y[0] - y[0] + F * math.sin(Omega * t + Psi)]

    events = []
    for x in xi_max:
        events.append((lambda x: lambda t, y: H(y[0], y[1]) - x)(x))
    for lo, hi in bounds:
        events.append((lambda hi: lambda t, y: y[0] - hi)(hi))
        events.append((lambda lo: lambda t, y: lo - y[0])(lo))
    for e in events:
        e.direction = 1
    barrier = lambda t, y: y[0] - 1.0
    barrier.direction, barrier.terminal = 1, True
    sol = solve_ivp(rhs, (0, cycles * T), [q0, p0], method="DOP853", rtol=1e-11, atol=1e-13, max_step=T / 64,
                    events=events + [barrier])
    first = [ev[0] / T if len(ev) else np.inf for ev in sol.t_events]
    tE = [0.0 if H(q0, p0) > x or q0 > 1 else min(t, first[-1]) for x, t in zip(xi_max, first)]
    tB = []
    for k, (lo, hi) in enumerate(bounds):
        t_hi, t_lo = first[len(xi_max) + 2 * k], first[len(xi_max) + 2 * k + 1]
        tB.append(0.0 if (q0 > hi or q0 < lo) else min(t_hi, t_lo))
    return tE, tB


def test_cubic_chart_matches_dop853_pixel_by_pixel(wells):
    """The cubic well (degree-4 code: Horner, one barrier at q = 1, none on the left), 7x6 ICs, 40 cycles,
    two energy thresholds (one at the barrier energy) and two asymmetric bound pairs (the turning
    points of xi = 0.12, and a one-sided pair (-inf, 0.9)): the same escape / no-escape label on
    every pixel and every escape time within one step of DOP853's event time."""
    S, cycles = 32, 40
    F, Om, Psi = 0.02, 0.85, 0.3
    w = wells.cubic
    xi = (0.12, w.barrier_energy)
    bounds = np.concatenate([displacement_bounds([0.12], w), [[-np.inf, 0.9]]])
    q0, p0 = np.linspace(-0.35, 0.6, 7), np.linspace(-0.35, 0.35, 6)
    ch = escape_chart(q0, p0, F, Om, Psi, xi_max=xi, q_bounds=bounds, cycles=cycles, steps_per_cycle=S, well=w)
    assert ch["escape_cycle_bounds"].dims == ("q_bounds", "q0", "p0")
    np.testing.assert_array_equal(ch["q_lower"].values, bounds[:, 0])
    np.testing.assert_array_equal(ch["q_upper"].values, bounds[:, 1])
    lo, hi = w.turning_points(0.12)
    assert -0.45 < lo < -0.4 and 0.6 < hi < 0.7 and ch.attrs["well"] == "cubic"
    assert "q > 1.0" in ch.attrs["escape_criteria"] and "q <" not in ch.attrs["escape_criteria"].split(";")[0]
    eng_E, eng_B = ch["escape_cycle_energy"].values, ch["escape_cycle_bounds"].values
    for i, a in enumerate(q0):
        for j, b in enumerate(p0):
            ref_E, ref_B = dop853_cubic(a, b, F, Om, Psi, xi, bounds, cycles)
            for eng, ref in zip([*eng_E[:, i, j], *eng_B[:, i, j]], [*ref_E, *ref_B]):
                assert np.isinf(eng) == np.isinf(ref), (a, b, eng, ref)
                if np.isfinite(ref):
                    assert -1e-7 <= eng - ref <= 1.0 / S + 1e-7, (a, b, eng, ref)
    for v in (eng_E[0], eng_E[1], eng_B[0], eng_B[1]):
        assert 0.3 < np.isfinite(v).mean() < 0.8          # both labels: the comparison is not vacuous
    assert (eng_B[1] >= eng_B[0]).all()                   # (-inf, 0.9) contains the turning points of 0.12


def test_cubic_map_and_bisection(wells):
    """stroboscopic_map in the cubic: iterates bitwise the plain integrator's of its code; the
    displacement criterion of critical_forcing_numeric uses the turning points of xi_max."""
    w = wells.cubic
    q0, p0 = np.array([0.1, -0.2, 0.3, 0.0]), np.array([0.1, 0.2, -0.1, 0.05])
    m = stroboscopic_map(q0, p0, 0.02, 0.85, 0.3, n_iter=30, xi_max=0.15, q_bounds=(-0.5, 0.8), well=w)
    assert m.attrs["q_lower"] == -0.5 and m.attrs["well"] == "cubic"
    safe = np.flatnonzero(~m["escaped"].values)
    assert safe.size
    S = m.attrs["steps_per_cycle"]
    q, p = kernels.final_states(q0[safe], p0[safe], np.zeros(safe.size, np.int64), schemes.lane_coefficients(0.85, S),
                                np.array([0.02]), schemes.sine_table(S, 0.3), 30, well=w.compiled)
    np.testing.assert_array_equal(q, m["q"].values[safe, 30])
    np.testing.assert_array_equal(p, m["p"].values[safe, 30])
    f = critical_forcing_numeric([0.8, 0.9], 0.12, cycles=60, n_scan=0, F_bracket=(0.0, 0.1), tol=2e-3,
                                 criterion="displacement", well=w)
    lo, hi = w.turning_points(0.12)
    assert f.attrs["q_lower"] == float(lo) and f.attrs["q_upper"] == float(hi) and f.attrs["well"] == "cubic"
    assert np.isfinite(f["F_cr"].values).all()
    e = critical_forcing_numeric([0.8, 0.9], 0.12, cycles=60, n_scan=0, F_bracket=(0.0, 0.1), tol=2e-3, well=w)
    assert (f["F_cr_high"].values >= e["F_cr_low"].values).all()


@njit
def _horner(key, wpar, q, p):
    w = steps.wtuple(wpar)
    return compiled.well_force(key, w, q, 0.25), compiled.well_energy2(key, w, q, p)


def _horner_of(code):
    key = code.key         # a global constant of the jitted lambda: a numba literal
    return njit(lambda wpar, q, p: _horner(key, wpar, q, p))


def test_horner_classes():
    """The force -V'(q) + f and 2 V(q) + p^2 of the polynomial classes against numpy; a cubic
    runs bitwise the same in the degree-4 and degree-8 classes (leading zeros are exact)."""
    P = np.polynomial.polynomial
    c6 = [0.0, 0.0, 0.5, 0.1, -0.3, 0.02, 0.05]
    code6 = compiled.polynomial_code(c6, (-1.0, 1.0))
    assert "class 8" in code6.name
    h8 = _horner_of(code6)
    for q, p in ((0.3, -0.2), (-0.7, 0.4), (1.3, 0.0)):
        f, e = h8(code6.wpar, q, p)
        assert f == pytest.approx(0.25 - P.polyval(q, P.polyder(c6)), rel=1e-14, abs=1e-15)
        assert e == pytest.approx(2 * P.polyval(q, c6) + p * p, rel=1e-14, abs=1e-15)
    c3 = [0.0, 0.0, 0.5, -1.0 / 3.0]
    code3 = compiled.polynomial_code(c3, (-np.inf, 1.0))
    assert "class 4" in code3.name
    as8 = compiled.polynomial_code(c3, (-np.inf, 1.0), degree_class=8)
    h4 = _horner_of(code3)
    for q, p in ((0.3, -0.2), (-0.7, 0.4)):
        assert h4(code3.wpar, q, p) == h8(code3.wpar, q, p)
    S = 16
    args = (np.array([0.2, -0.3]), np.array([0.1, 0.2]), np.zeros(2, np.int64), schemes.lane_coefficients(0.9, S),
            np.array([0.02]), schemes.sine_table(S, 0.0), 5)
    a = kernels.final_states(*args, well=code3)
    b = kernels.final_states(*args, well=as8)
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="degree 9"):
        compiled.polynomial_code([0, 0, 1, 0, 0, 0, 0, 0, 0, -1], (-1.0, 1.0))


# ---------------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------------
def _chart(**kw):
    return escape_chart([0.0, 0.1], [0.0, 0.1], 0.01, 0.9, 0.0, cycles=2, **kw)


@pytest.mark.parametrize("kw,name", [
    (dict(xi_max=0.2), "xi_max"),                          # above the cubic's barrier energy 1/6
    (dict(xi_max=0.0), "xi_max"),
    (dict(xi_max=(), q_max=1.2), "q_max"),                 # beyond the barrier q = 1
    (dict(xi_max=(), q_bounds=(-0.5, 1.1)), "q_bounds"),   # beyond the barrier
    (dict(xi_max=(), q_bounds=(0.1, 0.5)), "q_bounds"),    # lo >= 0
    (dict(xi_max=(), q_bounds=((-0.5, 0.5), (-0.4, 0.6))), "q_bounds"),   # not nested
    (dict(xi_max=(), q_max=0.5, q_bounds=(-0.3, 0.7)), "q_bounds"),       # not nested with q_max
    (dict(xi_max=(), q_bounds=[[-0.5, 0.5, 0.1]]), "q_bounds"),
    (dict(xi_max=()), "xi_max, q_max and q_bounds"),
])
def test_bad_thresholds_for_the_cubic(wells, kw, name):
    with pytest.raises(ValueError, match=name):
        _chart(well=wells.cubic, **kw)


def test_bad_wells_and_quartic_limits(wells):
    from safebasins.wells.numeric import NumericWell
    from scipy.special import erf
    nw = NumericWell(lambda q: 0.5 * q * q - 0.25 * q ** 4 + 0 * erf(q), lambda q: q - q ** 3)
    with pytest.raises(ValueError, match="V: the compiled engines need V"):     # scipy's erf: not numba code
        _chart(well=nw)
    for bad in (object(), "nonsense", {"polynomial": "x"}, {"expression": 3}, {"a": 1, "b": 2}):
        with pytest.raises(ValueError, match="well"):
            _chart(well=bad)
    with pytest.raises(ValueError, match="q_bounds"):
        _chart(q_bounds=(-1.1, 0.5))                       # the quartic's barrier at -1
    with pytest.raises(ValueError, match="xi_max"):
        _chart(xi_max=0.3)
    with pytest.raises(ValueError, match="xi_max"):
        critical_forcing_numeric([0.9], 0.2, well=wells.cubic)
    with pytest.raises(ValueError, match="q_bounds"):
        stroboscopic_map([0.1], [0.0], 0.01, 0.9, 0.0, q_bounds=((-0.5, 0.5), (-0.6, 0.6)), well=wells.cubic,
                         xi_max=None)
    with pytest.raises(ValueError, match="nested"):     # the engine itself refuses pairs it cannot watch
        run_ensemble([0.0], [0.0], [0], [1.0], [0.0], 0.0, q_max=(0.5,), q_bounds=((-0.6, 0.4),), cycles=1,
                            steps_per_cycle=8)
