"""Unit tests of safebasins.plotting on tiny synthetic datasets in the contract format
(docs/contracts.md).  Each figure builder must produce a non-trivial PNG (size, pixel variance)
without touching the physics code."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg
import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from safebasins.plotting import basins, charts, curves, fcr, maps
from safebasins.plotting.captions import notes
from safebasins.plotting.style import SB_EDGE, fmt_value, save_figure

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
        attrs=dict(F=0.0876, Omega=0.92, Psi=0.0, xi_max=0.24, fourier="paper", well="quartic", saddle_gamma=np.pi,
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
    chart["safe_numeric"] = ((param,), np.isinf(ec).sum(axis=(1, 2)))
    chart["safe_analytic"] = ((param,), np.isinf(ec).sum(axis=(1, 2)) + 3)
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
    """Six orbits in the format of analysis.period_map.period_map_portrait: four tori around the
    centre, one on a period-3 chain (with its elliptic orbit), one chaotic."""
    n, it = 6, 200
    th = RNG.uniform(0, 6.3, (n, 1)) + np.arange(it) * RNG.uniform(0.1, 0.4, (n, 1))
    r = RNG.uniform(0.1, 0.5, (n, 1))
    q, p = r * np.cos(th), r * np.sin(th)
    k = np.arange(it) % 3
    isl = 0.6 * np.exp(2j * np.pi * k / 3) + 0.03 * np.exp(0.7j * np.arange(it))
    q[4], p[4] = isl.real, isl.imag
    q[5], p[5] = RNG.uniform(-0.7, 0.7, it), RNG.uniform(-0.7, 0.7, it)
    chain_pts = 0.6 * np.exp(2j * np.pi * np.arange(3) / 3)
    return xr.Dataset(
        dict(q=(("sample", "iteration"), q), p=(("sample", "iteration"), p),
             escaped=("sample", np.zeros(n, bool)), q0=("sample", q[:, 0]), p0=("sample", p[:, 0]),
             origin=("sample", ["line"] * 2 + ["random"] * 4),
             orbit_class=("sample", np.array([1, 1, 1, 1, 2, 3], np.int8)),
             rotation_number=("sample", [0.05, 0.06, 0.055, 0.058, 1 / 3, 0.2]),
             birkhoff_digits=("sample", [12.0, 11.0, 13.0, 10.0, 9.0, 2.0]),
             period=("sample", [0, 0, 0, 0, 3, 0]), chain_index=("sample", [-1, -1, -1, -1, 0, -1]),
             escape_cycle_energy=("sample", [np.inf] * 4 + [12.0, 3.0]),
             escape_cycle_displacement=("sample", [np.inf] * 6),
             chain_period=("chain", [3]), chain_n_orbits=("chain", [1]), chain_trace=("chain", [1.2]),
             chain_q=(("chain", "island"), chain_pts.real[None]), chain_p=(("chain", "island"), chain_pts.imag[None])),
        attrs=dict(F=0.0876, Omega=0.99, Psi=np.pi, xi_max=0.24, q_max=0.894, criterion="displacement", seed=1,
                   well="quartic", center_q=0.0, center_p=0.0, center_rotation=0.06, n_iter=it - 1, min_digits=5.0,
                   n_candidates=40, n_non_escaping=10, n_line=3))


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
                      attrs=dict(F=0.0876, Omega=0.95, Psi=np.pi, cycles=cycles, t_eval=[100, cycles]))


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
    fig = maps.figure_period_map(rm_basin(), strobe())
    text = " ".join(notes(fig))
    assert "1 island chain" in text and "period 3" in text and "Stochastic layer: 1 orbit" in text
    assert "only 4 of these 6 orbits survive" in text  # energy-criterion escapes read from the data
    assert any(t.get_text() == "1:3 (A)" for t in fig.axes[0].texts)  # the chain is labelled m:k by its rotation
    render(fig, tmp_path, "strobe")
    fig = charts.figure_criteria(criteria())
    colors = [ln.get_color() for ln in fig.axes[0].lines if ln.get_marker() == "o"]
    assert colors == ["tab:blue", "tab:orange", "tab:green"]
    render(fig, tmp_path, "criteria")
    fig = charts.figure_dsb_esb(dsb_esb(), None, t_evals=[100, 1000])
    assert [ax.get_title() for ax in fig.axes[:2]] == [r"$t_{eval}$ = 100 EC", r"$t_{eval}$ = 1,000 EC"]
    render(fig, tmp_path, "dsb")
    chart = dsb_esb()
    fig = charts.figure_area_vs_time(chart, None, t_evals=list(range(50, 1001, 50)))
    for ax in fig.axes[:2]:
        ls = sorted(ln.get_linestyle() for ln in ax.lines if ln.get_linestyle() in ("-", "--"))
        assert ls == ["-", "--"]
    lin, log = fig.axes[:2]
    assert lin.get_xscale() == "linear" and lin.lines[0].get_marker() == "o"  # as in the paper: points per t_eval
    assert len(lin.lines[0].get_xdata()) == 20
    assert log.get_xscale() == "log" and log.get_xlim()[0] == 1.0  # the early transient shows
    ec = chart["escape_cycle_energy"].values
    last = ec[np.isfinite(ec)].max()
    assert f"loses its last pixel at {charts.ec(last)} and keeps {int(np.isinf(ec).sum()):,} pixels" in \
        " ".join(notes(fig))
    render(fig, tmp_path, "area")


def test_settle_time_and_coincident_curves():
    t = np.array([1, 2, 5, 10, 20, 50, 100.0])
    n = np.array([500, 300, 120, 104, 101, 100, 100.0])
    assert charts.settle_time(t, n, 0.01) == 20 and charts.settle_time(t, n, 0.05) == 10
    s = np.linspace(0, 2 * np.pi, 200)
    circle = (0, np.cos(s), np.sin(s))
    same = (1, np.cos(s[::-1]), np.sin(s[::-1]))        # the same curve, other direction and slice
    other = (2, 1.1 * np.cos(s), 1.1 * np.sin(s))
    assert [g for g, _ in charts.coincident_groups([circle, same, other], tol=0.01)] == [[0, 1]]
    (g, d), = charts.coincident_groups([circle, other], tol=0.2)
    assert g == [0, 1] and 0.09 < d < 0.11  # the largest distance between the two is reported


def test_nested_basins_draw_shared_boundaries_in_alternating_colours(tmp_path):
    b, chart = nested("xi_max")
    b["q0_vertex"][:2] = b["q0_vertex"][0]  # the two smallest basins share their boundary
    b["p0_vertex"][:2] = b["p0_vertex"][0]
    fig = charts.figure_nested_basins(b, chart)
    assert any("shared by 0.1, 0.2" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    assert any("coincide along one curve" in n_ for n_ in notes(fig))
    render(fig, tmp_path, "shared")


# ------------------------------------------------------------------ small helpers
def test_exact_names_fail_loudly():
    """A missing variable or parameter is a KeyError naming the dataset and the name."""
    ds = rm_basin().drop_vars("q0_vertex")
    ds.encoding["source"] = "results/data/analytic/basin_figXX.nc"
    with pytest.raises(KeyError, match="basin_figXX.nc.*'q0_vertex'"):
        curves.boundary_polylines(ds, "q0_vertex", "p0_vertex")
    with pytest.raises(KeyError, match="'saddle_gamma'"):
        basins.figure_rm_basin(rm_basin().drop_attrs(deep=False).assign_attrs(F=0.1, Omega=0.9, Psi=0.0, xi_max=0.2))
    plt.close("all")


def test_fmt_and_boundary_polylines():
    assert fmt_value(np.pi, "Psi") == r"$\pi$"
    assert fmt_value(1.0, "Psi") == "1"
    assert fmt_value(5e-5) == "5e-05"
    polys = curves.boundary_polylines(rm_basin(), "q0_vertex", "p0_vertex")
    assert len(polys) == 2 and polys[1][2] == "saddle"


def test_break_wraps():
    x, y = curves.break_wraps([3.0, 3.1, -3.1, -3.0], [0, 1, 2, 3])
    assert np.isnan(x[2]) and x.size == 5


def test_interior_curves_are_not_drawn_as_boundaries():
    q0 = np.linspace(-1, 1, 41)
    p0 = np.linspace(-1, 1, 41)
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    safe = xr.DataArray(np.hypot(Q, P) < 0.6, dims=("q0", "p0"), coords=dict(q0=q0, p0=p0))
    t = np.linspace(0, 2 * np.pi, 80)
    assert curves.separates_mask(0.6 * np.cos(t), 0.6 * np.sin(t), safe)       # the edge
    assert not curves.separates_mask(0.3 * np.cos(t), 0.3 * np.sin(t), safe)   # inside the basin
    assert not curves.separates_mask(0.9 * np.cos(t), 0.9 * np.sin(t), safe)   # in the escape region


def test_rm_basin_marks_parts_the_numerics_do_not_keep(tmp_path):
    """A slow-flow part that fewer than half of its ICs survive in the stored numeric check is
    drawn dotted/hatched and named apart in the title's (paper's) classification; the caption
    gives the rule and the fractions."""
    ds = rm_basin()
    Q, P = np.meshgrid(ds.q0.values, ds.p0.values, indexing="ij")
    blob = np.hypot(Q - 0.7, P - 0.5) < 0.15
    ds["escapes"] = (("q0", "p0"), ~((Q**2 + P**2 <= 0.2) | blob))
    t = np.linspace(0, 2 * np.pi, 50)
    ds = ds.drop_dims("vertex").assign(
        q0_vertex=("vertex", np.r_[0.45 * np.cos(t), np.nan, 0.7 + 0.15 * np.cos(t)]),
        p0_vertex=("vertex", np.r_[0.45 * np.sin(t), np.nan, 0.5 + 0.15 * np.sin(t)]),
        gamma=("vertex", np.r_[t - np.pi, np.nan, t - np.pi]),
        xi=("vertex", np.r_[0.1 + 0 * t, np.nan, 0.245 + 0.002 * np.sin(t)]),
        curve_index=("vertex", np.r_[np.zeros(50, int), -1, np.ones(50, int)]),
        kind=("curve", ["saddle", "island"]), C_level=("curve", [0.0, 0.1]))
    region = np.where(Q**2 + P**2 <= 0.2, 1, np.where(blob, 2, 0))
    ds["region"] = (("q0", "p0"), region)
    ds["region_size"] = ("region_index", [(region == 1).sum(), (region == 2).sum()])
    ds["region_numeric_safe"] = ("region_index", [0.9, 0.3])
    ds.attrs["check_cycles"] = 100
    assert basins.unconfirmed_parts(ds)[0] == {1}
    fig = basins.figure_rm_basin(ds)
    assert fig._suptitle.get_text().endswith("[saddle type (SBST); not confirmed: maximum type (SBMT), island]")
    text = " ".join(notes(fig))
    assert "Part 1: " in text and "90.0% stay (confirmed)" in text and "30.0% stay (not confirmed)" in text
    assert f"at least {100 * basins.CONFIRMED_FROM:.0f}% of its ICs stay" in text
    dotted = [a for a in fig.axes[1].lines + fig.axes[1].patches if a.get_linestyle() in (":", "dotted")]
    assert dotted, "the unconfirmed island is drawn dotted"
    render(fig, tmp_path, "rm_unconfirmed")


def test_join_seams_removes_zero_length_gaps():
    x, y = curves.join_seams([0.0, 1.0, np.nan, 1.0, 2.0, np.nan, 5.0], [0, 1, np.nan, 1, 0, np.nan, 3])
    assert np.isnan(x).sum() == 1 and x.size == 6
