"""Drawing pieces every basin figure shares: boundary curves of a basin dataset, safe-mask fills
and hatches, the unforced well outline (Figs 5-9, 13-18, the extras and the public plotting
functions).

Boundary vertices ``q0_vertex``, ``p0_vertex`` (or ``gamma``, ``xi``), ``curve_index`` on dim
``vertex`` and ``kind`` on dim ``curve`` (:func:`safebasins.theory.safe_basin_boundaries`,
docs/contracts.md).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.patches import Polygon

from safebasins.plotting.data import var
from safebasins.plotting.style import SB_EDGE, SB_FACE

if TYPE_CHECKING:
    import numpy.typing as npt
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.collections import QuadMesh
    from matplotlib.contour import QuadContourSet
    from matplotlib.lines import Line2D

    from safebasins.wells.base import Well

    #: a polyline of a basin dataset: x, y (NaN separators kept) and the kind of its curve
    Polyline = tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], str]


def draw_well(ax: Axes, xi_max: float, well: Well, *, n: int = 400, **kw: Any) -> Line2D:
    """Dashed outline of the unforced well ``H0(q, p) = xi_max`` on a (q, p) axes, between the
    turning points of the level (``-+q_max`` of eq (4) for the quartic)."""
    lo, hi = (float(np.ravel(t)[0]) for t in well.turning_points(xi_max))
    qq = np.linspace(lo, hi, n)
    pp = np.sqrt(np.clip(2 * (xi_max - well.V(qq)), 0, None))
    x = np.r_[qq, qq[::-1], qq[:1]]
    y = np.r_[pp, -pp[::-1], pp[:1]]
    style: dict[str, Any] = dict(color="0.35", lw=0.9, ls=(0, (4, 2)), zorder=4)
    style.update(kw)
    (line,) = ax.plot(x, y, **style)
    return line


def boundary_polylines(ds: xr.Dataset, xname: str, yname: str) -> list[Polyline]:
    """Polylines (x, y, kind) of a safe_basin_boundaries dataset (one slice of a stack);
    ``xname``/``yname``: ``"gamma"``/``"xi"`` on the manifold, ``"q0_vertex"``/``"p0_vertex"``
    on the IC plane."""
    x = np.asarray(var(ds, xname), float)
    y = np.asarray(var(ds, yname), float)
    idx = np.asarray(var(ds, "curve_index"), float)
    idx = np.where(np.isfinite(idx), idx, -1).astype(int)
    kinds = [str(k) for k in np.asarray(var(ds, "kind"))]
    out: list[Polyline] = []
    for ci in np.unique(idx[idx >= 0]):
        sel = idx == ci
        # keep NaN separators that sit between vertices of this curve
        xs, ys = x[sel], y[sel]
        if not np.isfinite(xs).any():
            continue
        out.append((xs, ys, kinds[ci]))
    return out


def join_seams(xs: npt.ArrayLike, ys: npt.ArrayLike,
               tol: float = 1e-9) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Drop NaN separators between coincident vertices (a curve split at the gamma = +-pi cut of
    the cylinder maps to one continuous curve on the IC plane), so that no cap is drawn there."""
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    gap = np.flatnonzero(~np.isfinite(xs) | ~np.isfinite(ys))
    drop = [i for i in gap if 0 < i < xs.size - 1 and np.isfinite(xs[i - 1]) and np.isfinite(xs[i + 1])
            and np.hypot(xs[i + 1] - xs[i - 1], ys[i + 1] - ys[i - 1]) < tol]
    return np.delete(xs, drop), np.delete(ys, drop)


#: boundary lines on the IC plane: round caps and joins, so closed curves have no visible seam
IC_LINE: dict[str, Any] = dict(solid_capstyle="round", solid_joinstyle="round")


def plot_curve(ax: Axes, xs: npt.ArrayLike, ys: npt.ArrayLike, **style: Any) -> list[Line2D] | list[Polygon]:
    """A boundary polyline on the IC plane: seams at the gamma cut removed (:func:`join_seams`);
    a curve that closes on itself is drawn as one closed path (no start / end cap)."""
    xs, ys = join_seams(xs, ys)
    ok = np.isfinite(xs) & np.isfinite(ys)
    if ok.all() and xs.size > 3 and np.hypot(xs[-1] - xs[0], ys[-1] - ys[0]) < 1e-9:
        kw = {k: v for k, v in style.items() if k not in ("solid_capstyle", "solid_joinstyle", "dash_capstyle")}
        kw["edgecolor"] = kw.pop("color", SB_EDGE)
        kw["linewidth"] = kw.pop("lw", 1.8)
        kw["linestyle"] = kw.pop("ls", "-")
        patch = Polygon(np.c_[xs[:-1], ys[:-1]], closed=True, fill=False, joinstyle="round", **kw)
        ax.add_patch(patch)
        return [patch]
    return ax.plot(xs, ys, **style)


def analytic_safe(ds: xr.Dataset) -> xr.DataArray:
    """Analytic safe mask ``~escapes`` over (q0, p0) of one basin slice."""
    return ~var(ds, "escapes").astype(bool)


def separates_mask(xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64], safe: xr.DataArray, *, halo: int = 2,
                   min_fraction: float = 0.5) -> bool:
    """True if the polyline (xs, ys) runs along the edge of the boolean DataArray ``safe``
    (dims q0, p0): at least ``min_fraction`` of its vertices have both safe and escaping
    pixels within ``halo`` pixels.  Level curves of C through a saddle can lie entirely
    inside the predicted basin (e.g. a saddle-type region contained in a peninsula): they are
    not boundaries of the safe basin and are not drawn on the IC plane."""
    q = np.asarray(safe["q0"], float)
    p = np.asarray(safe["p0"], float)
    S = np.asarray(safe.transpose("q0", "p0")).astype(bool)
    ok = np.isfinite(xs) & np.isfinite(ys)
    if not ok.any():
        return False
    i = np.clip(np.searchsorted(q, xs[ok]), 0, q.size - 1)
    j = np.clip(np.searchsorted(p, ys[ok]), 0, p.size - 1)
    edge = np.zeros(i.size, bool)
    for k, (a, b) in enumerate(zip(i, j)):
        win = S[max(a - halo, 0):a + halo + 1, max(b - halo, 0):b + halo + 1]
        edge[k] = win.any() and not win.all()
    return bool(edge.mean() >= min_fraction)


def draw_boundaries(ax: Axes, ds: xr.Dataset, *, safe: xr.DataArray | None = None,
                    **kw: Any) -> list[Line2D | Polygon]:
    """Boundary polylines of a basin dataset on the IC plane.  With ``safe`` (the analytic safe
    mask on (q0, p0)), curves that do not border it are skipped (:func:`separates_mask`)."""
    style: dict[str, Any] = dict(color=SB_EDGE, lw=1.8, zorder=6, **IC_LINE)
    style.update(kw)
    lines: list[Line2D | Polygon] = []
    for xs, ys, _kind in boundary_polylines(ds, "q0_vertex", "p0_vertex"):
        if safe is not None and not separates_mask(xs, ys, safe):
            continue
        lines += plot_curve(ax, xs, ys, **style)
    return lines


def break_wraps(x: npt.ArrayLike, y: npt.ArrayLike,
                period: float = 2 * np.pi) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Insert NaN where a periodic coordinate jumps by more than half a period."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if x.size < 2:
        return x, y
    jumps = np.flatnonzero(np.abs(np.diff(x)) > period / 2) + 1
    if jumps.size:
        x = np.insert(x, jumps, np.nan)
        y = np.insert(y, jumps, np.nan)
    return x, y


def xy_grid(da: xr.DataArray) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[Any]]:
    """DataArray over (q0, p0) in any order -> (q0, p0, Z) with Z indexed [p0, q0] for pcolor."""
    da = da.transpose("p0", "q0")
    return np.asarray(da["q0"]), np.asarray(da["p0"]), np.asarray(da)


def safe_fill(ax: Axes, x: npt.ArrayLike, y: npt.ArrayLike, safe: npt.NDArray[np.bool_], *, color: str = SB_FACE,
              zorder: float = 1, alpha: float = 1.0) -> QuadMesh:
    """Fill where ``safe`` (2-D, indexed [y, x]) is True with a flat colour."""
    z = np.ma.masked_where(~safe, np.ones(safe.shape))
    return ax.pcolormesh(x, y, z, cmap=ListedColormap([color]), vmin=0, vmax=1, shading="nearest",
                         zorder=zorder, alpha=alpha, rasterized=True, linewidth=0)


def hatch(ax: Axes, x: npt.ArrayLike, y: npt.ArrayLike, mask: npt.ArrayLike, *, color: str, hatches: str = "xxxx",
          zorder: float = 2) -> QuadContourSet | None:
    """Hatch where ``mask`` (2-D, indexed [y, x]) is True, the hatch lines in ``color`` (not the
    default black: on a few pixels a black hatch reads as a stray line)."""
    if not np.asarray(mask).any():
        return None
    with plt.rc_context({"hatch.color": color, "hatch.linewidth": 0.8}):
        return ax.contourf(x, y, np.asarray(mask, float), levels=[0.5, 1.5], colors="none", hatches=[hatches],
                           zorder=zorder)
