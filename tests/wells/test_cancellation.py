"""A V that loses relative accuracy at the well bottom (``1 - cos q``, ``(1 - exp(-q))^2``) is
detected and evaluated there as ``int_0^q V'`` (wells/bottom.py).  References: the same well
written without cancellation (``2 sin(q/2)^2``) and the pendulum's closed forms
(``V = 1 - cos q``, barriers ``+-pi``, ``E_b = 2``, ``m = k^2 = E/2``: ``omega = pi / (2 K(m))``,
``J = (8/pi) (E(m) - (1 - m) K(m)) = (8/pi) m (K(m) - R_D(0, 1 - m, 1)/3)``; near ``E_b`` K from
``ellipkm1(1 - m)``).

Measured: the two pendulums agree to 3e-15 (omega), 7e-16 (J, |q_1|); against the closed forms
omega within 1e-14 and J within 4e-14 for ``E <= 0.999 E_b``, omega within 2.2e-10 up to
``E_b - E = 2e-15`` (NumericWell's accuracy at a barrier separatrix, the same for 2 sin^2(q/2));
V near the bottom within 3 ulps (6e-16, given an accurate V').
"""
import numpy as np
import pytest
from scipy import special

from safebasins.wells.bottom import cancellation_fix
from safebasins.wells.numeric import NumericWell
from safebasins.wells.polynomial import cubic
from tests.wells.reference_orbits import rel


@pytest.fixture(scope="module")
def cos_pendulum():
    return NumericWell(lambda q: 1 - np.cos(q), np.sin, name="pendulum")


@pytest.fixture(scope="module")
def sin2_pendulum():
    return NumericWell(lambda q: 2 * np.sin(0.5 * q) ** 2, np.sin, name="pendulum")


def test_detected_where_v_cancels(cos_pendulum, sin2_pendulum):
    assert cos_pendulum.bottom_integral == pytest.approx((np.pi / 2, np.pi / 2), rel=1e-15)
    assert sin2_pendulum.bottom_integral is None
    assert cubic().bottom_integral is None
    assert NumericWell(lambda q: np.tanh(q) ** 2, lambda q: 2 * np.tanh(q) / np.cosh(q) ** 2).bottom_integral is None
    # V cancels, V' (written with expm1) does not: V at the bottom to V''s accuracy
    morse = NumericWell(lambda q: (1 - np.exp(-q)) ** 2, lambda q: -2 * np.expm1(-q) * np.exp(-q))
    assert morse.bottom_integral is not None
    q = np.concatenate([-np.geomspace(1e-9, 0.3, 30), np.geomspace(1e-9, 1.0, 30)])
    assert rel(morse.V(q), np.expm1(-q) ** 2) <= 1e-15
    # a V' off by a constant factor is a wrong V', not cancellation: left alone
    assert cancellation_fix(lambda q: 2 * np.sin(0.5 * q) ** 2, lambda q: (1 + 1e-8) * np.sin(q),
                            (np.pi, np.pi)) is None
    assert cancellation_fix(lambda q: 1 - np.cos(q), np.sin, (np.pi, np.pi)) is not None


def test_v_accurate_at_the_bottom(cos_pendulum):
    q = np.concatenate([-np.geomspace(1e-12, 3.0, 60), np.geomspace(1e-12, 3.0, 60)])
    assert rel(cos_pendulum.V(q), 2 * np.sin(0.5 * q) ** 2) <= 1e-15
    assert cos_pendulum.V(np.pi) == 2.0 and cos_pendulum.barrier_energy == 2.0      # barrier values: the given V


def test_cos_pendulum_agrees_with_sin2_pendulum(cos_pendulum, sin2_pendulum):
    assert cos_pendulum.barriers == sin2_pendulum.barriers
    E = np.concatenate([np.geomspace(1e-12, 1e-2, 20), np.linspace(0.01, 1.998, 200),
                        2 - np.geomspace(1e-3, 1e-15, 20)])
    for f in ("J", "omega", "harmonic_amplitude", "harmonic_phase"):
        a, b = getattr(cos_pendulum, f)(E), getattr(sin2_pendulum, f)(E)
        assert np.max(np.abs(a - b) / np.abs(b)) <= 1e-14, f


def test_cos_pendulum_against_closed_forms(cos_pendulum):
    E = np.concatenate([np.geomspace(1e-12, 1e-2, 20), np.linspace(0.01, 1.998, 200),
                        2 - np.geomspace(1e-3, 1e-15, 20)])
    m, mc = E / 2, (2 - E) / 2                      # 2 - E exact near E_b
    K = np.where(m < 0.5, special.ellipk(m), special.ellipkm1(mc))
    J = 8 / np.pi * m * (K - special.elliprd(0.0, mc, 1.0) / 3)
    inner = E <= 1.998
    assert rel(cos_pendulum.omega(E[inner]), np.pi / (2 * K[inner])) <= 5e-14
    assert rel(cos_pendulum.J(E[inner]), J[inner]) <= 5e-14
    # at the barrier separatrix: NumericWell's accuracy there (the same for 2 sin^2(q/2))
    assert rel(cos_pendulum.omega(E), np.pi / (2 * K)) <= 3e-10 and rel(cos_pendulum.J(E), J) <= 1e-13
    th = np.linspace(0, 2 * np.pi, 50)
    q, p = cos_pendulum.phase_point(th, 1e-10)      # the small-amplitude orbit: q = sqrt(2E) sin(theta)
    assert np.max(np.abs(q - np.sqrt(2e-10) * np.sin(th))) <= 1e-9 * np.sqrt(2e-10)
