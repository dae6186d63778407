"""Wells open at infinity: V' keeps its sign and V tends to a finite limit, the escape
energy (docs/wells.md).  References, with ``s = E_b - E`` (exact in float near E_b):

* Morse ``V = D (1 - e^{-a q})^2``, ``k = sqrt(E/D)``, ``k' = sqrt(s/D)``:
  ``omega = a sqrt(2 s)``, ``J = (sqrt(2 D)/a) (1 - k')``,
  ``q(theta) = (1/a) log[(1 - k cos(theta - theta_-)) / k'^2]`` with ``theta_- = -atan2(k', k)``,
  ``q_1 = -(r/a) (k + i k')``, ``r = k / (1 + k')`` (Fourier series of ``log(1 - k cos)``);
* ``V = tanh^2 q = 1 - sech^2 q``, ``c = sqrt(E/s)``: ``omega = sqrt(2 s)``,
  ``J = sqrt(2) (1 - sqrt(s))``, ``q(theta) = asinh(c sin theta)``,
  ``q_1 = -i (2/(3 pi)) sqrt(E) R_D(0, s, 1)`` (``= -i (2/(pi sqrt E)) (K(E) - E(E))``);
* ``V = q^2/(1 + q^2)`` (algebraic tail): ``T = 4 E(m = E) / (sqrt(2) s)``;
* DOP853 orbits + FFT (tests/wells/reference_orbits.py) for period, q_1 and angles, scipy quad
  for J.

Measured on this machine (bounds below leave a margin of 2-5): omega, J, q_1, arg q_1 of Morse
(three D, a) and tanh^2 within 1.2e-13 relative for every float E < E_b incl. the last one (J of
tanh^2: 2.1e-13, the interpolation tolerance); phase_point within 1.2e-13 for E <= 0.99 E_b and
1.7e-13 as an angle up to E_b - E = 1e-12 E_b; angle_energy within 3e-14; d|q_1|/dE 3e-13,
d arg q_1/dE 1.3e-12; DOP853 agrees to 2e-12 (its own accuracy), quad to 1e-13; the algebraic
tail's period within 2e-14.  Construction 0.07-0.16 s CPU.
"""
import time

import numpy as np
import pytest
from scipy import special

from safebasins.wells.numeric import NumericWell
from tests.wells.reference_orbits import angle_diff, assert_matches_orbit, rel

MORSE = [(1.0, 1.0), (1.3, 0.7), (0.5, 3.0)]


def morse(D, a, **kw):
    return NumericWell(lambda q: D * (1 - np.exp(-a * q)) ** 2,
                       lambda q: 2 * D * a * (1 - np.exp(-a * q)) * np.exp(-a * q), name="morse", **kw)


def sech_dV(q):
    return 2 * np.tanh(q) / np.cosh(q) ** 2


SECH2 = {"tanh^2": lambda q: np.tanh(q) ** 2, "1 - sech^2": lambda q: 1 - 1 / np.cosh(q) ** 2}


@pytest.fixture(scope="module", params=MORSE, ids=lambda p: f"D={p[0]},a={p[1]}")
def morse_well(request):
    return request.param, morse(*request.param)


@pytest.fixture(scope="module", params=list(SECH2))
def sech2(request):
    return NumericWell(SECH2[request.param], sech_dV, name="sech2")


def energies(Eb):
    """Bottom, middle, the approach to the limit and the last float below it."""
    return np.concatenate([Eb * np.geomspace(1e-12, 1e-2, 20), Eb * np.linspace(0.01, 0.99, 150),
                           Eb - Eb * np.geomspace(1e-2, 1e-15, 40), [np.nextafter(Eb, 0.0)]])


def morse_ref(D, a, E):
    s = D - E
    k, kc = np.sqrt(E / D), np.sqrt(s / D)
    r = k / (1 + kc)
    return {"omega": a * np.sqrt(2 * s), "J": np.sqrt(2 * D) / a * (E / D) / (1 + kc), "q1": -(r / a) * (k + 1j * kc),
            "k": k, "kc": kc, "theta_minus": -np.arctan2(kc, k)}


def morse_orbit(D, a, theta, E):
    ref = morse_ref(D, a, E)
    k, kc, om = ref["k"], ref["kc"], ref["omega"]
    c = np.cos(theta - ref["theta_minus"])
    return np.log((1 - k * c) / (kc * kc)) / a, om * k * np.sin(theta - ref["theta_minus"]) / (a * (1 - k * c))


def sech2_ref(E):
    s = 1.0 - E
    return {"omega": np.sqrt(2 * s), "J": np.sqrt(2) * E / (1 + np.sqrt(s)),
            "q1": -1j * 2 / (3 * np.pi) * np.sqrt(E) * special.elliprd(0.0, s, 1.0)}


def sech2_orbit(theta, E):
    s = 1.0 - E
    c = np.sqrt(E / s)
    return np.arcsinh(c * np.sin(theta)), np.sqrt(2 * s) * c * np.cos(theta) / np.sqrt(1 + (c * np.sin(theta)) ** 2)


# ----------------------------------------------------------------------------- the references
@pytest.mark.parametrize("D, a", MORSE)
def test_morse_closed_forms_are_consistent(D, a):
    E = D * np.linspace(0.05, 0.95, 7)
    h = 1e-6 * D
    dJ = (morse_ref(D, a, E + h)["J"] - morse_ref(D, a, E - h)["J"]) / (2 * h)
    assert rel(dJ, 1 / morse_ref(D, a, E)["omega"]) <= 1e-8                      # dE/dJ = omega
    n = 4096
    theta = 2 * np.pi * np.arange(n) / n
    for Ei in E:
        q, p = morse_orbit(D, a, theta, Ei)
        assert np.max(np.abs(0.5 * p * p + D * (1 - np.exp(-a * q)) ** 2 - Ei)) <= 1e-13   # on the level E
        q1 = np.mean(q * np.exp(-1j * theta))
        assert abs(q1 - morse_ref(D, a, Ei)["q1"]) <= 1e-12 * abs(q1)
    assert np.max(np.abs(morse_orbit(D, a, 0.0, E)[0])) <= 1e-13                  # theta = 0 at q = 0


def test_sech2_closed_forms_are_consistent():
    E = np.linspace(0.05, 0.95, 7)
    h = 1e-6
    assert rel((sech2_ref(E + h)["J"] - sech2_ref(E - h)["J"]) / (2 * h), 1 / sech2_ref(E)["omega"]) <= 1e-8
    m = E
    assert rel(sech2_ref(E)["q1"].imag, -2 / (np.pi * np.sqrt(E)) * (special.ellipk(m) - special.ellipe(m))) <= 1e-13
    n = 4096
    theta = 2 * np.pi * np.arange(n) / n
    for Ei in E:
        q, p = sech2_orbit(theta, Ei)
        assert np.max(np.abs(0.5 * p * p + np.tanh(q) ** 2 - Ei)) <= 1e-14
        q1 = np.mean(q * np.exp(-1j * theta))
        assert abs(q1 - sech2_ref(Ei)["q1"]) <= 1e-12 * abs(q1)


# ----------------------------------------------------------------------------- Morse
def test_morse_well_data(morse_well):
    (D, a), w = morse_well
    assert w.barriers == (-np.inf, np.inf) and w.asymptotes == (None, D)
    assert w.barrier_energy == D and w.open_at_infinity
    lo, hi = w.limits
    assert hi == np.inf and np.isfinite(lo) and w.V(lo) > D > w.V(0.999 * lo)
    assert w.omega0 == pytest.approx(a * np.sqrt(2 * D), rel=1e-8)
    E = D * np.array([0.0, 0.3, 0.9, 1 - 1e-9])
    qm, qp = w.turning_points(E)
    k = np.sqrt(E / D)
    assert np.max(np.abs(qm + np.log1p(k) / a)) <= 1e-14
    assert rel(qp[1:], -np.log((D - E[1:]) / D / (1 + k[1:])) / a) <= 1e-14          # 1 - k = k'^2 / (1 + k)
    qm, qp = w.turning_points(D)                          # the orbit at the limit is unbounded
    assert np.isfinite(qm) and qp == np.inf


def test_morse_against_closed_forms(morse_well):
    (D, a), w = morse_well
    E = energies(D)
    ref = morse_ref(D, a, E)
    assert rel(w.omega(E), ref["omega"]) <= 3e-13
    assert rel(w.period(E), 2 * np.pi / ref["omega"]) <= 3e-13
    assert rel(w.dJ_dE(E), 1 / ref["omega"]) <= 3e-13
    assert rel(w.J(E), ref["J"]) <= 3e-13
    assert np.max(np.abs(w.first_harmonic(E) - ref["q1"]) / np.abs(ref["q1"])) <= 3e-13
    assert np.max(np.abs(w.harmonic_phase(E) - np.angle(ref["q1"]))) <= 3e-13
    Ei = D * np.linspace(0.01, 0.99, 60)
    ref = morse_ref(D, a, Ei)
    dk, dkc = 1 / (2 * D * ref["k"]), -1 / (2 * D * ref["kc"])
    dA = ((dk * (1 + ref["kc"]) - ref["k"] * dkc) / (1 + ref["kc"]) ** 2) / a          # |q_1| = r/a
    assert rel(w.harmonic_amplitude_derivative(Ei), dA) <= 1e-10
    assert rel(w.harmonic_phase_derivative(Ei), -dk / ref["kc"]) <= 1e-10            # arg q_1 = acos k - pi


def test_morse_angles_against_closed_form(morse_well):
    (D, a), w = morse_well
    rng = np.random.default_rng(3)
    theta = rng.uniform(0, 2 * np.pi, 600)
    E = D * rng.uniform(0, 0.99, 600)
    q0, p0 = morse_orbit(D, a, theta, E)
    q, p = w.phase_point(theta, E)
    assert np.max(np.abs(q - q0)) <= 3e-13 and np.max(np.abs(p - p0)) <= 3e-13
    th, xi = w.angle_energy(q0, p0)
    assert angle_diff(th, theta) <= 3e-13
    q2, p2 = w.phase_point(th, xi)
    assert np.max(np.abs(q2 - q0)) <= 3e-13 and np.max(np.abs(p2 - p0)) <= 3e-13
    # near the limit the position is steep in theta (dq/dtheta = p/omega): compare as an angle
    E = D - D * np.geomspace(1e-2, 1e-12, 200)
    theta = rng.uniform(0, 2 * np.pi, 200)
    q0, p0 = morse_orbit(D, a, theta, E)
    q, p = w.phase_point(theta, E)
    fast = np.abs(p0) > 1e-3
    assert np.max((np.abs(q - q0) * morse_ref(D, a, E)["omega"] / np.abs(p0))[fast]) <= 1e-12


# ----------------------------------------------------------------------------- sech^2
def test_sech2_well_data(sech2):
    assert sech2.barriers == (-np.inf, np.inf) and sech2.asymptotes == (1.0, 1.0)
    assert sech2.barrier_energy == 1.0 and sech2.limits == (-np.inf, np.inf)
    assert sech2.omega0 == pytest.approx(np.sqrt(2), rel=1e-8)
    E = np.array([0.2, 0.7, 1 - 1e-12])
    qm, qp = sech2.turning_points(E)
    assert rel(qp, np.arcsinh(np.sqrt(E / (1 - E)))) <= 1e-14 and rel(-qm, qp) <= 1e-15      # sinh q_t = c
    assert sech2.turning_points(1.0) == (-np.inf, np.inf)


def test_sech2_against_closed_forms(sech2):
    E = energies(1.0)
    ref = sech2_ref(E)
    assert rel(sech2.omega(E), ref["omega"]) <= 3e-13
    assert rel(sech2.J(E), ref["J"]) <= 5e-13
    assert np.max(np.abs(sech2.first_harmonic(E) - ref["q1"]) / np.abs(ref["q1"])) <= 3e-13
    assert np.max(np.abs(sech2.harmonic_phase(E) + np.pi / 2)) <= 3e-13               # symmetric: q_1 = -i |q_1|


def test_sech2_angles_against_closed_form(sech2):
    rng = np.random.default_rng(4)
    theta = rng.uniform(0, 2 * np.pi, 600)
    E = rng.uniform(0, 0.99, 600)
    q0, p0 = sech2_orbit(theta, E)
    q, p = sech2.phase_point(theta, E)
    assert np.max(np.abs(q - q0)) <= 3e-13 and np.max(np.abs(p - p0)) <= 3e-13
    assert angle_diff(sech2.angle_energy(q0, p0)[0], theta) <= 3e-13
    E = 1 - np.geomspace(1e-2, 1e-12, 200)
    q0, p0 = sech2_orbit(theta[:200], E)
    q, p = sech2.phase_point(theta[:200], E)
    fast = np.abs(p0) > 1e-3
    assert np.max((np.abs(q - q0) * np.sqrt(2 * (1 - E)) / np.abs(p0))[fast]) <= 1e-12


# ----------------------------------------------------------------------------- DOP853 orbits, quad
OTHERS = {
    "morse(1.3, 0.7)": lambda: morse(1.3, 0.7),
    "sech^2": lambda: NumericWell(lambda q: np.tanh(q) ** 2, sech_dV),
    "gaussian": lambda: NumericWell(lambda q: 1 - np.exp(-0.5 * q * q), lambda q: q * np.exp(-0.5 * q * q)),
    "lorentzian": lambda: NumericWell(lambda q: q * q / (1 + q * q), lambda q: 2 * q / (1 + q * q) ** 2),
    "asymmetric tanh": lambda: NumericWell(lambda q: 0.5 * np.tanh(q) ** 2 * (1 + 0.6 * np.tanh(q)),
                                           lambda q: 0.5 * np.tanh(q) * (2 + 1.8 * np.tanh(q)) / np.cosh(q) ** 2),
}


@pytest.fixture(scope="module", params=list(OTHERS))
def open_well(request):
    return OTHERS[request.param]()


@pytest.mark.parametrize("frac", [0.05, 0.5, 0.9, 0.99])
def test_open_wells_against_quad_and_dop853(open_well, frac):
    assert_matches_orbit(open_well, frac * open_well.barrier_energy, 96)


def test_algebraic_tail_period_against_closed_form():
    w = OTHERS["lorentzian"]()
    E = 1 - np.geomspace(0.9, 1e-16, 60)
    s = 1 - E                                  # T grows like 1/s (not 1/sqrt(s)): q_t = sqrt(E/s)
    assert rel(w.period(E), 4 * special.ellipe(E) / (np.sqrt(2) * s)) <= 1e-13
    assert rel(w.turning_points(E)[1], np.sqrt(E / s)) <= 1e-14


# ----------------------------------------------------------------------------- thresholds, limits
def test_thresholds_lie_below_the_limit():
    w = morse(1.0, 1.0)
    assert w.check_threshold("xi_max", np.nextafter(1.0, 0.0)) == np.nextafter(1.0, 0.0)
    with pytest.raises(ValueError, match=r"xi_max must lie in \(0, 1.0\), below the escape energy.*unbounded"):
        w.check_threshold("xi_max", 1.0)
    with pytest.raises(ValueError, match="xi_max"):
        w.check_threshold("xi_max", 0.0)
    with pytest.raises(ValueError, match="E must be < the barrier energy"):
        w.J(1.0)
    from safebasins.wells.polynomial import cubic
    assert not cubic().open_at_infinity and cubic().check_threshold("xi_max", 1 / 6) == 1 / 6   # a barrier: E_b allowed


def test_declared_asymptotes():
    auto, given = morse(1.0, 1.0), morse(1.0, 1.0, asymptotes=(None, 1.0))
    E = energies(1.0)
    for f in ("J", "omega", "harmonic_amplitude", "harmonic_phase"):
        assert np.array_equal(getattr(auto, f)(E), getattr(given, f)(E)), f
    with pytest.raises(ValueError, match="asymptotes: the right limit is declared as 0.99, but V tends to 1.0"):
        morse(1.0, 1.0, asymptotes=(None, 0.99))
    with pytest.raises(ValueError, match="asymptotes: the right entry is None"):
        morse(1.0, 1.0, asymptotes=(None, None))
    with pytest.raises(ValueError, match="asymptotes: the left limit is declared as 2.0, but V does not converge"):
        morse(1.0, 1.0, asymptotes=(2.0, 1.0))
    # a declared limit of a barrier side is not used (escape over the barrier)
    bump = NumericWell(lambda q: q * q * np.exp(-q * q), lambda q: 2 * q * (1 - q * q) * np.exp(-q * q),
                       asymptotes=(0.0, 0.0))
    assert bump.barriers == pytest.approx((-1.0, 1.0), abs=1e-15) and bump.asymptotes == (None, None)


@pytest.mark.parametrize("asymptotes, match", [
    ((1.0,), "asymptotes must be a pair"), (3.0, "asymptotes must be a pair"),
    ((None, np.inf), "asymptotes: the right limit must be a finite number"),
    (("a", None), "asymptotes must be numeric"),
])
def test_bad_asymptotes_keyword(asymptotes, match):
    with pytest.raises(ValueError, match=match):
        morse(1.0, 1.0, asymptotes=asymptotes)


def test_tail_derivative_without_relative_precision_rejected():
    # 2 tanh (1 - tanh^2): 1 - tanh^2 cancels in the tail (sympy's derivative of tanh(q)**2)
    with pytest.raises(ValueError, match="dV: V' has lost its relative precision.*2 tanh"):
        NumericWell(lambda q: np.tanh(q) ** 2, lambda q: 2 * np.tanh(q) * (1 - np.tanh(q) ** 2))


def test_construction_time():
    """Budget 1 s CPU each (measured 0.08-0.2 s: Morse, sech^2, Gaussian, Lorentzian)."""
    for make in (lambda: morse(1.0, 1.0), *OTHERS.values()):
        t0 = time.process_time()
        make()
        assert time.process_time() - t0 < 1.0
