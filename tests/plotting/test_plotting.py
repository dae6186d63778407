"""Unit tests of safebasins.plotting on tiny synthetic datasets in the contract format
(docs/contracts.md).  Each figure builder must produce a non-trivial PNG (size, pixel variance)
without touching the physics code."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

from safebasins.plotting import basins, charts, fcr, maps  # noqa: E402
from safebasins.plotting.style import SB_EDGE, fmt_value, save_figure  # noqa: E402

RNG = np.random.default_rng(0)


# ------------------------------------------------------------------ synthetic datasets
def fcr_stack(n_curve=3, n_omega=40, numeric=False):
    Om = np.linspace(0.5, 1.2, n_omega)
    F = np.stack([0.02 + (0.2 + 0.05 * i) * np.abs(Om - 0.9) for i in range(n_curve)])
    mech = np.where(Om < 0.7, 4, np.where(Om < 0.9, 3, 2)).astype("int8")
    ds = xr.Dataset(
        dict(F_cr=(("curve", "Omega"), F), mechanism=(("curve", "Omega"), np.tile(mech, (n_curve, 1))),
             F_MM_0=(("curve", "Omega"), F * 1.1), F_MM_pi=(("curve", "Omega"), F * 1.2),
             F_SM=(("curve", "Omega"), F * 1.05), F_SMM=(("curve", "Omega"), np.where(Om < 0.7, F, np.nan))),
        coords=dict(Omega=Om, xi_max=("curve", [0.242] * n_curve), xi_ini=("curve", 0.05 * np.arange(n_curve)),
                    gamma_ini=("curve", [0.25] * n_curve), Psi=("curve", [np.pi] * n_curve),
                    label=("curve", [f"c{i}" for i in range(n_curve)])),
        attrs=dict(fourier="paper"))
    if not numeric:
        return ds
    num = ds[["F_cr"]].isel(Omega=slice(0, None, 5))
    nm = (num.Omega > 0.8) & (num.Omega < 1.0)
    num["F_escape_low"] = (num.F_cr * 0.9).where(nm, num.F_cr)
    num["F_escape_all"] = (num.F_cr * 1.1).where(nm, num.F_cr)
    num["non_monotone"] = nm.broadcast_like(num.F_cr)
    return num.assign_attrs(cycles=3000, tol=5e-5, criterion="energy")


def rm_basin(n=30):
    g = np.linspace(-np.pi, np.pi, 2 * n + 1)
    xi = np.linspace(0, 0.249, n)
    q0 = np.linspace(-1, 1, n)
    p0 = np.linspace(-0.75, 0.75, n)
    G, X = np.meshgrid(g, xi)
    C = -0.05 * X * np.cos(G) - 0.9 * X + X**1.5
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    t = np.linspace(0, 2 * np.pi, 50)
    return xr.Dataset(
        dict(C=(("xi_rm", "gamma_rm"), C), escapes_rm=(("xi_rm", "gamma_rm"), X > 0.15),
             escapes=(("q0", "p0"), Q**2 + P**2 > 0.2),
             gamma=("vertex", np.r_[t - np.pi, np.nan, t[:10]]),
             xi=("vertex", np.r_[0.15 + 0.01 * np.sin(t), np.nan, 0.1 + 0 * t[:10]]),
             q0_vertex=("vertex", np.r_[0.45 * np.cos(t), np.nan, 0.1 * t[:10]]),
             p0_vertex=("vertex", np.r_[0.45 * np.sin(t), np.nan, 0.1 * t[:10]]),
             curve_index=("vertex", np.r_[np.zeros(50, int), -1, np.ones(10, int)]),
             kind=("curve", ["peninsula", "saddle"]), C_level=("curve", [0.0, 0.1])),
        coords=dict(gamma_rm=g, xi_rm=xi, q0=q0, p0=p0),
        attrs=dict(F=0.0876, Omega=0.92, Psi=0.0, xi_max=0.24, fourier="paper", saddle_gamma=np.pi,
                   saddle_xi=0.2))


def nested(param="xi_max", n=40):
    q0 = np.linspace(-0.95, 0.95, n)
    p0 = np.linspace(-0.75, 0.75, n)
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    R = np.hypot(Q / 0.9, P / 0.7)
    vals = [0.1, 0.2, 0.24] if param == "xi_max" else [0.005, 0.01, 0.02]
    radii = [0.4 + v for v in vals] if param == "xi_max" else [0.7 - 5 * v for v in vals]
    ec = np.stack([np.where(R < r, np.inf, RNG.uniform(0, 100, R.shape)) for r in radii])
    if param == "xi_max":
        chart = xr.Dataset(dict(escape_cycle_energy=(("xi_max", "q0", "p0"), ec)),
                           coords=dict(xi_max=vals, q0=q0, p0=p0),
                           attrs=dict(F=0.015, Omega=1.04, Psi=np.pi, cycles=100, scan="xi_max", agreement_t_eval=100))
    else:
        chart = xr.Dataset(dict(escape_cycle_energy=(("F", "xi_max", "q0", "p0"), ec[:, None])),
                           coords=dict(F=vals, xi_max=[0.18], q0=q0, p0=p0),
                           attrs=dict(Omega=0.9, Psi=np.pi, cycles=100, scan="F", agreement_t_eval=100))
    chart["iou"] = ((param,), [0.9, 0.95, 0.97])
    chart["pixel_agreement"] = ((param,), [0.99, 0.98, 0.97])
    t = np.linspace(0, 2 * np.pi, 60)
    qv = np.stack([0.9 * r * np.cos(t) for r in radii])
    pv = np.stack([0.7 * r * np.sin(t) for r in radii])
    basins = xr.Dataset(
        dict(q0_vertex=((param, "vertex"), qv), p0_vertex=((param, "vertex"), pv),
             curve_index=((param, "vertex"), np.zeros(qv.shape, int)),
             kind=((param, "curve"), [["island"]] * 3),
             escapes=((param, "q0", "p0"), ~np.isinf(ec))),
        coords={param: vals, "q0": q0, "p0": p0})
    return basins, chart


def strobe():
    n, it = 6, 200
    th = RNG.uniform(0, 6.3, (n, 1)) + np.arange(it) * RNG.uniform(0.1, 0.4, (n, 1))
    r = RNG.uniform(0.1, 0.5, (n, 1))
    return xr.Dataset(dict(q=(("sample", "iteration"), r * np.cos(th)), p=(("sample", "iteration"), r * np.sin(th)),
                           escaped=("sample", np.zeros(n, bool))),
                      attrs=dict(F=0.0876, Omega=0.99, Psi=np.pi, xi_max=0.24, seed=1))


def criteria():
    F = np.arange(0.001, 0.072, 0.01)
    rd = F[:, None] * (1 + 0.3 * RNG.standard_normal((F.size, 5)))
    return xr.Dataset(dict(rel_diff=(("F", "repeat"), rd)), coords=dict(F=F, repeat=np.arange(5)),
                      attrs=dict(Omega=0.9, Psi=0.0, xi_max=0.25, q_max=1.0, n_ic=10000, cycles=3000))


def dsb_esb(n=40, cycles=1000):
    q0 = np.linspace(-1, 1, n)
    p0 = np.linspace(-1, 1, n)
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    R = np.hypot(Q, P)
    e = np.where(R < 0.4, np.inf, RNG.uniform(0, cycles, R.shape))
    d = np.where(R < 0.5, np.inf, e * 1.2)
    return xr.Dataset(dict(escape_cycle_energy=(("xi_max", "q0", "p0"), e[None]),
                           escape_cycle_displacement=(("q_max", "q0", "p0"), d[None])),
                      coords=dict(xi_max=[0.25], q_max=[1.0], q0=q0, p0=p0),
                      attrs=dict(F=0.0876, Omega=0.95, Psi=np.pi, cycles=cycles))


# ------------------------------------------------------------------ helpers
def assert_nontrivial_png(path, min_bytes=15_000):
    assert path.exists() and path.stat().st_size > min_bytes
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 300
    assert float(np.var(img[..., :3])) > 1e-3, "image is (nearly) blank"


def render(fig, tmp_path, name="fig"):
    png, pdf = tmp_path / f"{name}.png", tmp_path / f"{name}.pdf"
    save_figure(fig, png, pdf, dpi=120)
    plt.close(fig)
    assert pdf.exists() and pdf.stat().st_size > 2000
    assert_nontrivial_png(png)
    return png


# ------------------------------------------------------------------ builders (one per family)
@pytest.mark.parametrize("color_by", ["curve", "mechanism"])
def test_figure_fcr(tmp_path, color_by):
    ds = fcr_stack(n_curve=3 if color_by == "curve" else 1)
    fig = fcr.figure_fcr(ds, color_by=color_by, show_branches=(color_by == "mechanism"))
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "SM" in labels and "SMM" in labels and any("MM" in t and "pi" in t for t in labels)
    assert "ξ" in ax.get_title() or "xi" in ax.get_title()
    render(fig, tmp_path)


def test_fcr_segments_follow_mechanism():
    fig, ax = plt.subplots()
    Om = np.linspace(0, 1, 10)
    mech = np.array([4, 4, 4, 3, 3, 3, 0, 2, 2, 2])
    drawn = fcr.draw_fcr_curve(ax, Om, Om + 1, mech, color="k")
    assert drawn == {2, 3, 4}
    styles = [ln.get_linestyle() for ln in ax.lines]
    assert styles == [":", "-", "--"]
    # runs share their junction point (continuous curve) but never bridge a gap (mechanism none)
    assert len(ax.lines[0].get_xdata()) == 4 and len(ax.lines[1].get_xdata()) == 3
    plt.close(fig)


def test_figure_fcr_comparison(tmp_path):
    for layout in ("panels", "overlay"):
        fig = fcr.figure_fcr_comparison(fcr_stack(), fcr_stack(numeric=True), layout=layout)
        assert len(fig.axes) == (3 if layout == "panels" else 1)
        texts = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
        assert any("non-monotone" in t for t in texts)
        render(fig, tmp_path, layout)


def test_figure_rm_basin(tmp_path):
    fig = basins.figure_rm_basin(rm_basin())
    left, right = fig.axes[:2]
    assert left.get_xlabel().endswith(r"$\gamma$") and left.get_ylabel().endswith(r"$\xi$")
    assert "q_0" in right.get_xlabel() and "p_0" in right.get_ylabel()
    # truncation level dashed at xi_max, red boundary present on both panels
    assert any(ln.get_linestyle() == "--" and np.allclose(ln.get_ydata(), 0.24) for ln in left.lines)
    for ax in (left, right):
        assert any(ln.get_color() == SB_EDGE for ln in ax.lines)
    assert "0.0876" in fig._suptitle.get_text()
    render(fig, tmp_path)


@pytest.mark.parametrize("param", ["xi_max", "F"])
def test_figure_nested_basins(tmp_path, param):
    basins_ds, chart = nested(param)
    fig = charts.figure_nested_basins(basins_ds, chart)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert sum("IoU" in t for t in texts) == 3
    assert any("escape for all" in t for t in texts)
    render(fig, tmp_path)


def test_nested_shading_lighter_contains_darker():
    _, chart = nested("xi_max")
    vals, masks = charts.scan_masks(chart, "xi_max", 100)
    fig, ax = plt.subplots()
    shade = charts.draw_nested_safe(ax, masks)
    plt.close(fig)
    order = sorted(shade, key=lambda i: float(shade[i]))  # darkest (smallest grey value) first
    for darker, lighter in zip(order, order[1:]):
        assert float(shade[lighter]) > float(shade[darker])
        assert not (masks[darker].values & ~masks[lighter].values).any()


def test_period_map_criteria_dsb_area(tmp_path):
    render(maps.figure_period_map(rm_basin(), strobe()), tmp_path, "strobe")
    fig = charts.figure_criteria(criteria())
    colors = [ln.get_color() for ln in fig.axes[0].lines if ln.get_marker() == "o"]
    assert colors == ["tab:blue", "tab:orange", "tab:green"]
    render(fig, tmp_path, "criteria")
    fig = charts.figure_dsb_esb(dsb_esb(), None, t_evals=[100, 1000])
    assert [ax.get_title() for ax in fig.axes[:2]] == [r"$t_{eval}$ = 100 EC", r"$t_{eval}$ = 1,000 EC"]
    render(fig, tmp_path, "dsb")
    fig = charts.figure_area_vs_time(dsb_esb(), None, t_evals=list(range(50, 1001, 50)))
    ls = sorted(ln.get_linestyle() for ln in fig.axes[0].lines)
    assert ls == ["-", "--"]
    render(fig, tmp_path, "area")


# ------------------------------------------------------------------ small helpers
def test_exact_names_fail_loudly():
    """A missing variable or parameter is a KeyError naming the dataset and the name."""
    ds = rm_basin().drop_vars("q0_vertex")
    ds.encoding["source"] = "results/data/analytic/basin_figXX.nc"
    with pytest.raises(KeyError, match="basin_figXX.nc.*'q0_vertex'"):
        basins.boundary_polylines(ds, "q0_vertex", "p0_vertex")
    with pytest.raises(KeyError, match="'saddle_gamma'"):
        basins.figure_rm_basin(rm_basin().drop_attrs(deep=False).assign_attrs(F=0.1, Omega=0.9, Psi=0.0, xi_max=0.2))
    plt.close("all")


def test_fmt_and_boundary_polylines():
    assert fmt_value(np.pi, "Psi") == r"$\pi$"
    assert fmt_value(1.0, "Psi") == "1"
    assert fmt_value(5e-5) == "5e-05"
    polys = basins.boundary_polylines(rm_basin(), "q0_vertex", "p0_vertex")
    assert len(polys) == 2 and polys[1][2] == "saddle"


def test_break_wraps():
    x, y = basins.break_wraps([3.0, 3.1, -3.1, -3.0], [0, 1, 2, 3])
    assert np.isnan(x[2]) and x.size == 5


def test_interior_curves_are_not_drawn_as_boundaries():
    q0 = np.linspace(-1, 1, 41)
    p0 = np.linspace(-1, 1, 41)
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    safe = xr.DataArray(np.hypot(Q, P) < 0.6, dims=("q0", "p0"), coords=dict(q0=q0, p0=p0))
    t = np.linspace(0, 2 * np.pi, 80)
    assert basins.separates_mask(0.6 * np.cos(t), 0.6 * np.sin(t), safe)       # the edge
    assert not basins.separates_mask(0.3 * np.cos(t), 0.3 * np.sin(t), safe)   # inside the basin
    assert not basins.separates_mask(0.9 * np.cos(t), 0.9 * np.sin(t), safe)   # in the escape region
