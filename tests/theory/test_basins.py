"""Safe-basin boundaries (Sec. 2.3, eqs 27-28) vs the escape classification, Figs 5-9, 13, 14."""
import numpy as np
import pytest
from scipy import ndimage

from safebasins.theory import (escapes_on_manifold, first_integral, phase_point, safe_basin_boundaries,
                               saddles, slow_flow_escapes)

FIGS = {   # (F, Omega, Psi, xi_max) -> expected kinds
    "fig5": ((0.0876, 0.92, 0.0, 0.24), {"island"}),
    "fig6": ((0.0876, 1.04, 0.0, 0.249), {"peninsula"}),
    "fig7": ((0.0876, 0.57, 0.0, 0.21), {"peninsula"}),
    "fig8": ((0.0876, 0.57, 0.0, 0.2499), {"saddle", "island"}),
    "fig9": ((0.0478, 0.76, 0.0, 0.235), {"saddle", "island"}),
    "fig13": ((0.015, 1.04, np.pi, 0.2), {"peninsula"}),
    "fig14": ((0.01, 0.9, np.pi, 0.15), {"saddle", "island"}),
}


@pytest.mark.parametrize("name", list(FIGS))
def test_kinds_and_layout(name):
    args, kinds = FIGS[name]
    ds = safe_basin_boundaries(*args, n_points=200)
    assert set(ds.kind.values.tolist()) == kinds
    assert set(ds.dims) == {"curve", "vertex"}
    for v in ("gamma", "xi", "q0_vertex", "p0_vertex", "curve_index"):
        assert ds[v].dims == ("vertex",)
    assert ds.kind.dims == ("curve",) and ds.C_level.dims == ("curve",)
    for a in ("F", "Omega", "Psi", "xi_max", "fourier", "saddle_gamma", "saddle_xi"):
        assert a in ds.attrs
    assert set(np.unique(ds.curve_index)) == set(range(ds.sizes["curve"]))
    fin = np.isfinite(ds.gamma.values)
    assert (np.abs(ds.gamma.values[fin]) <= np.pi + 1e-12).all()
    assert (ds.xi.values[fin] <= args[3] + 1e-12).all()
    # vertices lie on their level curve and map to the IC plane through eqs (15), (17)
    C = first_integral(ds.gamma.values[fin], ds.xi.values[fin], args[0], args[1])
    lev = ds.C_level.values[ds.curve_index.values[fin]]
    assert np.abs(C - lev).max() < 1e-10
    q, p = phase_point(ds.gamma.values[fin] + args[2], ds.xi.values[fin])
    np.testing.assert_allclose(ds.q0_vertex.values[fin], q, atol=1e-12)
    np.testing.assert_allclose(ds.p0_vertex.values[fin], p, atol=1e-12)
    if "saddle" in kinds:
        gs, xs = ds.attrs["saddle_gamma"], ds.attrs["saddle_xi"]
        assert (gs, pytest.approx(xs, abs=1e-12)) in [(g, x) for g, x in saddles(*args[:2], args[3])]
    else:
        assert np.isnan(ds.attrs["saddle_xi"])


@pytest.mark.parametrize("name", list(FIGS))
def test_boundary_separates_safe_from_escaping(name):
    """Just inside every boundary (towards its safe side) the slow flow is safe; just outside it
    escapes unless another basin's condition holds there."""
    (F, Om, Psi, xm), _ = FIGS[name]
    ds = safe_basin_boundaries(F, Om, Psi, xm, n_points=150)
    g, x, k = ds.gamma.values, ds.xi.values, ds.curve_index.values
    sel = np.isfinite(g) & (np.abs(g) > 0.05) & (np.abs(g) < np.pi - 0.05) & (x < xm * (1 - 1e-3))
    g, x, k = np.abs(g[sel]), x[sel], k[sel]
    side = ds.safe_sign.values[k]          # -1: safe towards gamma = 0
    d = 2e-3
    inner = escapes_on_manifold(g + side * d, x, F, Om, xm)
    outer = escapes_on_manifold(g - side * d, x, F, Om, xm)
    assert not inner.any()
    assert outer.mean() > 0.9


def _inside(poly_x, poly_y, px, py):
    """Even-odd point-in-polygon (ray casting), vectorised over points."""
    inside = np.zeros(px.shape, bool)
    x0, y0 = poly_x, poly_y
    x1, y1 = np.roll(poly_x, -1), np.roll(poly_y, -1)
    for a, b, c, e in zip(x0, y0, x1, y1):
        cond = (b > py) != (e > py)
        xint = a + (py - b) * (c - a) / np.where(e != b, e - b, 1.0)
        inside ^= cond & (px < xint)
    return inside


@pytest.mark.parametrize("name", ["fig13", "fig6", "fig7", "fig5"])
def test_ic_plane_polygon_matches_slow_flow_escapes(name):
    """Single-curve basins: ICs inside the returned (q0, p0) polygon are safe, outside escape."""
    (F, Om, Psi, xm), _ = FIGS[name]
    ds = safe_basin_boundaries(F, Om, Psi, xm, n_points=300)
    assert ds.sizes["curve"] == 1
    fin = np.isfinite(ds.q0_vertex.values)
    qx, py_ = ds.q0_vertex.values[fin], ds.p0_vertex.values[fin]
    rng = np.random.default_rng(5)
    q = rng.uniform(-1, 1, 4000)
    p = rng.uniform(-0.75, 0.75, 4000)
    dist = np.min(np.hypot(q[:, None] - qx[None, :], p[:, None] - py_[None, :]), axis=1)
    far = dist > 0.01
    ins = _inside(qx, py_, q, p)
    safe = ~slow_flow_escapes(q, p, F, Om, Psi, xm)
    assert ins[far].sum() > 50
    np.testing.assert_array_equal(ins[far], safe[far])


def test_fig14_basin_is_disjoint_and_fig9_coexists():
    q = np.linspace(-1, 1, 201)
    Q, P = np.meshgrid(q, q, indexing="ij")
    (F, Om, Psi, xm), _ = FIGS["fig14"]
    _, n = ndimage.label(~slow_flow_escapes(Q, P, F, Om, Psi, xm))
    assert n == 2
    # a larger threshold merges the pieces again (Fig 14's sequence in xi_max)
    _, n = ndimage.label(~slow_flow_escapes(Q, P, F, Om, Psi, 0.22))
    assert n == 1
    ds = safe_basin_boundaries(*FIGS["fig9"][0])
    kinds = ds.kind.values.tolist()
    assert "saddle" in kinds and "island" in kinds
    assert ds.ray.values[kinds.index("saddle")] == 0.0
    assert ds.ray.values[kinds.index("island")] == pytest.approx(np.pi)


def test_no_forcing_no_boundary_and_exact_fourier():
    ds = safe_basin_boundaries(0.0, 0.9, 0.0, 0.2)
    assert ds.sizes["curve"] == 0 and ds.sizes["vertex"] == 0
    de = safe_basin_boundaries(0.0876, 0.92, 0.0, 0.24, fourier="exact", n_points=50)
    assert de.attrs["fourier"] == "exact" and de.sizes["curve"] >= 1


@pytest.mark.parametrize("kw, name", [
    (dict(F=-0.1), "F"), (dict(Omega=0.0), "Omega"), (dict(Psi=np.nan), "Psi"),
    (dict(xi_max=0.0), "xi_max"), (dict(xi_max=0.3), "xi_max"), (dict(n_points=0), "n_points"),
    (dict(fourier="x"), "fourier"),
])
def test_out_of_domain_raises(kw, name):
    args = dict(F=0.01, Omega=0.9, Psi=0.0, xi_max=0.1)
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        safe_basin_boundaries(**args)
