"""The minimal fatal shock of damped attractors (safebasins.analysis.fatal_shock).

Independent routes: at F = 0 the attractor is the well bottom, the energy only decays after the
kick, so the escape criterion ``H0 > xi_max`` is met at once or never: the MFS is the distance
from (0, 0) to the level set ``H0 = xi_max`` in closed form (sqrt(2 xi_max) in the energy norm;
a one-variable minimum in a weighted norm), its multipliers have modulus exp(-beta T / 2);
forced, the attractor is a fixed point of a separate DOP853 period map, the MFS agrees with the
LIM of a Cartesian grid (the same quantity at the grid's resolution), the quartic's symmetry
q -> -q, phase -> phase + pi leaves it unchanged, and the shock of the escape equation escapes
(and a slightly smaller one does not) under a separate DOP853 integration with event location.
"""
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins.analysis import minimal_fatal_shock

# Fig 14's forcing with damping beta = 0.1; Thompson's escape equation (cubic well)
QUARTIC = dict(F=0.01, Omega=0.9, damping=0.1)
CUBIC = dict(F=0.055, Omega=0.85, damping=0.1)


def _V(well, q):
    return 0.5 * q ** 2 - (q ** 4 / 4 if well == "quartic" else q ** 3 / 3)


def _dV(well, q):
    return q - (q ** 3 if well == "quartic" else q ** 2)


def _escapes(well, F, Omega, damping, phi, x0, cycles, xi):
    """DOP853 with event location: H0 > xi (or q beyond the barrier q = 1) within `cycles` periods."""
    def H(y):
        return 0.5 * y[1] ** 2 + _V(well, y[0])

    if H(x0) > xi or abs(x0[0]) > 1:
        return True

    def event(t, y):
        return H(y) - xi
    event.terminal, event.direction = True, 1
    T = 2 * np.pi / Omega
    sol = solve_ivp(lambda t, y: [y[1], -_dV(well, y[0]) - damping * y[1] + F * np.sin(Omega * t + phi)],
                    (0.0, cycles * T), x0, method="DOP853", rtol=1e-12, atol=1e-13, events=event, max_step=T / 256)
    return sol.t_events[0].size > 0


@pytest.fixture(scope="module")
def unforced():
    return minimal_fatal_shock(0.0, 0.9, 0.1, phases=(0.0,), cycles=3, weights=(0.25, 1.0), n_refine=2)


@pytest.fixture(scope="module")
def quartic():
    return minimal_fatal_shock(**QUARTIC, phases=(np.pi, 0.0), cycles=20, n_refine=1, n_lim=201)


@pytest.fixture(scope="module")
def cubic():
    return minimal_fatal_shock(**CUBIC, well="cubic", phases=(0.0,), cycles=10, n_refine=1)


def test_unforced_bottom_is_the_closed_form(unforced):
    ds = unforced.isel(attractor=0, phase=0)
    assert unforced.sizes["attractor"] == 1
    assert abs(float(ds.q_attractor)) < 1e-12 and abs(float(ds.p_attractor)) < 1e-12
    T = 2 * np.pi / 0.9
    assert float(unforced.multiplier_modulus[0]) == pytest.approx(np.exp(-0.1 * T / 2), rel=1e-7)
    # energy norm sqrt(p^2 + q^2): H0 = r^2/2 - q^4/4 > 1/4 is nearest along p, at r = sqrt(2 E_b)
    e = ds.sel(norm="energy")
    assert float(e.mfs) == pytest.approx(np.sqrt(0.5), rel=2e-9)
    assert float(e.mfs_safe) <= np.sqrt(0.5) <= float(e.mfs)
    assert abs(float(e.shock_dq)) < 1e-4 and abs(float(e.shock_dp)) == pytest.approx(np.sqrt(0.5), rel=1e-8)
    # weighted (1/4, 1): min of q^2/4 + p^2 on H0 = 1/4, p^2 = 1/2 - q^2 + q^4/2: q^2 = 3/4, 7/32
    wtd = ds.sel(norm="weighted")
    assert float(wtd.mfs) == pytest.approx(np.sqrt(7 / 32), rel=1e-8)
    assert abs(float(wtd.shock_dq)) == pytest.approx(np.sqrt(0.75), rel=1e-3)
    assert float(wtd.escape_cycle) == 0.0
    for n in ("energy", "weighted"):
        d = ds.sel(norm=n)
        assert float(d.mfs) <= float(d.mfs_grid)
        assert float(d.lim) - float(unforced.lim_spacing.sel(norm=n)) <= float(d.mfs) <= float(d.lim)


def test_unforced_mfs_of_a_lower_threshold():
    ds = minimal_fatal_shock(0.0, 1.1, 0.2, phases=(1.0,), xi_max=0.15, cycles=2, n_refine=1, n_lim=51)
    assert float(ds.mfs.squeeze()) == pytest.approx(np.sqrt(0.3), rel=2e-9)
    assert ds.attrs["xi_max"] == 0.15 and ds.attrs["damping"] == 0.2


def test_forced_attractor_is_a_fixed_point_of_the_period_map(quartic):
    T = 2 * np.pi / QUARTIC["Omega"]
    for k, phi in enumerate(quartic.phase.values):
        x = np.array([float(quartic.q_attractor[0, k]), float(quartic.p_attractor[0, k])])
        sol = solve_ivp(lambda t, y: [y[1], -_dV("quartic", y[0]) - 0.1 * y[1] + 0.01 * np.sin(0.9 * t + phi)],
                        (0.0, T), x, method="DOP853", rtol=1e-12, atol=1e-14)
        assert np.max(np.abs(sol.y[:, -1] - x)) < 1e-9
    assert float(quartic.multiplier_modulus[0]) < 1


def test_mfs_is_the_lim_at_the_grid_resolution(quartic, cubic):
    for ds in (quartic, cubic):
        h = float(ds.lim_spacing.sel(norm="energy"))
        mfs, lim, grid = (ds[v].sel(norm="energy").values for v in ("mfs", "lim", "mfs_grid"))
        assert np.all(lim - h <= mfs) and np.all(mfs <= lim * (1 + 1e-9))
        assert np.all(mfs <= grid)
        assert np.all(np.isfinite(ds.escape_cycle.values))       # the MFS shock itself escapes


def test_quartic_symmetry(quartic):
    m = quartic.mfs.sel(norm="energy").values[0]          # phases pi and 0: q -> -q, t -> t + T / 2
    assert m[0] == pytest.approx(m[1], rel=1e-7)
    assert float(quartic.q_attractor[0, 0]) == pytest.approx(-float(quartic.q_attractor[0, 1]), rel=1e-9)


def test_shock_escapes_under_dop853(cubic, quartic):
    for well, pars, ds in (("cubic", CUBIC, cubic), ("quartic", QUARTIC, quartic)):
        for a in ds.attractor.values:
            d = ds.isel(attractor=a, phase=0).sel(norm="energy")
            x_a = np.array([float(d.q_attractor), float(d.p_attractor)])
            shock = np.array([float(d.shock_dq), float(d.shock_dp)])
            args = (well, pars["F"], pars["Omega"], pars["damping"], float(d.phase), ds.attrs["cycles"],
                    ds.attrs["xi_max"])
            assert _escapes(*args[:5], x_a + shock * (1 + 1e-6), *args[5:])
            assert not _escapes(*args[:5], x_a + shock * (1 - 1e-3), *args[5:])
    # the escape equation has a resonant and a non-resonant response; the shocks escape in flight
    assert cubic.sizes["attractor"] == 2
    assert np.all(cubic.escape_cycle.values > 0)
    assert cubic.response_amplitude.values[0] < cubic.response_amplitude.values[1]


def test_quiet(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        minimal_fatal_shock(0.02, 0.9, 0.05, phases=(0.0, 1.0), cycles=3, weights=(2.0, 1.0), n_directions=16,
                            n_radii=12, n_refine=1, n_lim=21)
    out = capsys.readouterr()
    assert out.out == "" and out.err == "", out


@pytest.mark.parametrize("kwargs, name", [
    (dict(damping=0.0), "damping"), (dict(cycles=-1), "cycles"), (dict(weights=(0.0, 1.0)), "weights"),
    (dict(weights=(1.0,)), "weights"), (dict(n_lim=50), "n_lim"), (dict(phases=np.nan), "phases"),
    (dict(xi_max=0.3), "xi_max"), (dict(tol=0.5), "tol"), (dict(radius_max=0.01, cycles=2), "radius_max"),
])
def test_bad_input_names_the_argument(kwargs, name):
    base = dict(F=0.01, Omega=0.9, damping=0.1)
    base.update(kwargs)
    with pytest.raises(ValueError, match=name):
        minimal_fatal_shock(**base)
