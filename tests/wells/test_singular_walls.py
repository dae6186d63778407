"""Wells with singular walls: an electrostatic (MEMS) pole beyond the barrier, a Lennard-Jones core
as a closed side, constants whose rounding leaves V'(0) != 0, and the tol key of a well spec.
The orbit data are checked against DOP853 orbits and quadrature of the closed forms."""
import math

import numpy as np
import pytest
from scipy import integrate, optimize

from safebasins import wells

#: expression -> (V, V') in closed form, independent of the library's sympy path
WELLS = {
    "q**2/2 - 0.02/(1-q) + 0.02 + 0.02*q": (lambda q: q * q / 2 - 0.02 / (1 - q) + 0.02 + 0.02 * q,
                                             lambda q: q + 0.02 - 0.02 / (1 - q) ** 2),
    "q**2/2 - 0.05/(1-q) + 0.05 + 0.05*q": (lambda q: q * q / 2 - 0.05 / (1 - q) + 0.05 + 0.05 * q,
                                             lambda q: q + 0.05 - 0.05 / (1 - q) ** 2),
    "q**2/2 + 0.1*q - 0.081/(0.9-q) + 0.09": (lambda q: q * q / 2 + 0.1 * q - 0.081 / (0.9 - q) + 0.09,
                                               lambda q: q + 0.1 - 0.081 / (0.9 - q) ** 2),
    # the pole 0.010 beyond the barrier: no Gauss rule reaches tol over the standard segments
    "q**2/2 - 0.0001/(1-q) + 0.0001 + 0.0001*q": (lambda q: q * q / 2 - 0.0001 / (1 - q) + 0.0001 + 0.0001 * q,
                                                   lambda q: q + 0.0001 - 0.0001 / (1 - q) ** 2),
    "(1+q)**-12 - 2*(1+q)**-6 + 1": (lambda q: (1 + q) ** -12 - 2 * (1 + q) ** -6 + 1,
                                     lambda q: -12 * (1 + q) ** -13 + 12 * (1 + q) ** -7),
}


@pytest.fixture(scope="module", params=list(WELLS))
def well(request):
    return request.param, wells.expression(request.param)


@pytest.mark.parametrize("text", [t for t in WELLS if "(1+q)" not in t])
def test_mems_barrier_and_closed_side(text):
    w = wells.from_spec({"expression": text})
    V, dV = WELLS[text]
    # the barrier: V' = 0 between the bottom and the pole; the left side closes (V -> inf)
    pole = 0.9 if "0.9" in text else 1.0
    qb = optimize.brentq(dV, 0.1, pole - 1e-9, xtol=1e-15)
    assert w.barriers[0] == -np.inf and w.barriers[1] == pytest.approx(qb, rel=1e-13)
    assert w.barrier_energy == pytest.approx(V(qb), rel=1e-13)


def test_mean_rule_follows_the_pole():
    """The rule of <V'> (OrbitQuadrature): 4 nodes for the pendulum (unchanged), more as the pole
    nears the barrier, and shorter segments at the right end where no rule reaches tol."""
    rules = {text: wells.from_spec({"expression": text})._quad for text in
             ("1 - cos(q)", "q**2/2 - 0.05/(1-q) + 0.05 + 0.05*q", "q**2/2 - 0.0001/(1-q) + 0.0001 + 0.0001*q")}
    quads = list(rules.values())
    assert [q.n_mean for q in quads] == [4, 8, 16]
    assert quads[0].mean_length == quads[1].mean_length == (np.inf, np.inf)
    assert quads[2].mean_length[0] == np.inf and 0 < quads[2].mean_length[1] < 0.5 * 0.1 * quads[2].barriers[1]


def test_lennard_jones_core_is_a_wall_not_a_barrier():
    """V' changes sign through its pole at q = -1 (V -> +inf from inside): a closed side, not a
    barrier; the escape energy is the limit 1 at q -> +inf."""
    w = wells.expression("(1+q)**-12 - 2*(1+q)**-6 + 1")
    assert w.barriers == (-np.inf, np.inf)
    assert w.asymptotes == (None, 1.0) and w.open_at_infinity and w.barrier_energy == 1.0
    assert w.walls[-1.0] == pytest.approx(-1.0, abs=1e-12)
    assert -1.0 < w.limits[0] < w.turning_points(1.0)[0] + 1e-3
    assert w.barrier_text() == ""                     # no escape over a barrier on either side


def _dop853_orbit(dV, E, T_guess):
    """Period and first harmonic |q_1| of the free orbit of energy E, from q = 0, p > 0 (DOP853)."""
    def rhs(t, y):
        return [y[1], -dV(y[0])]

    def up(t, y):
        return y[0]
    up.direction = 1
    sol = integrate.solve_ivp(rhs, (0.0, 1.6 * T_guess), [0.0, math.sqrt(2.0 * E)], method="DOP853", rtol=1e-12,
                              atol=1e-14, events=up, dense_output=True)
    T = float(min(t for t in sol.t_events[0] if t > 0.5 * T_guess))
    t = np.arange(4096) * T / 4096
    q = sol.sol(t)[0]
    return T, abs(np.fft.rfft(q)[1]) / 4096


def _action(V, E, lo, hi):
    """J = (1/pi) int sqrt(2 (E - V)) dq between the turning points (quadrature of the closed form)."""
    qm = optimize.brentq(lambda q: V(q) - E, lo, 0.0, xtol=1e-15)
    qp = optimize.brentq(lambda q: V(q) - E, 0.0, hi, xtol=1e-15)
    val, _ = integrate.quad(lambda q: math.sqrt(max(2.0 * (E - V(q)), 0.0)), qm, qp, epsabs=0, epsrel=1e-13,
                            limit=200)
    return val / math.pi


@pytest.mark.parametrize("frac", [0.3, 0.9])
def test_orbit_data_against_dop853_and_quadrature(well, frac):
    text, w = well
    V, dV = WELLS[text]
    E = frac * w.barrier_energy
    T, q1 = _dop853_orbit(dV, E, float(w.period(E)))
    assert float(w.period(E)) == pytest.approx(T, rel=1e-9)
    assert float(w.harmonic_amplitude(E)) == pytest.approx(q1, rel=1e-8)
    hi = 0.999999 * (w.barriers[1] if np.isfinite(w.barriers[1]) else 50.0)
    assert float(w.J(E)) == pytest.approx(_action(V, E, -0.999 if "(1+q)" in text else -5.0, hi), rel=1e-10)


def test_constants_whose_rounding_leaves_a_slope_at_the_bottom():
    """0.3 - 0.243/0.81 is -2.8e-17 in floats: V'(0) is not 0 as written (sympy's cancelled form of V'
    keeps it as a constant term).  The orbits use V' - V'(0); this used to fail with 'V' not
    analytic at the well bottom'."""
    w = wells.expression("q**2/2 + 0.3*q - 0.24300000000000002/(0.9-q) + 0.27")
    assert float(w.dV(np.zeros(1))[0]) != 0.0
    E = np.array([1e-12, 1e-6, 0.5 * w.barrier_energy])
    assert np.isfinite(w.J(E)).all() and np.isfinite(w.omega(E)).all()
    # J ~ E / omega(0) at the bottom (the exact minimum is at q = 0 to rounding)
    assert float(w.J(1e-12)) == pytest.approx(1e-12 / float(w.omega(0.0)), rel=1e-6)


def test_tol_key_of_a_well_spec():
    """A formula whose own rounding stops short of 1e-13 (0.21 + ... cancels to V ~ 1e-4 over the well)
    fails naming the spec's tol key; {expression: ..., tol: 1e-11} builds it, and the tol travels
    with the spec and the dataset attributes."""
    text = "q**2/2 + 0.3*q - 0.147/(0.7-q) + 0.21"
    with pytest.raises(ValueError, match=r"tol: the energy interpolation did not reach tol = 1e-13.*tol: 1e-11"):
        wells.from_spec({"expression": text})
    w = wells.from_spec({"expression": text, "tol": 1e-11})
    assert w.tol == 1e-11 and w.spec() == {"name": "expression", "expression": text, "tol": 1e-11}
    attrs = wells.well_attrs(w)
    assert attrs["well_tol"] == 1e-11 and wells.from_attrs(attrs) is w
    assert wells.spec_of({"expression": "1 - cos(q)"}) == {"name": "expression", "expression": "1 - cos(q)"}
    for bad, msg in (({"expression": text, "tol": 1.0}, "tol must be a number in"),
                     ({"expression": text, "tol": "x"}, "tol must be numeric"),
                     ({"tol": 1e-11}, "is not a well")):
        with pytest.raises(ValueError, match=f"well: .*{msg}"):
            wells.spec_of(bad)
