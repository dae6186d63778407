"""Melnikov threshold of the hilltop saddle (safebasins.analysis.melnikov, docs/melnikov.md).

Independent routes: the closed-form separatrix orbits checked against the equation of motion
and the energy, their integrals I1 = int p0^2 dt and I2 = int p0 e^{i Omega t} dt by scipy's
QUADPACK (QAWF Fourier integrals) against the closed forms; the q-quadrature against the closed
forms (quartic, cubic, pendulum), against a direct DOP853 integration of the separatrix of a well
without closed form, and against mirrored / rewritten wells; the threshold against the manifolds
of the forced saddle integrated numerically (no intersection at 0.9 F_M, intersection at 1.1 F_M).
"""
import numpy as np
import pytest
from numpy.polynomial import polynomial as P
from scipy.integrate import quad, solve_ivp

from safebasins.analysis import melnikov_curve, melnikov_threshold
from safebasins.analysis.melnikov import (CLOSED_FORMS, manifold_splitting, melnikov_function, separatrix_integrals,
                                          separatrix_orbit)
from safebasins.wells import resolve_well

OMEGA = np.array([0.01, 0.05, 0.2, 0.5, 0.85, 1.0, 1.5, 2.0, 3.0, 4.0])
R2 = np.sqrt(2.0)
sech = lambda x: 2.0 * np.exp(-np.abs(x)) / (1.0 + np.exp(-2.0 * np.abs(x)))

#: closed-form separatrix orbits: q0(t), p0(t), V', E_b, saddles; t = 0 at the middle of the orbit
ORBITS = {
    "quartic": (lambda t: np.tanh(t / R2), lambda t: sech(t / R2) ** 2 / R2, lambda q: q - q ** 3, 0.25, (-1.0, 1.0)),
    "cubic": (lambda t: 1.0 - 1.5 * sech(t / 2) ** 2, lambda t: 1.5 * sech(t / 2) ** 2 * np.tanh(t / 2),
              lambda q: q - q ** 2, 1.0 / 6.0, (1.0,)),
    "pendulum": (lambda t: 4.0 * np.arctan(np.exp(t)) - np.pi, lambda t: 2.0 * sech(t), np.sin, 2.0, (-np.pi, np.pi)),
}
#: the thresholds F_M = beta I1 / |I2| written out (docs/melnikov.md)
THRESHOLDS = {
    "quartic": lambda W, b: 2.0 * b * np.sinh(np.pi * W / R2) / (3.0 * np.pi * W),
    "cubic": lambda W, b: b * np.sinh(np.pi * W) / (5.0 * np.pi * W ** 2),          # Thompson
    "pendulum": lambda W, b: 4.0 * b / np.pi * np.cosh(np.pi * W / 2.0),
}
ASYMMETRIC = [0.0, 0.0, 0.5, 0.2 / 3, -0.25]   # barriers -0.905 (V = 0.192) and 1.105 (V = 0.306): homoclinic


# ------------------------------------------------------------------ the closed forms themselves
@pytest.mark.parametrize("name", list(ORBITS))
def test_closed_form_orbit_solves_the_equation_on_the_separatrix(name):
    q0, p0, dV, Eb, saddles = ORBITS[name]
    t = np.linspace(-12.0, 12.0, 241)
    h = 1e-4
    assert np.allclose((q0(t + h) - q0(t - h)) / (2 * h), p0(t), rtol=0, atol=1e-8)      # q0' = p0
    assert np.allclose((p0(t + h) - p0(t - h)) / (2 * h), -dV(q0(t)), rtol=0, atol=1e-8)  # p0' = -V'(q0)
    w = resolve_well(name)
    assert np.allclose(w.H0(q0(t), p0(t)), Eb, rtol=0, atol=1e-14)
    assert w.barrier_energy == pytest.approx(Eb, rel=1e-14)
    # from the saddle (t -> -inf) back to it (homoclinic) or on to the other one (heteroclinic)
    assert q0(-60.0) == pytest.approx(saddles[0], abs=1e-12) and q0(60.0) == pytest.approx(saddles[-1], abs=1e-12)


@pytest.mark.parametrize("name", list(ORBITS))
def test_closed_form_integrals_by_quadpack(name):
    """I1 and |I2(Omega)| of the closed forms (docs/melnikov.md) against scipy's QUADPACK on the
    closed-form p0(t): p0 even (heteroclinic) gives I2 = 2 int_0^inf p0 cos, odd (homoclinic)
    I2 = 2 i int_0^inf p0 sin (QAWF)."""
    _, p0, _, _, _ = ORBITS[name]
    I1, I2abs, kind = CLOSED_FORMS[name]
    assert 2 * quad(lambda t: p0(t) ** 2, 0, np.inf, epsabs=0, epsrel=1e-13)[0] == pytest.approx(I1, rel=1e-12)
    weight = "cos" if kind == "heteroclinic" else "sin"
    for W in (0.3, 0.85, 2.0):
        val = 2 * quad(p0, 0, np.inf, weight=weight, wvar=W, epsabs=1e-12)[0]
        assert abs(val) == pytest.approx(I2abs(W), rel=1e-11)           # measured 1e-15


# ------------------------------------------------------------------ quadrature vs closed forms
@pytest.mark.parametrize("name", list(ORBITS))
def test_quadrature_matches_closed_forms(name):
    I1c, I2c, kind = CLOSED_FORMS[name]
    I1, I2, orbit = separatrix_integrals(OMEGA, name)
    assert orbit.kind == kind
    assert I1 == pytest.approx(I1c, rel=1e-13)
    assert np.max(np.abs(np.abs(I2) / I2c(OMEGA) - 1)) < 1e-12            # measured: 5e-14
    if kind == "homoclinic":                                               # t = 0 at the turning point
        assert np.all(np.abs(I2.real) <= 1e-15 * np.abs(I2))
    F = melnikov_threshold(OMEGA, 0.1, name)
    assert np.max(np.abs(F / THRESHOLDS[name](OMEGA, 0.1) - 1)) < 1e-12
    assert melnikov_threshold(1e-4, 0.1, name) == pytest.approx(THRESHOLDS[name](1e-4, 0.1), rel=1e-12)


def test_thompson_escape_equation_value():
    """The escape equation at beta = 0.1, Omega = 0.85: F_M = beta sinh(pi Omega) / (5 pi Omega^2)."""
    F = melnikov_threshold(0.85, 0.1, "cubic")
    assert isinstance(F, float)
    assert F == pytest.approx(0.1 * np.sinh(0.85 * np.pi) / (5 * np.pi * 0.85 ** 2), rel=1e-13)
    assert F == pytest.approx(0.0633353, abs=1e-7)


def test_orbits():
    o = separatrix_orbit("cubic")
    assert (o.kind, o.saddles, o.turning_point) == ("homoclinic", (1.0,), pytest.approx(-0.5, abs=1e-15))
    assert separatrix_orbit(None).kind == separatrix_orbit("pendulum").kind == "heteroclinic"
    o = separatrix_orbit({"polynomial": ASYMMETRIC})
    assert o.kind == "homoclinic" and o.saddles[0] < 0 < o.turning_point


@pytest.mark.parametrize("spec, like", [
    ({"polynomial": [0, 0, 0.5, 1 / 3]}, "cubic"),                 # mirrored cubic: saddle at q = -1, turns at 1/2
    ({"polynomial": [0, 0, 0.5, 0, -0.25]}, "quartic"),            # the quartic as a polynomial
    ({"expression": "q**2/2 - q**4/4"}, "quartic"),
    ({"expression": "q**2/2 - q**3/3"}, "cubic"),
])
def test_same_well_other_forms(spec, like):
    assert separatrix_orbit(spec).kind == CLOSED_FORMS[like][2]
    assert np.allclose(melnikov_threshold(OMEGA, 0.05, spec), THRESHOLDS[like](OMEGA, 0.05), rtol=1e-12, atol=0)


def test_heteroclinic_needs_equal_barriers():
    """A symmetric well is heteroclinic; a slightly tilted one (q^3 / 1000) homoclinic to its lower
    saddle, with a threshold of its own."""
    assert separatrix_orbit({"polynomial": [0, 0, 0.5, 0, -0.25]}).kind == "heteroclinic"
    tilted = {"polynomial": [0, 0, 0.5, 1e-3, -0.25]}
    o = separatrix_orbit(tilted)
    assert o.kind == "homoclinic" and o.saddles[0] < 0 and o.turning_point == pytest.approx(1.0, abs=0.05)
    assert np.isfinite(melnikov_threshold(OMEGA, 0.1, tilted)).all()


def test_quadrature_matches_dop853_separatrix():
    """A well without closed form (homoclinic to its left saddle): the separatrix integrated in time
    with DOP853 from its turning point (p = 0, V = E_b) until 1e-5 from the saddle, plus the
    linear tail q - q_b = x e^{-lambda (t - t_e)} (I1 += lambda x^2 / 2, I2 += ...)."""
    w = resolve_well({"polynomial": ASYMMETRIC})
    (qb,), qt = separatrix_orbit(w).saddles, separatrix_orbit(w).turning_point
    lam = np.sqrt(-P.polyval(qb, P.polyder(ASYMMETRIC, 2)))
    W = np.array([0.3, 0.9, 2.0])
    dV = P.polyder(ASYMMETRIC)
    event = lambda t, y: abs(y[0] - qb) - 1e-5
    event.terminal = True
    sol = solve_ivp(lambda t, y: [y[1], -P.polyval(y[0], dV), y[1] ** 2, *(y[1] * np.sin(W * t))], (0.0, 200.0),
                    [qt, 0.0, 0.0, 0.0, 0.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-15, events=event)
    te, (q, _p, J1, *S) = sol.t[-1], sol.y[:, -1]
    x = q - qb
    I1 = 2.0 * (J1 + 0.5 * lam * x * x)
    I2 = 2j * (np.array(S) + np.imag(-lam * x * np.exp(1j * W * te) / (lam - 1j * W)))   # p0 odd about t = 0
    I1q, I2q, _ = separatrix_integrals(W, w)
    assert I1q == pytest.approx(I1, rel=1e-12)                             # measured 1e-14
    assert np.allclose(I2q, I2, rtol=1e-9, atol=0)                         # measured <= 9e-11


# ------------------------------------------------------------------ API
def test_shapes_and_types():
    assert isinstance(melnikov_threshold(0.9, 0.1), float)
    assert isinstance(melnikov_threshold(np.float64(0.9), 0.1), float)
    F = melnikov_threshold([[0.5, 0.9], [1.2, 2.0]], 0.1)
    assert F.shape == (2, 2) and np.allclose(F, THRESHOLDS["quartic"](np.array([[0.5, 0.9], [1.2, 2.0]]), 0.1))
    assert melnikov_threshold(np.array([0.5, 0.9]), 0.0, "cubic").tolist() == [0.0, 0.0]
    assert melnikov_threshold(0.9, 0.0) == 0.0


def test_curve_dataset():
    ds = melnikov_curve([0.5, 0.85, 1.2], 0.1, "cubic")
    assert np.allclose(ds.F_M, THRESHOLDS["cubic"](ds.Omega.values, 0.1), rtol=1e-12)
    assert float(ds.I1) == pytest.approx(1.2, rel=1e-13)
    assert np.allclose(ds.I2_abs, CLOSED_FORMS["cubic"][1](ds.Omega.values), rtol=1e-12)
    assert ds.attrs["well"] == "cubic" and ds.attrs["orbit"] == "homoclinic" and ds.attrs["damping"] == 0.1
    assert ds.attrs["turning_point"] == pytest.approx(-0.5)
    for v in ("F_M", "I1", "I2_abs", "Omega"):
        assert ds[v].attrs["units"] == "1" and ds[v].attrs["long_name"]
    ds = melnikov_curve(0.9, 0.05, {"polynomial": [0, 0, 0.5, 0, -0.25]})
    assert ds.attrs["orbit"] == "heteroclinic" and ds.attrs["well_coefficients"] == [0.0, 0.0, 0.5, 0.0, -0.25]
    assert ds.F_M.shape == (1,)


@pytest.mark.parametrize("kwargs, name", [
    (dict(Omega=0.0, damping=0.1), "Omega"), (dict(Omega=-1.0, damping=0.1), "Omega"),
    (dict(Omega=np.nan, damping=0.1), "Omega"), (dict(Omega=np.inf, damping=0.1), "Omega"),
    (dict(Omega=[0.5, 0.0], damping=0.1), "Omega"), (dict(Omega="fast", damping=0.1), "Omega"),
    (dict(Omega=50.0, damping=0.1), "Omega"),                 # |I2| ~ e^{-pi Omega / sqrt 2} lost in rounding
    (dict(Omega=0.9, damping=-0.1), "damping"), (dict(Omega=0.9, damping=np.nan), "damping"),
    (dict(Omega=0.9, damping=[0.1, 0.2]), "damping"),
    (dict(Omega=0.9, damping=0.1, well="sech2"), "well"), (dict(Omega=0.9, damping=0.1, well="morse"), "well"),
    (dict(Omega=0.9, damping=0.1, well="nowell"), "well"),
])
def test_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        melnikov_threshold(**kwargs)


def test_open_wells_say_why():
    with pytest.raises(ValueError, match="no hilltop saddle"):
        melnikov_curve([0.9], 0.1, "sech2")


# ------------------------------------------------------------------ the physics
def test_melnikov_function_and_threshold():
    """max over t0 of M(t0) = -beta I1 + F |I2| is zero at F = F_M."""
    for name in ("cubic", "quartic"):
        FM = melnikov_threshold(0.85, 0.1, name)
        t0 = np.linspace(0, 2 * np.pi / 0.85, 2001)
        for fac, sign in ((0.9, -1), (1.1, 1)):
            M = melnikov_function(t0, fac * FM, 0.85, 0.1, name, Psi=0.4)
            assert np.sign(M.max()) == sign
        assert melnikov_function(t0, FM, 0.85, 0.1, name).max() == pytest.approx(0.0, abs=1e-6)
        assert melnikov_function(t0, 0.0, 0.85, 0.1, name) == pytest.approx(-0.1 * CLOSED_FORMS[name][0])


def test_manifolds_of_the_forced_saddle_cubic():
    """The escape equation at beta = 0.1, Omega = 0.85: on the normal section of the homoclinic
    orbit (p = 0 at the turning point) the energy gap H0(W^u) - H0(W^s) stays negative at 0.9 F_M
    (no intersection) and changes sign at 1.1 F_M; both within 1e-3 of the first-order M(t0)
    extrema -+0.012 (benchmarks/melnikov_check.py: F* / F_M = 1.0002)."""
    FM = melnikov_threshold(0.85, 0.1, "cubic")
    below = manifold_splitting(0.9 * FM, 0.85, 0.1, "cubic", n_phase=24)
    above = manifold_splitting(1.1 * FM, 0.85, 0.1, "cubic", n_phase=24)
    assert below.attrs["manifolds_intersect"] == 0 and above.attrs["manifolds_intersect"] == 1
    assert below.attrs["max_energy_gap"] == pytest.approx(-0.012, abs=1e-3)
    assert above.attrs["max_energy_gap"] == pytest.approx(0.012, abs=1e-3)
    assert np.max(np.abs(above.energy_gap - above.melnikov)) < 0.02          # second order in (F, beta)


def test_manifolds_unforced_damped():
    """F = 0: the saddle is a fixed point and the gap is -beta I1 (to second order) for every t0."""
    ds = manifold_splitting(0.0, 0.85, 0.02, "cubic", n_phase=8)
    assert np.allclose(ds.energy_gap, -0.02 * 1.2, rtol=0.01)
    assert ds.attrs["manifolds_intersect"] == 0
