"""The isolated-resonance theory on three wells: the paper's quartic, the escape
equation's cubic V = q^2/2 - q^3/3 and an asymmetric quartic polynomial with two barriers.

Independent routes: the slow-flow critical points against finite differences of C; the
unforced (F = 0) analytic basin against the well's own energy criterion; analytic F_cr and
safe basins against the compiled numerics of the same well (bounds measured on these cases and
stated); the first harmonic's shear delta against an FFT of a DOP853 orbit."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import wells
from safebasins.analysis.agreement import iou
from safebasins.numerics import critical_forcing_numeric, escape_chart
from safebasins.theory import (critical_forcing, first_integral, initial_condition, phase_point,
                               safe_basin_boundaries, slow_flow_escapes)

ASYM = [0, 0, 0.5, -0.1, -0.25]     # V = q^2/2 - q^3/10 - q^4/4: barriers at -1.16 (0.1694) and 0.86
WELLS = {"quartic": wells.QUARTIC, "cubic": wells.cubic(), "asymmetric": wells.polynomial(ASYM)}


@pytest.fixture(params=list(WELLS))
def well(request):
    return WELLS[request.param]


def test_unforced_basin_is_the_energy_disk(well):
    """F = 0: the slow flow keeps xi constant, so the safe set is exactly {H0 < xi_max} inside the well."""
    xm = 0.6 * well.barrier_energy
    lo, hi = well.turning_points(xm)
    q = np.linspace(1.2 * float(np.ravel(lo)[0]), 1.2 * float(np.ravel(hi)[0]), 61)
    p = np.linspace(-1.2 * np.sqrt(2 * xm), 1.2 * np.sqrt(2 * xm), 53)
    Q, P = np.meshgrid(q, p, indexing="ij")
    esc = np.asarray(slow_flow_escapes(Q, P, 0.0, 0.9, 0.3, xm, well=well), bool)
    np.testing.assert_array_equal(~esc, well.unforced_safe(Q, P, xm))


def test_critical_points_are_stationary_points_of_C(well):
    """The saddle that sets F_cr (SM mechanism) is a critical point of C(gamma, xi): for an
    asymmetric well at gamma* = -delta(xi*) (mod pi), not at 0 or pi."""
    xm = 0.7 * well.barrier_energy
    Om = np.linspace(0.85, 0.97, 7)
    d = critical_forcing(Om, xm, well=well)
    k = np.flatnonzero(np.isfinite(d["xi_saddle"].values))
    assert k.size >= 2, "expected saddle-type F_cr near the resonance"
    for i in k:
        F, om = float(d["F_SM"][i]), float(Om[i])
        g, x = float(d["gamma_saddle"][i]), float(d["xi_saddle"][i])
        h = 1e-6
        dg = (first_integral(g + h, x, F, om, well=well) - first_integral(g - h, x, F, om, well=well)) / (2 * h)
        dx = (first_integral(g, x + h, F, om, well=well) - first_integral(g, x - h, F, om, well=well)) / (2 * h)
        assert abs(float(dg)) < 1e-7 and abs(float(dx)) < 1e-6, (well.name, om, float(dg), float(dx))
        if well.name != "quartic":
            assert abs(np.sin(g + float(well.harmonic_shift(x)))) < 1e-8


def test_harmonic_shift_against_a_dop853_orbit():
    """q_1 = -i A e^{i delta} of the cubic from an FFT of q(theta) sampled on a DOP853 orbit
    started at the well bottom with p > 0 (theta = 0), uniformly in time."""
    w = WELLS["cubic"]
    E = 0.12
    T = 2 * np.pi / float(w.omega(E))
    n = 256
    sol = solve_ivp(lambda t, y: [y[1], -float(w.dV(y[0]))], (0, T), [0.0, np.sqrt(2 * E)], method="DOP853",
                    rtol=1e-12, atol=1e-13, t_eval=np.arange(n) * T / n)
    q1 = np.fft.fft(sol.y[0])[1] / n
    assert abs(q1 - complex(w.first_harmonic(E))) < 1e-8
    assert abs(np.angle(q1) + np.pi / 2 - float(w.harmonic_shift(E))) < 1e-7


def test_initial_condition_is_on_its_orbit(well):
    xi, g, Psi = 0.4 * well.barrier_energy, 0.25, np.pi
    q0, p0 = initial_condition(xi, g, Psi, well=well)
    assert abs(float(well.H0(q0, p0)) - xi) < 1e-12
    q, p = phase_point(g + Psi, xi, well=well)
    assert (float(q), float(p)) == (float(q0), float(p0))


# measured (xi_max = 0.6 x barrier energy, zero IC, 1000 cycles): relative F_cr error at Omega = 0.8,
# 0.86, 0.9 (below the resonance dip) quartic 1.7/1.2/1.2 %, cubic 2.9/2.6/1.6 %, asymmetric
# 2.6/2.2/1.7 %; at Omega = 1.02, 1.1 (maximum-mechanism branch) 9.1/11.7 %, 6.6/9.8 %, 6.1/8.7 %
FCR_BOUND_BELOW, FCR_BOUND_ABOVE = 0.04, 0.13


def test_fcr_theory_against_numerics_near_resonance(well):
    xm = 0.6 * well.barrier_energy
    Om = np.array([0.8, 0.86, 0.9, 1.02, 1.1])
    a = critical_forcing(Om, xm, well=well)["F_cr"].values
    n = critical_forcing_numeric(Om, xm, cycles=1000, tol=1e-4, F_bracket=(0.0, 0.2), n_scan=41,
                                 well=well)["F_cr"].values
    rel = np.abs(a - n) / n
    assert np.all(rel[:3] < FCR_BOUND_BELOW) and np.all(rel[3:] < FCR_BOUND_ABOVE), (well.name, rel)


# measured (F = 0.004, Omega = 0.9, Psi = pi, 300 cycles, 60 x 50 grid): IoU 0.982 (quartic), 0.994 (cubic),
# 0.998 (asymmetric); bound 0.95
IOU_BOUND = 0.95


def test_small_forcing_basin_against_numerics(well):
    xm = 0.6 * well.barrier_energy
    lo, hi = (float(np.ravel(t)[0]) for t in well.turning_points(xm))
    q = np.linspace(1.05 * lo, 1.05 * hi, 60)
    p = np.linspace(-1.05 * np.sqrt(2 * xm), 1.05 * np.sqrt(2 * xm), 50)
    Q, P = np.meshgrid(q, p, indexing="ij")
    F, Om, Psi = 0.004, 0.9, np.pi
    ana = ~np.asarray(slow_flow_escapes(Q, P, F, Om, Psi, xm, well=well), bool)
    ch = escape_chart(q, p, F, Om, Psi, xi_max=(xm,), cycles=300, well=well)
    num = np.asarray(ch["escape_cycle_energy"].isel(xi_max=0).values > 300)
    assert iou(ana, num) > IOU_BOUND, (well.name, iou(ana, num))
    b = safe_basin_boundaries(F, Om, Psi, xm, well=well, n_points=100)
    assert np.isfinite(b["q0_vertex"].values).sum() > 50


def test_bad_input_names_the_reason():
    cub = WELLS["cubic"]
    with pytest.raises(ValueError, match="barrier energy|1/6|0.1666"):
        critical_forcing([0.9], 0.17, well=cub)
    with pytest.raises(ValueError, match="exact first harmonic"):
        critical_forcing([0.9], 0.1, well=cub, fourier="paper")
    with pytest.raises(ValueError):
        phase_point(0.3, 0.2, well=cub)           # energy above the barrier
    with pytest.raises(ValueError, match="unknown well 'no-such-well'"):
        slow_flow_escapes(0.1, 0.1, 0.01, 0.9, 0.0, 0.1, well="no-such-well")
    # a name or a spec is a well everywhere (the config's forms)
    assert slow_flow_escapes(0.1, 0.1, 0.01, 0.9, 0.0, 0.1, well="cubic") == \
        slow_flow_escapes(0.1, 0.1, 0.01, 0.9, 0.0, 0.1, well=cub)
    with pytest.raises(ValueError, match="V'\\(0\\) = 0"):
        wells.polynomial([0, 0.1, 0.5, 0, -0.25])   # minimum not at q = 0
    with pytest.raises(ValueError, match="no barrier"):
        wells.polynomial([0, 0, 0.5, 0, 0.25])      # nothing can escape


def test_cubic_fcr_with_xi_max_at_the_rounded_barrier():
    """xi_max = 1/6 (the float) lies one ulp below the cubic's rounded barrier energy: it counts as at
    the barrier, where the undamped slow flow has no orbit (refused, naming xi_max, as by the config and
    the command line).  Just below, the SMM search above xi_max has little energy left (it used to
    evaluate the well on the barrier and raise): F_cr is finite and equals the eq (24) endpoint
    branch, with no saddle above xi_max."""
    from safebasins.theory import critical_forcing
    from safebasins.wells import resolve_well

    w = resolve_well("cubic")
    assert 1 / 6 < w.barrier_energy and np.nextafter(1 / 6, 1.0) == w.barrier_energy
    with pytest.raises(ValueError, match="xi_max must lie below the barrier energy 0.16666666666666669 of the cubic"):
        critical_forcing(np.array([0.9]), 1 / 6, well="cubic")
    ds = critical_forcing(np.array([0.6, 0.9, 1.05]), (1 - 2e-12) / 6, well="cubic")
    assert np.isfinite(ds["F_cr"]).all() and np.isnan(ds["F_SMM"]).all()
    assert np.isnan(ds["xi_saddle_smm"]).all()
    assert np.array_equal(ds["F_cr"].values, np.fmax(ds["F_MM_0"], np.fmax(ds["F_MM_pi"], ds["F_SM"])).values)
