"""numerics.escape_probability and its kernels: noise = 0 is escape_chart bitwise, the paths do
not depend on threads, lanes or order (counter-based streams), the Gaussian pairs are standard
normal, the dataset's statistics follow from the escape times, and bad input is refused by name."""
from __future__ import annotations

import math

import numpy as np
import xarray as xr
import pytest
from scipy import stats

from safebasins.numerics import escape_chart, noise_kernels, schemes
from safebasins.numerics.noise import escape_probability, wilson_interval
from safebasins.numerics.scheme_code import scheme_code
from safebasins.wells.compiled import quartic_code

Q = np.linspace(-0.6, 0.6, 9)
P = np.linspace(-0.5, 0.5, 7)
FORCING = dict(F=0.04, Omega=0.9, Psi=0.3)


@pytest.mark.parametrize("damping,variates", [(0.0, "gaussian"), (0.02, "gaussian"), (0.02, "five-point")])
def test_zero_noise_is_escape_chart_bitwise(damping, variates):
    """sigma = 0: every path is the engine's trajectory (the half kicks add exact zeros), so the
    escape cycles are escape_chart's, bit for bit, for every path, seed and law of the variates."""
    chart = escape_chart(Q, P, **FORCING, xi_max=0.2, cycles=40, damping=damping)
    want = np.minimum(chart.escape_cycle_energy.isel(xi_max=0).values, 40.0)
    assert np.isinf(want).any() is np.False_ and (want == 40).any() and ((want > 0) & (want < 40)).any()
    ds = escape_probability(Q, P, **FORCING, noise=0.0, paths=1, xi_max=0.2, t_eval=[40], cycles=40, damping=damping,
                            seed=5, variates=variates)
    np.testing.assert_array_equal(ds.first_passage_mean.values, want)
    np.testing.assert_array_equal(ds.censored_fraction.values, np.isinf(chart.escape_cycle_energy[0]).values)
    assert np.isnan(ds.first_passage_sem).all()          # one path: no standard error (documented)
    three = escape_probability(Q, P, **FORCING, noise=0.0, paths=3, xi_max=0.2, t_eval=[10, 40], cycles=40,
                               damping=damping, seed=9, variates=variates)
    for t in (10, 40):
        np.testing.assert_array_equal(three.P_escape.sel(t_eval=t).values,
                                      (chart.escape_cycle_energy[0] <= t).values.astype(float))
    assert (three.first_passage_sem == 0).all()          # three equal paths


def _kernel_run(n_tasks, lanes, n_paths=37, seed=11, law=noise_kernels.GAUSSIAN, S=16):
    code, sc = quartic_code(), scheme_code("srkn6b", True)
    coef = schemes.lane_coefficients([0.9], S, "srkn6b", 0.05)
    tab = schemes.sine_table(S, 0.0)
    q0, p0 = np.array([0.0, 0.3, -0.5, 0.9]), np.array([0.0, 0.1, 0.2, 0.5])
    return noise_kernels.escape_steps(code, sc, q0, p0, n_paths, coef, tab, 0.03, 0.4, 30,
                                      noise_kernels.StepNoise(0.02, law=law), seed, shift=0.01,
                                      n_tasks=n_tasks, lanes=lanes)


@pytest.mark.parametrize("law,S", [(noise_kernels.GAUSSIAN, 16), (noise_kernels.FIVE_POINT, 16),
                                   (noise_kernels.FIVE_POINT, 21)])
def test_paths_do_not_depend_on_tasks_lanes_or_order(law, S):
    """Counter-based streams: the first-passage steps are the same for 1 or 3 tasks and 256 or 7
    lanes (lanes refilled and compacted at other moments); a path's steps do not depend on how
    many paths are run (path m of IC i is the same path in a longer run); either law (five-point:
    a block per period, or two with the second partial)."""
    ref = _kernel_run(1, 256, law=law, S=S)
    assert (ref > 0).any() and (ref < 0).any()
    np.testing.assert_array_equal(_kernel_run(3, 7, law=law, S=S), ref)
    np.testing.assert_array_equal(_kernel_run(2, 64, law=law, S=S), ref)
    np.testing.assert_array_equal(_kernel_run(1, 256, n_paths=50, law=law, S=S)[:, :37], ref)
    assert not np.array_equal(_kernel_run(1, 256, seed=12, law=law, S=S), ref)
    if law != noise_kernels.GAUSSIAN:
        assert not np.array_equal(_kernel_run(1, 256, S=S), ref)
    kw = dict(noise=0.03, paths=40, xi_max=0.2, t_eval=[5, 20], damping=0.05, seed=3)
    a = escape_probability(Q, P, **FORCING, threads=1, **kw)
    b = escape_probability(Q, P, **FORCING, threads=2, **kw)
    for v in ("P_escape", "survival", "first_passage_mean"):
        np.testing.assert_array_equal(a[v].values, b[v].values)


def test_gaussian_pairs_are_independent_standard_normals():
    """Box-Muller pairs of the Philox blocks: mean, variance, skewness, kurtosis and the pair's
    correlation within 5 standard errors; Kolmogorov-Smirnov against N(0, 1) (p > 1e-4); distinct
    (step, path, ic) give distinct numbers."""
    n = 200_000
    k = np.arange(n)
    z = noise_kernels.gaussian_pairs(2026, k % 1000, k // 1000, np.full(n, 3))
    x = z.ravel()
    se = 1 / math.sqrt(x.size)
    assert abs(x.mean()) < 5 * se
    assert abs(x.var() - 1) < 5 * math.sqrt(2) * se
    assert abs(stats.skew(x)) < 5 * math.sqrt(6) * se
    assert abs(stats.kurtosis(x)) < 5 * math.sqrt(24) * se
    assert abs(np.corrcoef(z[:, 0], z[:, 1])[0, 1]) < 5 / math.sqrt(n)
    assert stats.kstest(x, "norm").pvalue > 1e-4
    assert np.unique(x).size == x.size
    again = noise_kernels.gaussian_pairs(2026, k[:10] % 1000, k[:10] // 1000, np.full(10, 3))
    np.testing.assert_array_equal(again, z[:10])


def test_sincos_2pi_accuracy():
    """sin, cos(2 pi u) of the Box-Muller angle within 3e-16 (absolute) of numpy's at the
    quadrant edges and at random u."""
    from numba import njit

    @njit
    def both(u, s, c):
        for j in range(u.size):
            s[j], c[j] = noise_kernels._sincos_2pi(u[j])

    u = np.concatenate([np.random.default_rng(0).random(20000), np.arange(0, 9) / 8, [2.0 ** -53, 1 - 2.0 ** -53]])
    s, c = np.empty_like(u), np.empty_like(u)
    both(u, s, c)
    # numpy's sin(2 pi u) carries the rounding of 2 pi u (<= 4.5e-16 here): compare in long double
    x = 2 * np.pi * u.astype(np.longdouble)
    assert np.abs(s - np.sin(x)).max() < 6e-16
    assert np.abs(c - np.cos(x)).max() < 6e-16


def test_dataset_statistics_follow_from_the_escape_times():
    ds = escape_probability([0.0, 0.3], [0.0, 0.1], F=0.03, Omega=0.9, Psi=0.0, noise=0.04, paths=300, xi_max=0.2,
                            t_eval=[2, 5, 10, 25], cycles=25, damping=0.05, seed=1, grid=False)
    Pe = ds.P_escape.values
    assert Pe.shape == (2, 4) and (np.diff(Pe, axis=1) >= 0).all() and 0 < Pe[0, -1] < 1
    low, high = wilson_interval(Pe * 300, 300)
    np.testing.assert_allclose(ds.P_escape_low.values, low)
    assert (ds.P_escape_low.values <= Pe).all() and (Pe <= ds.P_escape_high.values).all()
    # survival on every cycle 0..25 is 1 - P_escape at the same times
    np.testing.assert_allclose(ds.survival.sel(t_survival=[2.0, 5.0, 10.0, 25.0]).values, 1 - Pe)
    assert ds.survival.values[:, 0].tolist() == [1.0, 1.0]
    # the restricted mean is the integral of the survival curve (to the survival grid's
    # resolution of one cycle: the curve is a step function between cycles)
    integral = ds.survival.integrate("t_survival").values
    assert np.all(np.abs(ds.first_passage_mean.values - integral) < 0.5 + 1e-12)
    np.testing.assert_allclose(ds.censored_fraction.values, 1 - Pe[:, -1])
    assert ds.attrs["noise"] == 0.04 and ds.attrs["seed"] == 1 and ds.attrs["paths"] == 300
    assert "Philox" in ds.attrs["random_numbers"] and "Gobet" in ds.attrs["boundary_correction"]
    assert ds.P_escape.attrs["units"] == "1" and "Wilson" in ds.P_escape_low.attrs["long_name"]


def test_wilson_interval_closed_form():
    """k = 0 of n: (0, z^2 / (n + z^2)); k = n: (n / (n + z^2), 1); a middle value against the
    textbook formula written out."""
    z = 1.959963984540054
    lo, hi = wilson_interval([0, 20, 7], 20)
    assert lo[0] == 0.0 and math.isclose(hi[0], z * z / (20 + z * z))
    assert hi[1] == 1.0 and math.isclose(lo[1], 20 / (20 + z * z))
    p, n = 7 / 20, 20
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    d = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    assert math.isclose(lo[2], c - d) and math.isclose(hi[2], c + d)


@pytest.mark.parametrize("law", [noise_kernels.GAUSSIAN, noise_kernels.FIVE_POINT])
def test_chunks_with_offsets_draw_the_whole_runs_streams(law):
    """ICs 1..3 with ic_offset=1 and paths 20..36 with path_offset=20 are that block of the whole
    run's escape steps, bitwise; escape_probability over two path chunks, pooled, is the whole
    run's P_escape; the offsets are recorded and refused by name when out of range."""
    code, sc = quartic_code(), scheme_code("srkn6b", True)
    coef = schemes.lane_coefficients([0.9], 16, "srkn6b", 0.05)
    tab = schemes.sine_table(16, 0.0)
    q0, p0 = np.array([0.0, 0.3, -0.5, 0.9]), np.array([0.0, 0.1, 0.2, 0.5])

    def run(ics, n_paths, **kw):
        return noise_kernels.escape_steps(code, sc, q0[ics], p0[ics], n_paths, coef, tab, 0.03, 0.4, 30,
                                          noise_kernels.StepNoise(0.02, law=law), 11, shift=0.01, **kw)
    whole = run(slice(0, 4), 37)
    assert (whole > 0).any() and (whole < 0).any()
    np.testing.assert_array_equal(run(slice(1, 4), 37, ic_offset=1), whole[1:])
    np.testing.assert_array_equal(run(slice(0, 4), 17, path_offset=20), whole[:, 20:])
    np.testing.assert_array_equal(run(slice(2, 3), 5, ic_offset=2, path_offset=30, n_tasks=2, lanes=3),
                                  whole[2:3, 30:35])
    assert not np.array_equal(run(slice(1, 4), 37), whole[1:])
    kw = dict(noise=0.03, xi_max=0.2, t_eval=[5, 20], damping=0.05, seed=3, grid=False,
              variates="gaussian" if law == noise_kernels.GAUSSIAN else "five-point")
    q, p = [0.0, 0.3, -0.5], [0.0, 0.1, 0.2]
    full = escape_probability(q, p, **FORCING, paths=30, **kw)
    a = escape_probability(q, p, **FORCING, paths=12, **kw)
    b = escape_probability(q, p, **FORCING, paths=18, path_offset=12, **kw)
    np.testing.assert_array_equal((12 * a.P_escape + 18 * b.P_escape).values, (30 * full.P_escape).values)
    assert b.attrs["path_offset"] == 12 and "ic_offset" not in b.attrs and "path_offset" not in a.attrs
    c = escape_probability(q[1:], p[1:], **FORCING, paths=30, ic_offset=1, **kw)
    np.testing.assert_array_equal(c.P_escape.values, full.P_escape.values[1:])
    for bad, name in ((dict(ic_offset=-1), "ic_offset"), (dict(path_offset=2 ** 32 - 5), "path_offset"),
                      (dict(ic_offset=1.5), "ic_offset")):
        with pytest.raises(ValueError, match=f"^{name}"):
            escape_probability(q, p, **FORCING, paths=30, **kw, **bad)


@pytest.mark.parametrize("law", [noise_kernels.GAUSSIAN, noise_kernels.FIVE_POINT])
def test_several_thresholds_in_one_pass(law):
    """Energy thresholds 2 xi_max = 0.2, 0.3, 0.3, 0.45 in one pass: each column is the run with that
    threshold alone, bitwise (the paths do not depend on the thresholds; a trajectory runs until
    it is beyond the largest); crossings in order, ties equal; a descending array is refused."""
    code, sc = quartic_code(), scheme_code("srkn6b", True)
    coef = schemes.lane_coefficients([0.9], 16, "srkn6b", 0.05)
    tab = schemes.sine_table(16, 0.0)
    q0, p0 = np.array([0.0, 0.3, -0.5, 0.9, 0.2]), np.array([0.0, 0.1, 0.2, 0.5, 0.5])
    thr = np.array([0.2, 0.3, 0.3, 0.45])

    def run(t, **kw):
        return noise_kernels.escape_steps(code, sc, q0, p0, 23, coef, tab, 0.03, t, 30,
                                          noise_kernels.StepNoise(0.02, law=law), 11, shift=0.01, **kw)
    many = run(thr, n_tasks=2, lanes=5)
    assert many.shape == (5, 23, 4)
    for k, t in enumerate(thr):
        np.testing.assert_array_equal(many[..., k], run(float(t)))
    np.testing.assert_array_equal(many[..., 1], many[..., 2])
    done = np.where(many < 0, np.iinfo(np.int64).max, many)
    assert (np.diff(done, axis=-1) >= 0).all()
    assert (many[..., 0] == 0).any() and (many[..., 3] == 0).any() and (many[..., 0] > 0).any()
    assert ((many[..., 0] > 0) & (many[..., 3] < 0)).any() and (many[..., 0] < many[..., 3]).any()
    with pytest.raises(ValueError, match="^thrE2"):
        run(thr[::-1])


def test_escape_probability_with_several_xi_max():
    """xi_max = [0.22, 0.12, 0.18] (not sorted): every variable gains the dimension xi_max, in the
    caller's order, and each slice is the Dataset of that threshold alone (values and dims)."""
    kw = dict(noise=0.04, paths=30, t_eval=[3, 8], cycles=8, damping=0.03, seed=6, variates="five-point")
    xs = [0.22, 0.12, 0.18]
    many = escape_probability(Q[::2], P[::2], **FORCING, xi_max=xs, **kw)
    assert list(many.xi_max.values) == xs and "xi_max" not in many.attrs
    assert many.P_escape.dims == ("q0", "p0", "xi_max", "t_eval")
    assert many.first_passage_mean.dims == ("q0", "p0", "xi_max")
    for x in xs:
        one = escape_probability(Q[::2], P[::2], **FORCING, xi_max=x, **kw)
        for v in one.data_vars:
            xr.testing.assert_equal(many[v].sel(xi_max=x, drop=True), one[v])
    p = many.P_escape.sel(t_eval=8).values
    assert (p[..., 1] >= p[..., 2]).all() and (p[..., 2] >= p[..., 0]).all() and (p[..., 1] > p[..., 0]).any()
    with pytest.raises(ValueError, match="^xi_max"):
        escape_probability(Q, P, **FORCING, xi_max=[0.1, 0.3], **kw)


GOOD = dict(noise=0.05, paths=10, xi_max=0.2, t_eval=[5])


@pytest.mark.parametrize("change,name", [
    (dict(noise=-0.1), "noise"), (dict(noise=float("nan")), "noise"), (dict(noise=[0.1, 0.2]), "noise"),
    (dict(paths=0), "paths"), (dict(paths=2.5), "paths"), (dict(paths=2 ** 32 + 1), "paths"),
    (dict(xi_max=0.3), "xi_max"), (dict(xi_max=-1), "xi_max"),
    (dict(t_eval=[-1]), "t_eval"), (dict(t_eval=[20], cycles=10), "t_eval"), (dict(t_eval=[]), "t_eval"),
    (dict(seed=-1), "seed"), (dict(seed=2 ** 63), "seed"), (dict(seed=1.5), "seed"), (dict(seed=True), "seed"),
    (dict(correction="bridge"), "correction"), (dict(variates="uniform"), "variates"), (dict(backend="gpu"), "backend"),
    (dict(damping=-0.1), "damping"),
    (dict(cycles=0), "cycles"), (dict(steps_per_cycle=2), "steps_per_cycle"), (dict(threads=0), "threads"),
    (dict(integrator="euler"), "integrator"), (dict(noise_time=-1.0), "noise_time"),
    (dict(noise_time=0.05), "noise_time"),
])
def test_bad_input_is_refused_by_name(change, name):
    kw = {**GOOD, **change}
    with pytest.raises(ValueError, match=f"^{name}"):
        escape_probability([0.0], [0.0], 0.05, 0.9, 0.0, **kw)


@pytest.mark.parametrize("args,name", [(([0.0], [0.0], -0.1, 0.9, 0.0), "F"), (([0.0], [0.0], 0.1, 0.0, 0.0), "Omega"),
                                       (([0.0], [0.0], 0.1, 0.9, math.inf), "Psi"),
                                       (([[0.0, 1.0]], [0.0], 0.1, 0.9, 0.0), "q0 and p0"),
                                       (([math.nan], [0.0], 0.1, 0.9, 0.0), "q0")])
def test_bad_equation_is_refused_by_name(args, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        escape_probability(*args, **GOOD)
