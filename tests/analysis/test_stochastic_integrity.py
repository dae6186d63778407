"""Stochastic safe basins {P_escape <= epsilon}, their conservative (Wilson) variant and the stochastic
erosion profiles: the zero-noise limit against the deterministic erosion profile bit for bit, the exact
nestings, the conservative set rebuilt from the path counts with scipy's Wilson interval, the known
answers at weak and strong noise, the erosion in sigma against its measured seed-to-seed spread, and
bad input refused by name.  Small grids, few paths, few cycles."""
import numpy as np
import pytest
import xarray as xr
from scipy.stats import binomtest

from safebasins.analysis import erosion, stochastic_integrity
from safebasins.analysis.stochastic_integrity import (certifiable_epsilon, paths_to_certify, stochastic_erosion,
                                                      stochastic_safe_basin)
from safebasins.numerics import escape_chart, escape_probability
from safebasins.numerics.noise import WILSON_Z, wilson_interval

Q = np.linspace(-1, 1, 17)
P = np.linspace(-0.75, 0.75, 13)
MEASURES = ("GIM", "LIM", "IF", "area", "r_local", "r_global", "if_q0", "if_p0", "area_unforced",
            "r_local_unforced", "r_global_unforced")
T_EVAL = [2, 10, 20]


@pytest.fixture(scope="module")
def ensemble():
    """F = 0, thermal noise in the damped quartic: P_escape spread over (0, 1) on much of the grid."""
    return escape_probability(Q, P, 0.0, 1.0, 0.0, noise=0.05, paths=100, xi_max=0.2, t_eval=[5, 10], damping=0.05,
                              seed=3)


@pytest.mark.parametrize("damping", [0.0, 0.05])
def test_zero_noise_is_the_deterministic_erosion_bitwise(damping):
    F = [0.0, 0.03, 0.06]
    prof, charts = erosion.erosion_profile_numeric(F, 0.9, np.pi, 0.2, Q, P, t_eval=T_EVAL, cycles=20,
                                                   damping=damping, keep_charts=True)
    det = prof.sel(xi_max=0.2)
    st = stochastic_erosion(Q, P, F, 0.9, np.pi, noise=0.0, epsilon=[0.05, 0.5, 0.95], paths=50, xi_max=0.2,
                            t_eval=T_EVAL, damping=damping, keep_masks=True)
    assert st["GIM"].dims == ("F", "epsilon", "t_eval") and float(st["noise"]) == 0.0
    mask = (charts["escape_cycle_energy"].sel(xi_max=0.2) > xr.DataArray(T_EVAL, dims="t_eval")).transpose(
        "F", "t_eval", "q0", "p0").values
    for e in st["epsilon"].values:
        s = st.sel(epsilon=e)
        np.testing.assert_array_equal(s["safe"].values, mask)
        np.testing.assert_array_equal(s["safe_conservative"].values, mask)   # P_escape is exact at noise 0
        for k in MEASURES:
            np.testing.assert_array_equal(s[k].values, det[k].values, err_msg=k)
        for k in MEASURES[:8]:
            np.testing.assert_array_equal(s[k + "_conservative"].values, det[k].values, err_msg=k)
    assert 0 < float(det["GIM"].sel(F=0.06, t_eval=20)) < 1           # the comparison is not all ones
    assert "zero_noise" in st.attrs and "conservative_epsilon_floor" not in st.attrs
    assert st.attrs.get("damping", 0.0) == damping
    # the noise = 0 point of a sweep in sigma is the same deterministic profile
    sw = stochastic_erosion(Q, P, 0.06, 0.9, np.pi, noise=[0.0, 0.02], epsilon=0.1, paths=40, xi_max=0.2,
                            t_eval=T_EVAL, damping=damping)
    for k in MEASURES:
        np.testing.assert_array_equal(sw[k].sel(noise=0.0).values, det[k].sel(F=0.06).values, err_msg=k)


def test_exact_nestings_in_epsilon_t_eval_and_confidence(ensemble):
    b = stochastic_safe_basin(ensemble, [0.1, 0.3, 0.6])
    assert b["safe"].dims == ("epsilon", "t_eval", "q0", "p0")
    s, c = b["safe"].values, b["safe_conservative"].values
    assert (s[:-1] <= s[1:]).all() and (s[:, 1] <= s[:, 0]).all() and (c <= s).all()
    for k in ("GIM", "LIM", "IF", "area"):
        assert (b[k].diff("epsilon") >= 0).all() and (b[k].diff("t_eval") <= 0).all(), k
        assert (b[k + "_conservative"] <= b[k]).all(), k
    # the nesting is not trivial here: the levels and the confidence separate the sets
    assert (b["GIM"].diff("epsilon") > 0).any() and (b["GIM_conservative"] < b["GIM"]).any()
    # one evaluation time and one level: a slice of the full result, scalar coordinates
    one = stochastic_safe_basin(ensemble, 0.3, t_eval=10)
    assert one["GIM"].dims == () and float(one["t_eval"]) == 10 and float(one["epsilon"]) == 0.3
    xr.testing.assert_equal(one["safe"], b["safe"].sel(epsilon=0.3, t_eval=10))
    assert one["GIM"].attrs["units"] == "1" and "long_name" in one["epsilon"].attrs
    assert one.attrs["noise"] == 0.05 and one.attrs["well"] == "quartic" and "history" in one.attrs
    plain = stochastic_safe_basin(ensemble, 0.3, conservative=False)
    assert "safe_conservative" not in plain and "GIM_conservative" not in plain


def test_conservative_set_is_scipys_wilson_bound_from_the_counts(ensemble):
    eps = 0.1
    b = stochastic_safe_basin(ensemble, eps)
    n = ensemble.attrs["paths"]
    k = np.rint(ensemble["P_escape"].values * n)
    np.testing.assert_array_equal(k / n, ensemble["P_escape"].values)          # whole counts
    high = {int(j): binomtest(int(j), n).proportion_ci(0.95, "wilson").high for j in np.unique(k)}
    upper = np.vectorize(high.get)(k.astype(int))
    assert np.min(np.abs(upper - eps)) > 1e-6                                    # no tie at the level
    expected = (upper <= eps).transpose(2, 0, 1)                                # (t_eval, q0, p0)
    np.testing.assert_array_equal(b["safe_conservative"].values, expected)
    cons = b["safe_conservative"].values
    assert (ensemble["P_escape_high"].values.transpose(2, 0, 1)[cons] <= eps).all()
    # some ICs are safe on the estimate but not with confidence, some are safe with confidence
    assert cons.any() and (b["safe"].values & ~cons).any()


def test_certifiable_level_and_paths():
    for n in (1, 10, 100, 1000):
        assert certifiable_epsilon(n) == pytest.approx(WILSON_Z ** 2 / (n + WILSON_Z ** 2), rel=1e-12)
    for eps in (0.5, 0.1, 0.05, 0.01, 0.001):
        n = paths_to_certify(eps)
        assert n > 1 and certifiable_epsilon(n) <= eps < certifiable_epsilon(n - 1), eps


def test_weak_and_strong_noise_known_answers():
    """F = 0, thermal noise sigma^2 = 2 beta T near the bottom of the quartic (xi_max = 0.2): ICs with
    H0 <= 0.04 need a deviation of about sqrt(0.4) - sqrt(0.08) = 0.35 in (q, p) to reach xi_max, while
    the noise moves p by sigma sqrt(t) = 0.035 over two cycles at sigma = 0.01 (10 standard deviations):
    nothing escapes, every measure is 1.  At sigma = 3 p diffuses by 10.6 over the same time across a
    well 1.3 wide: every path escapes, every measure is 0."""
    qi = np.linspace(-0.2, 0.2, 9)
    st = stochastic_erosion(qi, qi, 0.0, 1.0, 0.0, noise=[0.01, 3.0], epsilon=0.05, paths=100, xi_max=0.2,
                            t_eval=2, damping=0.1, keep_masks=True)
    weak, strong = st.sel(noise=0.01), st.sel(noise=3.0)
    assert (weak["P_escape"] == 0).all() and weak["safe_conservative"].all()
    assert (strong["P_escape"] == 1).all() and not strong["safe"].any()
    for k in ("GIM", "LIM", "IF"):
        assert float(weak[k]) == 1.0 and float(weak[k + "_conservative"]) == 1.0, k
        assert float(strong[k]) == 0.0 and float(strong[k + "_conservative"]) == 0.0, k


@pytest.mark.parametrize("seed", [0, 1])
def test_erosion_in_sigma_beyond_the_sampling_spread(seed):
    """F = 0, damping 0.05, xi_max 0.2, 100 paths, t_eval 10 cycles on the 17 x 13 grid.  Over 20 seeds
    (measured) GIM at epsilon = 0.1 was 1, 0.892 +- 0.007 (0.888-0.910), 0.614 +- 0.020 (0.573-0.640),
    0 at sigma = 0.01, 0.025, 0.05, 0.1; at epsilon = 0.5: 1, 0.999 +- 0.003, 0.864 +- 0.010,
    0.011 +- 0.010.  The gaps at epsilon = 0.1 are > 10 standard deviations: asserted at 0.05.  Per IC,
    no pair of neighbouring sigmas had disjoint Wilson intervals in the reversed order (P at the smaller
    sigma significantly above P at the larger) in 20 x 3 x 221 comparisons."""
    st = stochastic_erosion(Q, P, 0.0, 1.0, 0.0, noise=[0.01, 0.025, 0.05, 0.1], epsilon=[0.1, 0.5], paths=100,
                            xi_max=0.2, t_eval=10, damping=0.05, seed=seed, keep_masks=True)
    g = st["GIM"]
    assert g.dims == ("noise", "epsilon") and float(st["t_eval"]) == 10     # a scalar t_eval: a scalar coordinate
    assert float(g.sel(noise=0.01, epsilon=0.1)) == 1.0 and float(g.sel(noise=0.1, epsilon=0.1)) == 0.0
    assert (-g.sel(epsilon=0.1).diff("noise") >= 0.05).all()
    assert (g.sel(epsilon=0.5).diff("noise") <= 0).all()
    assert (st["LIM"].diff("noise") <= 0).all() and (st["IF"].diff("noise") <= 0).all()
    lo, hi = wilson_interval(np.rint(st["P_escape"].values * 100), 100)
    assert not (lo[:-1] > hi[1:]).any()


@pytest.fixture(scope="module")
def paired():
    return escape_probability([0.1, 0.2], [0.0, 0.1], 0.0, 1.0, 0.0, noise=0.05, paths=4, xi_max=0.2, t_eval=[2],
                              grid=False)


@pytest.mark.parametrize("kwargs, name", [
    (dict(epsilon=0.0), "epsilon"), (dict(epsilon=1.0), "epsilon"), (dict(epsilon=-0.1), "epsilon"),
    (dict(epsilon=np.nan), "epsilon"), (dict(epsilon=[[0.1]]), "epsilon"), (dict(epsilon="a"), "epsilon"),
    (dict(epsilon=[0.5, 0.1]), "epsilon"), (dict(epsilon=[]), "epsilon"), (dict(epsilon=0.3, t_eval=7), "t_eval"),
    (dict(epsilon=0.3, bottom=(0.0,)), "bottom"),
])
def test_bad_basin_input_is_refused_by_name(ensemble, kwargs, name):
    eps = kwargs.pop("epsilon")
    with pytest.raises(ValueError, match=name):
        stochastic_safe_basin(ensemble, eps, **kwargs)


def test_bad_maps_and_uncertifiable_levels_are_refused(ensemble, paired):
    chart = escape_chart(Q[:3], P[:3], 0.0, 1.0, 0.0, xi_max=0.2, cycles=2)
    for ds in (ensemble["P_escape"], chart, paired, ensemble.drop_vars("P_escape_high")):
        with pytest.raises(ValueError, match="ds"):
            stochastic_safe_basin(ds, 0.3)
    few = escape_probability(Q[6:11], P[4:9], 0.0, 1.0, 0.0, noise=0.05, paths=10, xi_max=0.2, t_eval=[2])
    with pytest.raises(ValueError, match=r"epsilon.*paths >= 35"):      # floor 0.277 for 10 paths
        stochastic_safe_basin(few, 0.1)
    plain = stochastic_safe_basin(few, 0.1, conservative=False)                # the estimate needs no floor
    assert np.isfinite(plain["GIM"]).all() and plain.attrs["conservative_epsilon_floor"] == certifiable_epsilon(10)
    with pytest.raises(ValueError, match="conservative"):
        stochastic_safe_basin(ensemble, 0.3, conservative="no")


@pytest.mark.parametrize("change, name", [
    (dict(noise=-0.1), "noise"), (dict(noise=[0.1, 0.05]), "noise"), (dict(noise=[[0.1]]), "noise"),
    (dict(F=[-1.0]), "F"), (dict(F=[0.1, 0.1]), "F"), (dict(q0=np.array([0.0, 0.1, 0.3])), "q0"),
    (dict(paths=0), "paths"), (dict(keep_masks="yes"), "keep_masks"), (dict(conservative=1), "conservative"),
    (dict(epsilon=0.01), "epsilon"), (dict(epsilon=2.0), "epsilon"),
])
def test_bad_erosion_input_is_refused_before_anything_runs(monkeypatch, change, name):
    def never(*args, **kwargs):
        raise AssertionError("an ensemble ran before the arguments were checked")
    monkeypatch.setattr(stochastic_integrity, "escape_probability", never)
    args = {**dict(q0=Q, p0=P, F=0.0, noise=[0.0, 0.05], epsilon=0.1, paths=50, keep_masks=False), **change}
    with pytest.raises(ValueError, match=name):
        stochastic_erosion(args.pop("q0"), args.pop("p0"), args.pop("F"), 1.0, 0.0, xi_max=0.2, t_eval=2, **args)
