"""NumericWell: action-angle data of any well by quadrature (paper Sec. 2.1 generalised).

References: the quartic's closed forms (theory.action_angle, Jacobi elliptic functions), the
pendulum's (complete elliptic integrals), and for the asymmetric quartic scipy quad (action) and
DOP853 orbits (period, first harmonic, angles).  Stated accuracy: <= 1e-12 relative for
J, omega, |q_1| for E <= 0.249 (quartic), <= 1e-11 at 0.2499, <= 1e-9 down to E_b - E = 1e-12.
"""
import time

import numpy as np
import pytest
from scipy import special

from safebasins.theory import action_angle as aa
from safebasins.wells.numeric import NumericWell
from tests.wells.reference_orbits import angle_diff, assert_matches_orbit, rel


def quartic_V(q):
    return q * q * (0.5 - 0.25 * q * q)


def quartic_dV(q):
    return q * (1.0 - q * q)


def asym_V(q):                       # q^2/2 + 0.1 q^3 - q^4/4
    return q * q * (0.5 + q * (0.1 - 0.25 * q))


def asym_dV(q):
    return q * (1.0 + q * (0.3 - q))


ASYM_BARRIERS = ((0.3 - np.sqrt(4.09)) / 2, (0.3 + np.sqrt(4.09)) / 2)


@pytest.fixture(scope="module")
def quartic():
    return NumericWell(quartic_V, quartic_dV, name="quartic")


@pytest.fixture(scope="module")
def asym():
    return NumericWell(asym_V, asym_dV, name="asymmetric")


@pytest.fixture(scope="module")
def pendulum():
    return NumericWell(lambda q: 2.0 * np.sin(0.5 * q) ** 2, np.sin, name="pendulum")


# ----------------------------------------------------------------------------- quartic
def test_quartic_well_data(quartic):
    assert quartic.barriers == pytest.approx((-1.0, 1.0), abs=1e-15)
    assert quartic.barrier_energy == pytest.approx(0.25, abs=1e-16)
    assert quartic.omega0 == pytest.approx(1.0, rel=1e-8)
    E = np.linspace(0.0, 0.25, 11)
    qm, qp = quartic.turning_points(E)
    ref = np.sqrt(1 - np.sqrt(1 - 4 * E))                       # eq (4)
    assert np.max(np.abs(qp - ref)) <= 1e-15 and np.max(np.abs(qm + ref)) <= 1e-15
    assert qp[-1] == 1.0 and qm[-1] == -1.0 and qp[0] == 0.0      # separatrix, well bottom


def test_quartic_against_closed_form(quartic):
    E = np.concatenate([np.geomspace(1e-12, 1e-3, 40), np.linspace(1e-3, 0.249, 2000)])
    assert rel(quartic.J(E), aa.J(E)) <= 1e-12
    assert rel(quartic.omega(E), aa.omega(E)) <= 1e-12
    assert rel(quartic.period(E), 2 * np.pi / aa.omega(E)) <= 1e-12
    assert rel(quartic.dJ_dE(E), aa.dJ_dxi(E)) <= 1e-12
    G = aa.G(E, fourier="exact")
    assert rel(quartic.harmonic_amplitude(E), G) <= 1e-12
    # convention of base.Well: q_1 = -i G_exact for the symmetric quartic
    assert np.max(np.abs(quartic.first_harmonic(E) + 1j * G) / G) <= 1e-12
    assert np.max(np.abs(quartic.harmonic_phase(E) + np.pi / 2)) <= 1e-12
    assert rel(quartic.harmonic_amplitude_derivative(E), aa.dG_dxi(E, fourier="exact")) <= 1e-10
    assert np.max(np.abs(quartic.harmonic_phase_derivative(E[E > 1e-4]))) <= 1e-9
    # the well bottom
    assert quartic.J(0.0) == 0.0 and quartic.harmonic_amplitude(0.0) == 0.0
    assert quartic.omega(0.0) == pytest.approx(1.0, abs=1e-13)


@pytest.mark.parametrize("s, bound", [(1e-4, 1e-11), (1e-6, 1e-11), (1e-9, 1e-10), (1e-12, 1e-9)])
def test_quartic_near_separatrix(quartic, s, bound):
    E = 0.25 - s * np.linspace(1.0, 3.0, 7)      # E = 0.2499 for the first entry
    assert rel(quartic.J(E), aa.J(E)) <= bound
    assert rel(quartic.omega(E), aa.omega(E)) <= bound
    assert rel(quartic.harmonic_amplitude(E), aa.G(E, fourier="exact")) <= bound


def test_quartic_angles_against_closed_form(quartic):
    rng = np.random.default_rng(1)
    theta = rng.uniform(0, 2 * np.pi, 3000)
    E = rng.uniform(0, 0.249, 3000)
    q0, p0 = aa.phase_point(theta, E)
    q, p = quartic.phase_point(theta, E)
    assert np.max(np.abs(q - q0)) <= 1e-12 and np.max(np.abs(p - p0)) <= 1e-12
    th, xi = quartic.angle_energy(q0, p0)
    th0, xi0 = aa.angle_energy(q0, p0)
    assert angle_diff(th, th0) <= 1e-11
    assert np.max(np.abs(xi - xi0)) <= 1e-16
    assert np.all((th >= 0) & (th < 2 * np.pi))
    # round trips
    q2, p2 = quartic.phase_point(th, xi)
    assert np.max(np.abs(q2 - q0)) <= 1e-12 and np.max(np.abs(p2 - p0)) <= 1e-12
    assert angle_diff(quartic.angle_energy(q, p)[0], theta) <= 1e-11


def test_quartic_angles_at_02499(quartic):
    theta = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    q0, p0 = aa.phase_point(theta, 0.2499)
    q, p = quartic.phase_point(theta, 0.2499)
    assert np.max(np.abs(q - q0)) <= 1e-11 and np.max(np.abs(p - p0)) <= 1e-11
    assert angle_diff(quartic.angle_energy(q0, p0)[0], aa.angle_energy(q0, p0)[0]) <= 1e-10


def test_angles_at_the_well_bottom(quartic):
    th, E = quartic.angle_energy([0.0], [0.0])
    assert th[0] == 0.0 and E[0] == 0.0
    q, p = quartic.phase_point([0.3, 2.0], 0.0)
    assert np.all(q == 0.0) and np.all(p == 0.0)


# ----------------------------------------------------------------------------- pendulum
def test_pendulum_against_elliptic_closed_form(pendulum):
    assert pendulum.barriers == pytest.approx((-np.pi, np.pi), abs=1e-14)
    assert pendulum.barrier_energy == pytest.approx(2.0, abs=1e-15)
    E = np.concatenate([np.geomspace(1e-8, 1e-2, 10), np.linspace(0.01, 1.998, 200)])
    m = E / 2.0                      # sin(q/2) = k sn(t), k^2 = E/2
    K = special.ellipk(m)
    assert rel(pendulum.omega(E), np.pi / (2 * K)) <= 1e-12
    # J = (8/pi) (E(m) - (1 - m) K(m)) = (8/pi) m (K - R_D(0, 1 - m, 1)/3)  (no cancellation)
    J_ref = 8 / np.pi * m * (K - special.elliprd(0.0, 1 - m, 1.0) / 3)
    assert rel(pendulum.J(E), J_ref) <= 1e-12


# ----------------------------------------------------------------------------- asymmetric quartic
def test_asymmetric_well_data(asym):
    assert asym.barriers == pytest.approx(ASYM_BARRIERS, abs=1e-15)
    assert asym.barrier_energy == pytest.approx(asym_V(ASYM_BARRIERS[0]), abs=1e-16)
    assert asym_V(ASYM_BARRIERS[1]) > asym.barrier_energy + 0.2      # two barriers, different heights


@pytest.mark.parametrize("frac", [0.01, 0.3, 0.7, 0.95, 0.999])
def test_asymmetric_against_quad_and_dop853(asym, frac):
    orbit = assert_matches_orbit(asym, frac * asym.barrier_energy, 96)
    assert abs(asym.harmonic_phase(frac * asym.barrier_energy) - np.angle(orbit.q1)) <= 1e-10


def test_asymmetric_first_harmonic_is_complex(asym):
    E = asym.barrier_energy * np.concatenate([np.linspace(0.001, 0.9, 400), 1 - np.geomspace(0.1, 1e-9, 400)])
    phase = asym.harmonic_phase(E)
    assert np.all(np.abs(np.diff(phase)) < 0.05)                 # continuous in E (no 2 pi jumps)
    assert np.all((phase > -np.pi) & (phase < 0))
    assert phase.max() - phase.min() > 0.5                        # not the constant -pi/2
    q1 = asym.first_harmonic(E)
    assert np.max(np.abs(q1.real)) > 0.05
    # derivatives against central differences of the interpolants
    h = 1e-6
    Ei = asym.barrier_energy * np.linspace(0.01, 0.99, 300)
    fd = (asym.harmonic_phase(Ei + h) - asym.harmonic_phase(Ei - h)) / (2 * h)
    assert np.max(np.abs(asym.harmonic_phase_derivative(Ei) - fd)) <= 1e-6 * np.max(np.abs(fd))
    fd = (asym.harmonic_amplitude(Ei + h) - asym.harmonic_amplitude(Ei - h)) / (2 * h)
    assert rel(asym.harmonic_amplitude_derivative(Ei), fd) <= 1e-6


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("E", [-1e-3, 0.25, 0.3, np.nan, [0.1, np.nan]])
def test_energy_outside_the_well(quartic, E):
    for f in (quartic.J, quartic.omega, quartic.period, quartic.first_harmonic, quartic.harmonic_phase):
        with pytest.raises(ValueError, match="E"):
            f(E)
    with pytest.raises(ValueError, match="E"):
        quartic.phase_point(0.0, E)


def test_turning_points_domain(quartic):
    assert quartic.turning_points(0.25)[1] == pytest.approx(1.0, abs=1e-15)
    with pytest.raises(ValueError, match="E"):
        quartic.turning_points(0.2500001)


def test_derivatives_need_positive_energy(quartic):
    with pytest.raises(ValueError, match="E must be > 0"):
        quartic.harmonic_amplitude_derivative(0.0)
    with pytest.raises(ValueError, match="E must be > 0"):
        quartic.harmonic_phase_derivative([0.1, 0.0])


@pytest.mark.parametrize("q, p, name", [(1.0, 0.0, "q"), (-1.2, 0.0, "q"), (0.5, 0.6, "p"),
                                        (np.nan, 0.0, "q"), (0.0, np.nan, "p"), (0.1, np.inf, "p")])
def test_point_outside_the_well(quartic, q, p, name):
    with pytest.raises(ValueError, match=name):
        quartic.angle_energy(q, p)


def test_theta_must_be_finite(quartic):
    with pytest.raises(ValueError, match="theta"):
        quartic.phase_point(np.inf, 0.1)


@pytest.mark.parametrize("V, dV, match", [
    (lambda q: quartic_V(q) + 0.1, quartic_dV, r"V\(0\)"),
    (lambda q: quartic_V(q) + 0.05 * q, lambda q: quartic_dV(q) + 0.05, r"V'\(0\)"),
    (lambda q: -quartic_V(q), lambda q: -quartic_dV(q), r"V''\(0\)"),
    (lambda q: q ** 4 / 4 - q ** 6 / 6, lambda q: q ** 3 - q ** 5, r"V''\(0\)"),
    (lambda q: 0.5 * q * q, lambda q: q, "closed: no barrier"),
    (lambda q: q * q * (0.5 + 0.25 * q * q), lambda q: q * (1 + q * q), "closed: no barrier"),
    (quartic_V, lambda q: q - 0.9 * q ** 3, "dV does not match"),
    (1.0, quartic_dV, "V must be a callable"),
])
def test_bad_potentials(V, dV, match):
    with pytest.raises(ValueError, match=match):
        NumericWell(V, dV)


def test_two_open_sides_with_different_limits():
    # V = tanh^2 q (1 + 0.6 tanh q) / 2: limits 0.2 (left, the escape energy) and 0.8 (right, above
    # it: that side closes where V = 0.2)
    V = lambda q: 0.5 * np.tanh(q) ** 2 * (1 + 0.6 * np.tanh(q))
    dV = lambda q: 0.5 * np.tanh(q) * (2 + 1.8 * np.tanh(q)) / np.cosh(q) ** 2
    w = NumericWell(V, dV)
    assert w.asymptotes == pytest.approx((0.2, 0.8), rel=1e-15) and w.barrier_energy == w.asymptotes[0]
    assert w.open_at_infinity and w.barriers == (-np.inf, np.inf)
    assert w.limits[0] == -np.inf and 0.6 < w.limits[1] < 0.62 and V(w.limits[1]) > 0.2
    E = 0.2 - 0.2 * np.geomspace(0.5, 1e-15, 30)
    assert np.all(np.diff(w.omega(E)) < 0) and w.omega(E[-1]) < 1e-6    # omega -> 0 at the limit


def test_side_neither_closing_nor_converging():
    # left: V -> 0.1 (below E_b = 1/6) like 1/log|q|: not converged within float range
    L = lambda q: np.logaddexp(0.0, np.log(5.0) + 2 * np.log(np.abs(q)))
    V = lambda q: np.where(q < 0, 0.1 * (1 - 1 / (1 + L(q))), q * q * (0.5 - q / 3))
    dV = lambda q: np.where(q < 0, q / (1 + 5 * q * q) / (1 + L(q)) ** 2, q * (1 - q))
    with np.errstate(divide="ignore"), pytest.raises(ValueError, match="neither closes nor is open at infinity"):
        NumericWell(V, dV)


def test_barriers_checked():
    assert NumericWell(quartic_V, quartic_dV, barriers=(-1.0, 1.0)).barriers == pytest.approx((-1, 1))
    with pytest.raises(ValueError, match="barriers: the right barrier"):
        NumericWell(quartic_V, quartic_dV, barriers=(-1.0, 0.9))
    with pytest.raises(ValueError, match="barriers must satisfy"):
        NumericWell(quartic_V, quartic_dV, barriers=(1.0, -1.0))
    with pytest.raises(ValueError, match="search_bound"):
        NumericWell(quartic_V, quartic_dV, search_bound=-1.0)


def test_interior_equilibrium_rejected():
    # V' = q (q - 1)^2 (2 - q): V' vanishes at q = 1 without changing sign
    dV = lambda q: q * (q - 1) ** 2 * (2 - q)
    V = lambda q: q ** 2 - 5 * q ** 3 / 3 + q ** 4 - q ** 5 / 5
    with pytest.raises(ValueError, match="V' vanishes at q ~ 0.99999"):
        NumericWell(V, dV)


# ----------------------------------------------------------------------------- speed
def _best(f, n=3):
    """Best of n CPU times of this process (wall time on a shared machine measures the others)."""
    best = np.inf
    for _ in range(n):
        t0 = time.process_time()
        f()
        best = min(best, time.process_time() - t0)
    return best


def test_speed(quartic):
    """Budgets: construction < 2 s, 1e5 energies < 50 ms per quantity, angle_energy on a
    300 x 300 grid < 0.5 s."""
    assert _best(lambda: NumericWell(quartic_V, quartic_dV), 1) < 2.0
    E = np.random.default_rng(0).uniform(0, 0.2499, 100_000)
    for f in (quartic.J, quartic.omega, quartic.harmonic_amplitude, quartic.harmonic_phase,
              quartic.first_harmonic):
        assert _best(lambda: f(E)) < 0.05, f.__name__
    q, p = np.meshgrid(np.linspace(-0.7, 0.7, 300), np.linspace(-0.35, 0.35, 300))  # all inside
    assert _best(lambda: quartic.angle_energy(q, p), 2) < 0.5
