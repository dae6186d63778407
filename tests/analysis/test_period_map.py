"""Rotation numbers, island chains and chaotic orbits of area-preserving maps
(safebasins.analysis.period_map), checked against maps whose answers are known independently:
a twist map with an exact rotation number, Henon's quadratic area-preserving map (linear
rotation at the origin, the period-5 chain of Henon 1969 confirmed by Newton, its chaotic
outer layer)."""
import numpy as np
import pytest

from safebasins.analysis.period_map import (chain_orbits, classify_orbits, minimal_period, periodic_orbit,
                                             rotation_numbers, weighted_birkhoff)

N_ITER = 3000


def iterate(step, q0, p0, n=N_ITER):
    Q = np.empty((len(q0), n + 1))
    P = np.empty_like(Q)
    Q[:, 0], P[:, 0] = q0, p0
    with np.errstate(all="ignore"):
        for i in range(n):
            Q[:, i + 1], P[:, i + 1] = step(Q[:, i], P[:, i])
    bad = ~(np.isfinite(Q).all(axis=1) & (np.abs(Q).max(axis=1) < 5))
    Q[bad], P[bad] = np.nan, np.nan  # escaped: NaN, as in the stroboscopic map
    return Q, P


# ---------------------------------------------------------------- twist map, exact rotation
CENTER = np.array([0.3, -0.2])


def omega(r):
    return 0.1 + 0.2 * r ** 2 + np.sqrt(2) * 1e-3


def twist(q, p):
    """Rotation by 2 pi omega(r) about CENTER (counter-clockwise): rotation number omega(r)."""
    x, y = q - CENTER[0], p - CENTER[1]
    a = 2 * np.pi * omega(np.hypot(x, y))
    return CENTER[0] + x * np.cos(a) - y * np.sin(a), CENTER[1] + x * np.sin(a) + y * np.cos(a)


def test_weighted_birkhoff_converges_super_polynomially():
    n = np.arange(1000)
    f = 1.0 + np.cos(2 * np.pi * n * (np.sqrt(5) - 1) / 2)  # quasi-periodic, mean 1
    assert abs(weighted_birkhoff(f) - 1.0) < 1e-12
    assert abs(f.mean() - 1.0) > 1e-5  # the plain average is far worse


def test_rotation_number_of_a_twist_map():
    r = np.array([0.05, 0.2, 0.4, 0.6])
    Q, P = iterate(twist, CENTER[0] + r, np.full(r.size, CENTER[1]))
    rho, digits = rotation_numbers(Q, P, CENTER)
    np.testing.assert_allclose(rho, omega(r), rtol=0, atol=1e-10)
    assert (digits > 10).all()
    # clockwise rotation has the opposite sign
    rho_cw, _ = rotation_numbers(Q, -P + 2 * CENTER[1], CENTER)
    np.testing.assert_allclose(rho_cw, -omega(r), atol=1e-10)


# ---------------------------------------------------------------- Henon's area-preserving map
COS_A = 0.24
SIN_A = np.sqrt(1 - COS_A ** 2)


def henon(x, y):
    x, y = np.asarray(x, float), np.asarray(y, float)
    u = y - x * x
    return x * COS_A - u * SIN_A, x * SIN_A + u * COS_A


@pytest.fixture(scope="module")
def henon_orbits():
    x0 = np.array([0.02, 0.3, 0.48, 0.6, 0.66, 0.8, 0.9])
    Q, P = iterate(henon, x0, np.zeros_like(x0))
    return x0, Q, P, classify_orbits(Q, P, (0.0, 0.0))


def test_henon_fixed_point_and_linear_rotation(henon_orbits):
    x0, Q, P, c = henon_orbits
    fp = periodic_orbit(henon, (0.05, -0.03), 1)
    assert fp is not None
    x, trace, residual = fp
    np.testing.assert_allclose(x, 0.0, atol=1e-12)
    assert trace == pytest.approx(2 * COS_A, abs=1e-6) and residual < 1e-12
    # a small orbit turns at the linear rotation number arccos(cos a) / 2 pi
    assert c["rotation_number"][0] == pytest.approx(np.arccos(COS_A) / (2 * np.pi), abs=5e-5)


def test_henon_classes(henon_orbits):
    x0, Q, P, c = henon_orbits
    cls = dict(zip(x0, c["orbit_class"]))
    assert cls[0.02] == cls[0.3] == cls[0.48] == 1       # invariant circles around the origin
    assert cls[0.6] == cls[0.66] == 2                     # the period-5 island chain
    assert cls[0.8] == 3                                  # chaotic layer outside it
    assert cls[0.9] == 0                                  # escapes
    assert c["birkhoff_digits"][x0 == 0.8][0] < 5 < c["birkhoff_digits"][x0 == 0.3][0]
    k = dict(zip(x0, c["chain_period"]))
    m = dict(zip(x0, c["chain_winding"]))
    assert (k[0.6], m[0.6]) == (5, 1) and (k[0.48], k[0.3]) == (0, 0)


def test_henon_chain_period_matches_newton(henon_orbits):
    """Independent route: the elliptic periodic orbit found by Newton on the 5th iterate from the
    island centroid has minimal period 5, the period read from the orbit statistics."""
    x0, Q, P, c = henon_orbits
    member, chains = chain_orbits(henon, Q, P, c["chain_period"])
    assert len(chains) == 1
    ch = chains[0]
    assert ch["period"] == ch["minimal_period"] == 5 and abs(ch["trace"]) < 2
    assert set(np.flatnonzero(member == 0)) == set(np.flatnonzero(c["chain_period"] == 5))
    x = ch["points"][0]
    assert minimal_period(henon, x, 20) == 5
    y = x.copy()
    for _ in range(5):
        y = np.array(henon(y[0], y[1]))
    np.testing.assert_allclose(y, x, atol=1e-10)
    # the rotation number of the chain's orbits is exactly 1/5
    np.testing.assert_allclose(c["rotation_number"][c["chain_period"] == 5], 0.2, atol=1e-7)
