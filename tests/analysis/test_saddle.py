"""The forced hilltop saddle's orbit and manifolds (safebasins.analysis.saddle).

Independent routes: the orbit's period mean against the second-order closed form, the two
quartic saddles against the symmetry q -> -q, t -> t + T/2; the manifolds' invariance (points
between the vertices of W^u mapped one period forward by a separate scipy DOP853 integration
land on W^u, W^s backward likewise); at F = 0 without damping both inner branches lie on the
separatrix (energy E_b) and reach its turning point; the signed gap on curves of known geometry;
the manifolds' first tangency within 2% of the Melnikov threshold at beta = 0.1 (the full Brent
root, 2.4e-4 above F_M, takes minutes: docs/melnikov.md).
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins.analysis import hilltop_orbit, saddle_manifolds
from safebasins.analysis.melnikov import melnikov_threshold
from safebasins.analysis.saddle import _tangency_gap, manifold_tangency, signed_gap
from safebasins.wells import resolve_well

CUBIC = resolve_well("cubic")
OMEGA = 0.85


def _flow(F, beta, x, T):
    """Each column of x over time T (< 0: backward), scipy DOP853 at rtol 1e-12, one at a time."""
    out = []
    for y0 in x.T:
        sol = solve_ivp(lambda t, y: [y[1], -y[0] + y[0] ** 2 - beta * y[1] + F * np.sin(OMEGA * t)], (0.0, T), y0,
                        method="DOP853", rtol=1e-12, atol=1e-14)
        out.append(sol.y[:, -1])
    return np.array(out).T


def _distance(points, poly):
    """Distance of each point (2, n) from the polyline poly (m, 2; NaN rows split it)."""
    A, B = poly[:-1], poly[1:]
    ok = np.isfinite(A).all(axis=1) & np.isfinite(B).all(axis=1) & (np.abs(B - A).sum(axis=1) > 0)
    A, B = A[ok], B[ok]
    d = B - A
    x = points.T[:, None, :] - A[None]
    t = np.clip(np.einsum("nmi,mi->nm", x, d) / np.einsum("mi,mi->m", d, d), 0.0, 1.0)
    return np.min(np.hypot(*np.moveaxis(x - t[..., None] * d[None], -1, 0)), axis=1)


def test_hilltop_orbit_dataset_and_second_order_mean():
    ds = hilltop_orbit(0.01, OMEGA, 0.1, "cubic", n_time=32)
    assert ds.sizes == {"saddle": 1, "time": 32, "component": 2}
    for name in ds.data_vars:
        assert "long_name" in ds[name].attrs and "units" in ds[name].attrs, name
    assert "history" in ds.attrs and ds.attrs["well"] == "cubic"
    np.testing.assert_allclose(ds.mean_shift, ds.mean_shift_second_order, rtol=2e-3)   # next order: F^4
    assert float(ds.closure.max()) < 1e-9
    assert float(np.abs(ds.q - ds.q_linear).max()) < 0.3 * 0.01 ** 2
    quartic = hilltop_orbit(0.02, 0.9, 0.05, None, n_time=32)                       # q -> -q, t -> t + T/2
    np.testing.assert_allclose(quartic.q[0], -np.roll(quartic.q[1].values, 16), atol=1e-9)
    with pytest.raises(ValueError, match="barrier"):
        hilltop_orbit(0.01, OMEGA, 0.1, "cubic", barrier="left")
    with pytest.raises(ValueError, match="Omega"):
        hilltop_orbit(0.01, -1.0)


def _curve(ds, kind, side):
    c = int(np.flatnonzero((ds.kind.values == kind) & (ds.side.values == side))[0])
    sel = ds.curve_index.values == c
    return np.stack([ds.q0_vertex.values[sel], ds.p0_vertex.values[sel]], axis=1), ds.iterate.values[sel]


def test_manifolds_are_invariant():
    F, beta = 0.03, 0.1
    ds = saddle_manifolds(F, OMEGA, beta, "cubic", iterations=2, ds_max=0.05, rtol=1e-10)
    T = 2 * np.pi / OMEGA
    for kind, direction in (("unstable", 1.0), ("stable", -1.0)):
        poly, it = _curve(ds, kind, "inner")
        P, P_next = poly[it == 1], poly[it == 2]
        mid = 0.5 * (P[:-1] + P[1:])                                # between the vertices: not on any orbit computed
        kept = np.isfinite(mid).all(axis=1) & np.isfinite(P_next[:-1] + P_next[1:]).all(axis=1)
        mid = mid[kept][::4].T                                      # (whose neighbours' images stayed in the box)
        assert mid.shape[1] >= 8
        image = _flow(F, beta, mid, direction * T)
        assert np.max(_distance(image, poly)) < 5e-4, kind
        # the other manifold is not invariant under this direction of time
        other, _ = _curve(ds, "stable" if kind == "unstable" else "unstable", "inner")
        assert np.max(_distance(image, other)) > 1e-2


def test_undamped_unforced_manifolds_are_the_separatrix():
    ds = saddle_manifolds(0.0, OMEGA, 0.0, "cubic", iterations=3, ds_max=0.05)
    q, p = ds.q0_vertex.values, ds.p0_vertex.values
    ok = np.isfinite(q)
    E = 0.5 * p[ok] ** 2 + CUBIC.V(q[ok])
    np.testing.assert_allclose(E, 1.0 / 6.0, atol=1e-9)
    for kind in ("unstable", "stable"):
        poly, _ = _curve(ds, kind, "inner")
        assert np.nanmin(poly[:, 0]) == pytest.approx(-0.5, abs=1e-3)            # the turning point
    assert ds.resolved.all() and ds.sizes["saddle"] == 1


def test_signed_gap_on_known_curves():
    s = np.linspace(-1.0, 1.0, 201)
    line = np.stack([s, np.zeros_like(s)], axis=1)               # W^s: the q axis, the well below (p < 0)
    inside = np.array([0.0, -1.0])
    bump = lambda h: np.stack([s, h - 0.5 * s ** 2], axis=1)     # W^u: a parabola, top at p = h
    for h in (-0.02, 0.01, 0.03):
        gap, i, _ = signed_gap(bump(h), line, inside, 0.05)
        assert gap == pytest.approx(h, abs=1e-12) and i == 100
    gap, i, _ = signed_gap(bump(-0.2), line, inside, 0.05)       # nowhere near
    assert (gap, i) == (-0.05, -1)
    with pytest.raises(ValueError, match="damping"):
        manifold_tangency(OMEGA, 0.0, "cubic")


def test_manifolds_touch_at_the_melnikov_threshold():
    F_M = float(melnikov_threshold(OMEGA, 0.1, "cubic"))
    opts = dict(iterations=None, s0=1e-7, ds_max=0.05, angle_max=0.2, max_points=2000, rtol=1e-8)
    below = _tangency_gap(CUBIC, (0.98 * F_M, OMEGA, 0.1, 0.0), (1.0, 1.0), opts, rounds=2)
    past = _tangency_gap(CUBIC, (1.02 * F_M, OMEGA, 0.1, 0.0), (1.0, 1.0), opts, rounds=2)
    assert below < 0 < past and past > 1e-3            # W^u inside W^s, then across it by ~ 0.16 (F / F_M - 1)
