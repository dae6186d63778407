"""Attractors followed across a parameter (safebasins.analysis.continue_attractors).

Independent routes: the quartic's branches against its closed-form harmonic balance and the damped
slow flow's steady responses (theory.responses), the folds against the slow flow's saddle-node
points, errors shrinking with F; every fixed point against a scipy DOP853 period map of the
closed-form force, the located folds and period doubling against det(D P -+ I) of that map's
central-difference Jacobian, and the period-2 orbit past the doubling against a long run; the
multipliers' product against Liouville's exp(-beta T); long DOP853 runs from grid nodes inside the
escape equation's hysteresis band against the attractors reported and the basin labels; the LIM
radius and the losses to escape against direct counts on the labels.
"""
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import safebasins.analysis.continuation as continuation
from safebasins.analysis import continue_attractors
from safebasins.analysis.arclength import EVENT_KINDS
from safebasins.theory.responses import steady_responses
from safebasins.wells import resolve_well

QUARTIC, CUBIC = resolve_well(None), resolve_well("cubic")
FORCE = {"quartic": lambda q: q - q ** 3, "cubic": lambda q: q - q * q}     # V'(q), written out
OMEGA, BETA = 0.85, 0.1                    # the escape equation of the damped study
F_BAND = (0.045, 0.055, 0.065, 0.075)      # its hysteresis band is about 0.047 < F < 0.069
SMALL_F = (0.01, 0.0025)                   # the quartic with beta = F


@pytest.fixture(scope="module")
def escape():
    return continue_attractors(OMEGA, F_BAND, BETA, "cubic", n_grid=31, step_max=0.15)


@pytest.fixture(scope="module")
def small():
    """The quartic near its lower fold, Omega over [1 - 2 d, 1 - d / 2], d the slow flow's fold detuning."""
    out = {}
    for F in SMALL_F:
        fold = float(steady_responses([0.95], F, F).Omega_fold.values[-1])
        d = 1.0 - fold
        out[F] = (fold, continue_attractors(np.linspace(1 - 2 * d, 1 - 0.5 * d, 3), F, F, n_grid=9, step_max=0.2))
    return out


def _kinds(ds):
    return [EVENT_KINDS[k] for k in ds["event_kind"].values]


def _period_map(force, F, Omega, beta, x):
    """One trajectory over one period, scipy DOP853 at rtol 1e-12, the force in closed form."""
    def f(t, y):
        return [y[1], -force(y[0]) - beta * y[1] + F * np.sin(Omega * t)]
    return solve_ivp(f, (0.0, 2 * np.pi / Omega), x, method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]


def test_folds_match_the_slow_flow_saddle_nodes(small):
    err = []
    for F in SMALL_F:
        fold, ds = small[F]
        folds = ds["event_parameter"].values[np.array(_kinds(ds)) == "fold"]
        assert folds.size == 1
        err.append(abs(folds[0] - fold))
        assert err[-1] < 0.2 * F ** 1.5                 # measured 0.12 F^1.5
        # the multiplier through +1 at the located fold
        mu = ds["event_multiplier_real"].values[np.array(_kinds(ds)) == "fold"][0]
        assert np.min(np.abs(mu - 1.0)) < 1e-6
    assert err[1] < err[0] / 4                          # F / 4: measured / 7.5


def test_branches_match_harmonic_balance_and_the_slow_flow(small):
    hb, sf = [], []
    for F in SMALL_F:
        _, ds = small[F]
        Om, a, lag = ds["parameter"].values, ds["harmonic_amplitude"].values, ds["phase_lag"].values
        # q = a sin(Omega t - lag): a (1 - Omega^2) - 3 a^3 / 4 = F cos(lag), beta Omega a = F sin(lag)
        res = np.hypot((1 - Om ** 2) * a - 0.75 * a ** 3 - F * np.cos(lag), F * Om * a - F * np.sin(lag))
        hb.append(np.max(res) / F)
        assert hb[-1] < 1.0 * F ** 0.5                  # measured 0.69 F^0.5 and 0.53 F^0.5
        # the slow flow's fixed points at the same Omega: averaged energy and slow phase
        theta, xi = QUARTIC.angle_energy(ds["q"].values, ds["p"].values)
        sr = steady_responses(Om, F, F)
        x_sf = np.where(sr["xi"].values < 0.2, sr["xi"].values, np.nan)
        j = np.nanargmin(np.abs(x_sf - xi[:, None]), axis=1)
        k = np.arange(Om.size)
        rel = np.abs(x_sf[k, j] - xi) / x_sf[k, j]
        dg = np.abs(np.angle(np.exp(1j * (theta - sr["gamma"].values[k, j]))))
        sf.append(np.max(rel))
        assert sf[-1] < 1.5 * F ** 0.5 and np.max(dg) < 2.0 * F     # measured 1.1 F^0.5, 1.4 F
        # three branches: the non-resonant and the resonant attractors and the saddle between them
        assert ds.sizes["attractor"] == 2
        assert (~ds["stable"].values).sum() > 3
    assert hb[1] < 0.6 * hb[0] and sf[1] < 0.7 * sf[0]


def test_fixed_points_of_an_independent_period_map_and_liouville(escape, small):
    for ds, well, F, Om, beta in [(escape, "cubic", escape["parameter"].values, OMEGA, BETA)] + [
            (small[F][1], "quartic", F, small[F][1]["parameter"].values, F) for F in SMALL_F[:1]]:
        n = ds.sizes["point"]
        F_, Om_ = np.broadcast_to(F, n), np.broadcast_to(Om, n)
        for i in range(0, n, 3):
            x = np.array([ds["q"].values[i], ds["p"].values[i]])
            y = _period_map(FORCE[well], F_[i], Om_[i], beta, x)
            assert np.max(np.abs(y - x)) < 1e-8
        mu = ds["multiplier_real"].values + 1j * ds["multiplier_imag"].values
        liouville = np.abs(mu[:, 0] * mu[:, 1] - np.exp(-beta * 2 * np.pi / Om_))
        assert np.max(liouville) < 1e-8                 # measured < 1e-9
        assert np.isfinite(ds["q"].values).all() and np.isfinite(mu).all()
        assert np.array_equal(ds["stable"].values, np.max(np.abs(mu), axis=1) < 1)


def test_escape_equation_branches_and_events(escape):
    ds = escape
    kinds = _kinds(ds)
    assert kinds.count("fold") == 2 and kinds.count("range_end") == 2 and len(kinds) == 4
    folds = np.sort(ds["event_parameter"].values[np.array(kinds) == "fold"])
    assert 0.046 < folds[0] < 0.048 and 0.068 < folds[1] < 0.070
    for i in np.flatnonzero(np.array(kinds) == "fold"):      # an independent Jacobian has a multiplier +1
        x = np.array([ds["event_q"].values[i], ds["event_p"].values[i]])
        J = _jacobian(FORCE["cubic"], float(ds["event_parameter"].values[i]), OMEGA, BETA, x)
        assert abs(np.linalg.det(J - np.eye(2))) < 1e-5
    # two attractors: the non-resonant one ends at the upper fold, the resonant one starts at the lower
    assert ds.sizes["attractor"] == 2
    ends = ds["attractor_end_parameter"].values
    end_kind = np.array(EVENT_KINDS)[ds["attractor_end_kind"].values]
    assert ends[0, 1] == folds[1] and end_kind[0].tolist() == ["range_end", "fold"]
    assert ends[1, 0] == folds[0] and end_kind[1].tolist() == ["fold", "range_end"]
    assert ds["attractor_class"].values[0] == 0                       # lag < pi/2 throughout
    inside = (ds["F"].values > folds[0]) & (ds["F"].values < folds[1])
    assert np.array_equal(ds["exists"].values.all(axis=1), inside)
    assert ds["matched"].values[ds["exists"].values].all()


def _long_runs(F, q0, p0, cycles):
    """DOP853 runs of the grid nodes over ``cycles`` periods: escaped (H0 above the barrier energy at a
    sample, 64 per period, or q past 1.5) or the final state."""
    n = q0.size
    E_b = 1.0 / 6.0

    def f(t, y):
        q, p = y[:n], y[n:]
        frozen = q > 1.5
        dq = np.where(frozen, 0.0, p)
        dp = np.where(frozen, 0.0, -FORCE["cubic"](q) - BETA * p + F * np.sin(OMEGA * t))
        return np.concatenate([dq, dp])
    T = 2 * np.pi / OMEGA
    t = np.linspace(0.0, cycles * T, 64 * cycles + 1)
    sol = solve_ivp(f, (0.0, cycles * T), np.concatenate([q0, p0]), method="DOP853", rtol=1e-10, atol=1e-12,
                    t_eval=t)
    q, p = sol.y[:n], sol.y[n:]
    escaped = ((0.5 * p * p + 0.5 * q * q - q ** 3 / 3 > E_b) | (q > 1.0)).any(axis=1)
    last = np.stack([q[:, -1], p[:, -1]], axis=1)
    period = np.max(np.abs(last - np.stack([q[:, -65], p[:, -65]], axis=1)), axis=1)
    return escaped, last, period


@pytest.mark.parametrize("k", [1, 2])                    # F = 0.055 and 0.065: two attractors each
def test_long_runs_end_on_the_attractors_and_in_their_basins(escape, k):
    ds = escape.isel(F=k)
    F = float(ds["F"])
    att = np.stack([ds["q_attractor"].values, ds["p_attractor"].values], axis=1)
    assert np.isfinite(att).all() and att.shape == (2, 2)
    i = np.arange(2, 31, 6)                             # 5 x 5 nodes of the labels' grid
    I, J = np.meshgrid(i, i, indexing="ij")
    q0, p0 = ds["q0"].values[I.ravel()], ds["p0"].values[J.ravel()]
    escaped, last, period = _long_runs(F, q0, p0, 70)   # transients ~ exp(-beta T 70 / 2) ~ 1e-11
    d = np.max(np.abs(last[:, None, :] - att[None, :, :]), axis=2)
    fate = np.where(escaped, 0, 1 + np.argmin(d, axis=1))
    assert np.all(np.min(d[~escaped], axis=1) < 1e-6) and np.all(period[~escaped] < 1e-6)
    assert set(fate[~escaped]) == {1, 2}                # both reported attractors are reached
    labels = ds["basin"].values[I.ravel(), J.ravel()]
    assert (labels == fate).sum() >= 23                 # boundary nodes may differ (fixed-step engine)


def test_basin_measures_are_those_of_the_labels(escape):
    ds = escape
    q0, p0 = ds["q0"].values, ds["p0"].values
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    dq, dp = q0[1] - q0[0], p0[1] - p0[0]
    for k in range(ds.sizes["F"]):
        lab = ds["basin"].values[k]
        for a in range(ds.sizes["attractor"]):
            if not ds["exists"].values[k, a]:
                assert np.isnan(ds["GIM"].values[k, a]) and np.isnan(ds["LIM"].values[k, a])
                continue
            mask = lab == a + 1
            assert ds["basin_nodes"].values[k, a] == mask.sum()
            assert ds["basin_fraction"].values[k, a] == pytest.approx(mask.mean())
            # LIM radius: distance from the attractor to the nearest node outside its basin or the grid
            qa, pa = ds["q_attractor"].values[k, a], ds["p_attractor"].values[k, a]
            r = min(np.min(np.hypot(Q[~mask] - qa, P[~mask] - pa)),
                    qa - q0[0] + dq, q0[-1] + dq - qa, pa - p0[0] + dp, p0[-1] + dp - pa)
            assert ds["lim_radius"].values[k, a] == pytest.approx(r, rel=1e-12)
        gims = np.nansum(ds["GIM"].values[k])
        assert gims <= ds["GIM_safe"].values[k] + 1e-12
        if not (lab == -1).any():
            assert gims == pytest.approx(ds["GIM_safe"].values[k], rel=1e-12)
    # loss to escape: nodes of a basin at one F that escape at the next, counted directly
    unforced = np.sum(CUBIC.unforced_safe(Q, P, 1.0 / 6.0))
    lab = ds["basin"].values
    for a in range(ds.sizes["attractor"]):
        lost = ((lab[:-1] == a + 1) & (lab[1:] == 0)).sum(axis=(1, 2)) / unforced
        np.testing.assert_allclose(ds["lost_to_escape"].values[1:, a], lost, rtol=1e-12)
        k = 1 + int(np.argmax(lost))
        assert (ds["cliff_low"].values[a], ds["cliff_high"].values[a]) == (ds["F"].values[k - 1], ds["F"].values[k])
    assert np.isnan(ds["lost_to_escape"].values[0]).all()
    lost_safe = ((lab[:-1] != 0) & (lab[1:] == 0)).sum(axis=(1, 2)) / unforced
    np.testing.assert_allclose(ds["lost_safe"].values[1:], lost_safe, rtol=1e-12)
    k = 1 + int(np.argmax(lost_safe))
    assert float(ds["safe_cliff_drop"]) == pytest.approx(lost_safe[k - 1], rel=1e-12)
    assert float(ds["safe_cliff_high"]) == ds["F"].values[k]


def test_no_attractor_in_the_well():
    # past the escape equation's last attractor every IC escapes: no branch, the basins all escape
    ds = continue_attractors(OMEGA, (0.1, 0.11), BETA, "cubic", n_grid=9)
    assert ds.sizes["point"] == ds.sizes["attractor"] == ds.sizes["event"] == 0
    assert np.array_equal(ds["GIM_safe"].values, [0.0, 0.0]) and (ds["basin"].values == 0).all()
    assert np.array_equal(ds["n_grid_attractors"].values, [0, 0]) and np.isnan(ds["safe_cliff_low"])


def _jacobian(force, F, Omega, beta, x, h=1e-6):
    """D P by central differences of the independent period map."""
    cols = [(_period_map(force, F, Omega, beta, x + h * e) - _period_map(force, F, Omega, beta, x - h * e)) / (2 * h)
            for e in np.eye(2)]
    return np.stack(cols, axis=1)


def test_period_doubling_on_the_resonant_branch(capsys):
    # the escape equation at beta = 0.05, Omega = 0.8: the resonant attractor flips near F = 0.0649
    with warnings.catch_warnings():
        warnings.simplefilter("error")                  # quiet: no warning, no print
        ds = continue_attractors(0.8, (0.05, 0.06, 0.07), 0.05, "cubic", n_grid=21, step_max=0.3)
    assert capsys.readouterr() == ("", "")
    kinds = np.array(_kinds(ds))
    assert kinds.tolist().count("period_doubling") == 1 and ds["event_located"].values.all()
    i = int(np.flatnonzero(kinds == "period_doubling")[0])
    F_pd = float(ds["event_parameter"].values[i])
    assert 0.064 < F_pd < 0.066
    # an independent Jacobian at the located point has a multiplier -1: det(D P + I) = 0
    x = np.array([ds["event_q"].values[i], ds["event_p"].values[i]])
    J = _jacobian(FORCE["cubic"], F_pd, 0.8, 0.05, x)
    assert abs(np.linalg.det(J + np.eye(2))) < 1e-5
    a = [k for k in range(ds.sizes["attractor"]) if EVENT_KINDS[int(ds["attractor_end_kind"].values[k, 1])]
         == "period_doubling"]
    assert len(a) == 1 and ds["attractor_end_parameter"].values[a[0], 1] == F_pd
    # the flip saddle's branch leaves the well: it ends on the located point where its largest H0 is E_b
    left = np.flatnonzero(kinds == "left_well")
    assert left.size == 1 and 0.065 < ds["event_parameter"].values[left[0]] < 0.066
    c = ds["curve"].values == ds["event_curve"].values[left[0]]
    e = ds["energy_max"].values
    assert np.all(e <= (1 + 1e-6) / 6) and np.isfinite(e).all()
    assert e[c][-1] == pytest.approx(1 / 6, rel=1e-6) and not ds["stable"].values[c][-1]
    assert ds["parameter"].values[c][-1] == ds["event_parameter"].values[left[0]]
    # just past it, a long run from the flip saddle settles on a period-2 orbit about it
    F = F_pd + 4e-4
    y = x + np.array([1e-3, 0.0])
    T = 2 * np.pi / 0.8
    sol = solve_ivp(lambda t, z: [z[1], -FORCE["cubic"](z[0]) - 0.05 * z[1] + F * np.sin(0.8 * t)], (0, 200 * T), y,
                    method="DOP853", rtol=1e-10, atol=1e-12, t_eval=T * np.arange(198, 201))
    X = sol.y.T
    assert np.max(np.abs(X[2] - X[0])) < 1e-8 and np.max(np.abs(X[2] - X[1])) > 0.05


@pytest.mark.parametrize("kwargs, words", [
    (dict(Omega=0.85, F=0.05), "exactly one must be a 1-D sweep"),
    (dict(Omega=[0.8, 0.9], F=[0.05, 0.06]), "exactly one must be a 1-D sweep"),
    (dict(Omega=0.85, F=[0.06, 0.05]), "F must be a sweep of at least 2 strictly increasing"),
    (dict(Omega=[0.9], F=0.05), "Omega must be a sweep of at least 2"),
    (dict(Omega=[0.0, 0.9], F=0.05), "Omega"),
    (dict(Omega=0.85, F=[-0.01, 0.05]), "F"),
    (dict(damping=0.0), "damping must be > 0"),
    (dict(damping=np.nan), "damping"),
    (dict(Psi=np.nan), "Psi"),
    (dict(xi_max=0.3), "xi_max"),
    (dict(n_grid=5), "n_grid"),
    (dict(n_iter=0), "n_iter"),
    (dict(step_max=-1.0), "step_max"),
    (dict(max_points=2), "max_points"),
    (dict(steps_per_cycle=0), "steps_per_cycle"),
    (dict(well="nonsense"), "well"),
])
def test_bad_input_is_refused_before_anything_runs(monkeypatch, kwargs, words):
    def fail(*args, **kw):
        raise AssertionError("the map ran before the arguments were checked")
    monkeypatch.setattr(continuation, "stroboscopic_map", fail)
    args = dict(Omega=0.85, F=[0.05, 0.06], damping=0.1, well="cubic") | kwargs
    with pytest.raises(ValueError, match=words):
        continue_attractors(**args)
