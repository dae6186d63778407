"""PolynomialWell / cubic / polynomial: coefficient checks, barriers from the roots of V', and
the action-angle data against scipy quad and DOP853 orbits (cubic) and the closed forms
(quartic, eq 2)."""
import numpy as np
import pytest
from numpy.polynomial import polynomial as P

from safebasins.theory import action_angle as aa
from safebasins.wells.numeric import NumericWell
from safebasins.wells.polynomial import PolynomialWell, cubic, polynomial, quartic_polynomial
from tests.wells.reference_orbits import assert_matches_orbit, rel

ASYM = [0.0, 0.0, 0.5, 0.1, -0.25]


@pytest.fixture(scope="module")
def cub():
    return cubic()


# ----------------------------------------------------------------------------- coefficients
@pytest.mark.parametrize("c, match", [
    ([0.1, 0.0, 0.5, 0.0, -0.25], "c_0"),
    ([0.0, 0.2, 0.5, 0.0, -0.25], "c_1"),
    ([0.0, 0.0, -0.5, 0.0, 0.25], "c_2"),
    ([0.0, 0.0, 0.0, 0.0, -0.25], "c_2"),
    ([0.0, 0.0, np.nan, -0.25], "finite"),
    ([0.0, 0.0], "at least 3"),
    ([[0.0, 0.0, 0.5]], "1-D"),
    (["a", 0, 1], "numbers"),
])
def test_bad_coefficients(c, match):
    with pytest.raises(ValueError, match=f"coefficients.*{match}|{match}.*coefficients"):
        PolynomialWell(c)


@pytest.mark.parametrize("c", [[0.0, 0.0, 1.0], [0.0, 0.0, 0.5, 0.0, 0.25]])
def test_no_barrier(c):
    with pytest.raises(ValueError, match="no barrier"):
        polynomial(c)


def test_interior_inflection_rejected():
    # V' = q (q - 1)^2 (2 - q): the nearest roots of V' are a double root (inflection) at 1
    dc = P.polymul(P.polymul([0, 1], [1, -2, 1]), [2, -1])
    with pytest.raises(ValueError, match="coefficients: V' vanishes at q = 0.99"):
        polynomial(P.polyint(dc))


def test_barriers_given_rejected():
    with pytest.raises(ValueError, match="barriers"):
        PolynomialWell(ASYM, barriers=(-1, 1))


# ----------------------------------------------------------------------------- cubic
def test_cubic_well_data(cub):
    assert cub.name == "cubic"
    assert isinstance(cub.coefficients, np.ndarray) and cub.coefficients.dtype == float
    assert cub.coefficients.tolist() == [0.0, 0.0, 0.5, -1.0 / 3.0]
    assert cub.barriers[0] == -np.inf and cub.barriers[1] == 1.0
    assert cub.barrier_energy == pytest.approx(1.0 / 6.0, abs=1e-16)
    lo, hi = cub.limits
    assert hi == 1.0 and -0.6 < lo < -0.5 and cub.V(lo) > cub.barrier_energy
    q = np.linspace(-2, 1.5, 11)
    assert np.max(np.abs(cub.V(q) - (q * q / 2 - q ** 3 / 3))) <= 1e-15
    assert np.max(np.abs(cub.dV(q) - (q - q * q))) <= 1e-15
    # the polynomial-root barriers agree with the generic scan of NumericWell
    generic = NumericWell(lambda q: q * q * (0.5 - q / 3), lambda q: q * (1 - q))
    assert generic.barriers == cub.barriers


@pytest.mark.parametrize("frac", [0.001, 0.2, 0.6, 0.9, 0.99, 0.9999])
def test_cubic_against_quad_and_dop853(cub, frac):
    assert_matches_orbit(cub, frac / 6.0, 60)


def test_cubic_small_energy_limit(cub):
    # harmonic limit: omega -> 1, |q_1| -> sqrt(E/2), J -> E; the first corrections are O(E)
    E = np.array([1e-10, 1e-8])
    assert rel(cub.omega(E), 1.0) <= 5 * E.max()
    assert rel(cub.harmonic_amplitude(E), np.sqrt(E / 2)) <= 5 * np.sqrt(E.max())
    assert rel(cub.J(E), E) <= 5 * E.max()


# ----------------------------------------------------------------------------- quartics
def test_quartic_polynomial_against_closed_form():
    w = quartic_polynomial()
    assert w.barriers == (-1.0, 1.0) and w.barrier_energy == 0.25
    E = np.linspace(1e-6, 0.249, 500)
    assert rel(w.J(E), aa.J(E)) <= 1e-12
    assert rel(w.omega(E), aa.omega(E)) <= 1e-12
    assert np.max(np.abs(w.first_harmonic(E) + 1j * aa.G(E, fourier="exact")) / aa.G(E, fourier="exact")) <= 1e-12
    E = np.array([0.2499])
    assert rel(w.omega(E), aa.omega(E)) <= 1e-11


def test_asymmetric_quartic_barriers_and_generic_agreement():
    w = polynomial(ASYM)
    r = np.sqrt(0.09 + 4.0)
    assert w.barriers == pytest.approx(((0.3 - r) / 2, (0.3 + r) / 2), abs=1e-15)
    assert w.barrier_energy == pytest.approx(P.polyval((0.3 - r) / 2, ASYM), abs=1e-16)
    generic = NumericWell(lambda q: q * q * (0.5 + q * (0.1 - 0.25 * q)), lambda q: q * (1 + q * (0.3 - q)))
    E = w.barrier_energy * np.linspace(0.0, 0.999, 300)
    for f in ("J", "omega", "harmonic_amplitude", "harmonic_phase"):
        a, b = getattr(w, f)(E), getattr(generic, f)(E)
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(b)), f


# ----------------------------------------------------------------------------- high degree, options
TAYLOR8 = [0.0, 0.0, 1 / 2, 0.0, -1 / 24, 0.0, 1 / 720, 0.0, -1 / 40320]     # 1 - cos q to degree 8


def test_degree8_taylor_pendulum():
    """Cauchy's bound is 1.7e30 here (leading coefficient 1/40320): the search bound comes from the
    real roots of V' and V - E_b instead, and the bottom check probes at 1e-7 of it."""
    w = polynomial(TAYLOR8)
    assert w._cauchy_bound() > 1e29 and w.search_bound < 20
    qb = w.barriers[1]
    assert w.barriers[0] == -qb and 3.07 < qb < 3.08 and abs(P.polyval(qb, w.dV_coefficients)) <= 1e-15
    assert w.barrier_energy == P.polyval(qb, TAYLOR8) and 1.97 < w.barrier_energy < 1.98
    assert w.omega0 == pytest.approx(1.0, abs=1e-12)
    # the pendulum 2 sin^2(q/2) differs by -q^10/10! + ...: relative ~ 1e-5 E^4 (measured 1.2e-5)
    pend = NumericWell(lambda q: 2 * np.sin(0.5 * q) ** 2, np.sin)
    E = np.array([1e-8, 1e-4, 1e-3, 1e-2, 0.05, 0.1])
    for f in ("omega", "J", "harmonic_amplitude"):
        assert np.all(np.abs(getattr(w, f)(E) / getattr(pend, f)(E) - 1) <= 3e-5 * E ** 4 + 2e-15), f


@pytest.mark.parametrize("kwargs, match", [
    ({"tol": -1}, "tol must be"), ({"tol": 0.0}, "tol must be"), ({"tol": "x"}, "tol must be numeric"),
    ({"tol": [1e-13, 1e-12]}, "tol must be"), ({"n_scan": 3}, "n_scan must be"),
    ({"asymptotes": (1.0,)}, "asymptotes must be a pair"),
])
def test_bad_options_named_first(kwargs, match):
    with pytest.raises(ValueError, match=match):
        cubic(**kwargs)
    with pytest.raises(ValueError, match=match):       # before the coefficients are looked at
        polynomial([1.0, 0.0, 0.5], **kwargs)
