"""escape_chart / safe_mask / safe_area: structure, threshold logic, criteria, theory."""
import numpy as np
import pytest

from safebasins.analysis.safe import safe_area, safe_mask
from safebasins.numerics import escape_chart, random_initial_conditions


def q_max_from_xi(xi):
    return np.sqrt(1 - np.sqrt(1 - 4 * np.asarray(xi, float)))   # eq (4)


@pytest.fixture(scope="module")
def chart():
    q = np.linspace(-1, 1, 50)
    p = np.linspace(-0.9, 0.9, 40)
    xi = (0.25, 0.15, 0.2)                                # deliberately unsorted
    return escape_chart(q, p, 0.0876, 0.95, np.pi, xi_max=xi, q_max=tuple(q_max_from_xi(xi)), cycles=200)


def test_grid_structure_and_metadata(chart):
    assert chart["escape_cycle_energy"].dims == ("xi_max", "q0", "p0")
    assert chart["escape_cycle_displacement"].dims == ("q_max", "q0", "p0")
    assert chart.sizes == {"xi_max": 3, "q_max": 3, "q0": 50, "p0": 40}
    assert chart["xi_max"].values.tolist() == [0.25, 0.15, 0.2]
    for k in ("F", "Omega", "Psi", "cycles", "steps_per_cycle", "integrator"):
        assert k in chart.attrs
    assert chart.attrs["cycles"] == 200
    for name in list(chart.data_vars) + list(chart.coords):
        assert "long_name" in chart[name].attrs, name
        if name != "sample":
            assert "units" in chart[name].attrs, name
    v = chart["escape_cycle_energy"].values
    finite = v[np.isfinite(v)]
    assert np.all(np.isposinf(v[~np.isfinite(v)]))
    assert finite.min() >= 0 and finite.max() <= 200
    S = chart.attrs["steps_per_cycle"]
    np.testing.assert_array_equal(finite * S, np.round(finite * S))   # whole steps


def test_paired_and_grid_agree(chart):
    q, p = random_initial_conditions(200, 3, box=((-1, 1), (-0.9, 0.9)))
    # paired ICs that are exactly grid points
    iq = (np.arange(200) * 7) % 50
    ip = (np.arange(200) * 3) % 40
    qs, ps = chart["q0"].values[iq], chart["p0"].values[ip]
    d = escape_chart(qs, ps, 0.0876, 0.95, np.pi, xi_max=(0.25, 0.15, 0.2),
                     q_max=tuple(chart["q_max"].values), cycles=200, grid=False)
    assert d["escape_cycle_energy"].dims == ("xi_max", "sample")
    np.testing.assert_array_equal(d["q0"].values, qs)
    np.testing.assert_array_equal(d["escape_cycle_energy"].values, chart["escape_cycle_energy"].values[:, iq, ip])
    np.testing.assert_array_equal(d["escape_cycle_displacement"].values,
                                  chart["escape_cycle_displacement"].values[:, iq, ip])
    # 2-D paired arrays are flattened in C order
    d2 = escape_chart(qs.reshape(20, 10), ps.reshape(20, 10), 0.0876, 0.95, np.pi, xi_max=0.25, cycles=200)
    assert d2.sizes["sample"] == 200
    np.testing.assert_array_equal(d2["escape_cycle_energy"].values[0], d["escape_cycle_energy"].values[0])
    assert q.shape == (200,) and p.shape == (200,)
    # grid=None: unsorted 1-D arrays (random ICs) are paired, sorted ones are axes
    auto = escape_chart(q[:30], p[:30], 0.0876, 0.95, np.pi, xi_max=0.25, cycles=5)
    assert auto["escape_cycle_energy"].dims == ("xi_max", "sample")
    axes = escape_chart(np.sort(q[:30]), np.sort(p[:20]), 0.0876, 0.95, np.pi, xi_max=0.25, cycles=5)
    assert axes["escape_cycle_energy"].dims == ("xi_max", "q0", "p0")
    forced = escape_chart(np.sort(q[:30]), np.sort(p[:30]), 0.0876, 0.95, np.pi, xi_max=0.25, cycles=5, grid=False)
    assert forced.sizes["sample"] == 30
    assert np.array_equal(random_initial_conditions(200, 3, box=((-1, 1), (-0.9, 0.9)))[0], q)


def test_lower_threshold_never_escapes_later(chart):
    e = chart["escape_cycle_energy"].sortby("xi_max").values
    d = chart["escape_cycle_displacement"].sortby("q_max").values
    assert np.all(e[:-1] <= e[1:]) and np.all(d[:-1] <= d[1:])


def test_energy_basin_inside_displacement_basin(chart):
    """ESB subset of DSB for q_max = q_max(xi_max) (appendix): energy escape never later."""
    e = chart["escape_cycle_energy"].values
    d = chart["escape_cycle_displacement"].values          # same threshold order (eq 4 is monotone)
    assert np.all(e <= d)
    m = safe_mask(chart, [0, 10, 100, 200])
    se = m["safe_energy"].values
    sd = m["safe_displacement"].values
    assert np.all(~se | sd)
    assert (sd & ~se).any()                                 # and the DSB is genuinely larger


def test_safe_area_monotone_in_t_eval(chart):
    t = np.array([0, 1, 2, 5, 10, 50, 100, 200])
    a = safe_area(chart, t)
    assert a["pixels_energy"].dims == ("t_eval", "xi_max")
    for v in ("pixels_energy", "pixels_displacement", "area_energy", "area_displacement"):
        x = a[v].values
        assert np.all(np.diff(x, axis=0) <= 0), v
    dq = 2 / 49
    dp = 1.8 / 39
    np.testing.assert_allclose(a["area_energy"].values, a["pixels_energy"].values * dq * dp)
    # scalar t_eval: scalar coordinate
    s = safe_area(chart, 100)
    assert "t_eval" not in s.dims and float(s["t_eval"]) == 100
    np.testing.assert_array_equal(s["pixels_energy"].values, a["pixels_energy"].sel(t_eval=100).values)
    # consistent with a direct count
    direct = (chart["escape_cycle_energy"] > 100).sum(("q0", "p0"))
    np.testing.assert_array_equal(s["pixels_energy"].values, direct.values)


def test_unforced_chart_is_the_energy_disc():
    q = np.linspace(-1, 1, 41)
    c = escape_chart(q, q, 0.0, 1.0, 0.0, xi_max=0.2, cycles=20)
    Q, P = np.meshgrid(q, q, indexing="ij")
    inside = 0.5 * P ** 2 + 0.5 * Q ** 2 - 0.25 * Q ** 4 < 0.2 - 1e-6
    outside = 0.5 * P ** 2 + 0.5 * Q ** 2 - 0.25 * Q ** 4 > 0.2 + 1e-6
    v = c["escape_cycle_energy"].values[0]
    assert np.all(np.isinf(v[inside & (np.abs(Q) < 1)])) and np.all(v[outside] == 0)


def test_agrees_with_slow_flow_theory_small_F():
    """Fig 13 regime: F = 0.015, Omega = 1.04, Psi = pi, xi_max = 0.2: IoU >= 0.9."""
    theory = pytest.importorskip("safebasins.theory")
    if not hasattr(theory, "slow_flow_escapes"):
        pytest.skip("safebasins.theory.slow_flow_escapes not available yet")
    q = np.linspace(-1, 1, 60)
    Q, P = np.meshgrid(q, q, indexing="ij")
    esc = np.asarray(theory.slow_flow_escapes(Q, P, 0.015, 1.04, np.pi, 0.2), dtype=bool)
    c = escape_chart(q, q, 0.015, 1.04, np.pi, xi_max=0.2, cycles=1000)
    safe_num = np.isinf(c["escape_cycle_energy"].values[0])
    safe_th = ~esc
    iou = (safe_num & safe_th).sum() / (safe_num | safe_th).sum()
    assert iou >= 0.9, iou


@pytest.mark.parametrize("kwargs,name", [
    (dict(F=-0.1), "F"), (dict(F=np.nan), "F"), (dict(Omega=0.0), "Omega"), (dict(Omega=[1, 2]), "Omega"),
    (dict(Psi=np.inf), "Psi"), (dict(xi_max=0.3), "xi_max"), (dict(xi_max=(0.1, -0.1)), "xi_max"),
    (dict(q_max=1.5), "q_max"), (dict(xi_max=(), q_max=()), "xi_max"), (dict(cycles=0), "cycles"),
    (dict(cycles=2.5), "cycles"), (dict(steps_per_cycle=0), "steps_per_cycle"),
    (dict(steps_per_cycle=16.0), "steps_per_cycle"), (dict(threads=0), "threads"),
    (dict(q0=[0.1, np.nan]), "q0"), (dict(p0="x"), "p0"),
])
def test_bad_arguments_name_the_argument(kwargs, name):
    args = dict(q0=np.linspace(-1, 1, 3), p0=np.linspace(-1, 1, 3), F=0.01, Omega=1.0, Psi=0.0)
    args.update(kwargs)
    pos = [args.pop(k) for k in ("q0", "p0", "F", "Omega", "Psi")]
    with pytest.raises(ValueError, match=name):
        escape_chart(*pos, cycles=args.pop("cycles", 2), **args)


def test_bad_shapes_and_t_eval(chart):
    with pytest.raises(ValueError, match="q0"):
        escape_chart(np.zeros(3), np.zeros(4), 0.01, 1.0, 0.0, grid=False)
    with pytest.raises(ValueError, match="q0"):
        escape_chart(np.zeros((2, 2)), np.zeros((2, 2)), 0.01, 1.0, 0.0, grid=True)
    with pytest.raises(ValueError, match="t_eval"):
        safe_mask(chart, 201)
    with pytest.raises(ValueError, match="t_eval"):
        safe_area(chart, -1)
    with pytest.raises(ValueError, match="seed"):
        random_initial_conditions(3, -1)
    with pytest.raises(ValueError, match="box"):
        random_initial_conditions(3, 1, box=((1, -1), (0, 1)))
    with pytest.raises(ValueError, match="n"):
        random_initial_conditions(0, 1)
