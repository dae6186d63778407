"""Basins with known answers, to validate the fractal boundary measures (docs/basin-measures.md).

cantor_basins   the two exits of an expanding open map: the basin boundary is a Cantor set
                (times an interval), box dimension ``1 + log 2 / log s`` in closed form, so the
                uncertainty exponent is ``1 - log 2 / log s``
newton_basins   the three basins of Newton's method for z^3 = 1: a fractal boundary with the
                Wada property (each basin's boundary is the Julia set)
half_plane, disc, sectors
                smooth boundaries (uncertainty exponent 1; three sectors: not Wada)

Each returns ``(labels, q0, p0)``: int64 labels over an ``ij`` grid and its axes, the input of
:func:`safebasins.analysis.basin_measures.basin_entropy` and its siblings.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from safebasins.core import checks

__all__ = ["cantor_basins", "cantor_exponent", "newton_basins", "half_plane", "disc", "sectors"]

#: iterations of the Cantor map: a pixel centre off the Cantor set exits long before
CANTOR_ITERATIONS = 200
#: Newton iterations: the orbits that have not reached a root by then lie within a few ulps of
#: the Julia set and take the nearest root
NEWTON_ITERATIONS = 60

Extent = tuple[tuple[float, float], tuple[float, float]]
#: labels over an ``ij`` grid and its q0, p0 axes
Basins = tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], npt.NDArray[np.float64]]
WINDOW: Extent = ((-1.0, 1.0), (-1.0, 1.0))
NEWTON_WINDOW: Extent = ((-1.5, 1.5), (-1.5, 1.5))


def _axes(n_q0: int, n_p0: int, extent: Extent) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    n_q0 = checks.check_positive_int("n_q0", n_q0)
    n_p0 = checks.check_positive_int("n_p0", n_p0)
    (a, b), (c, d) = extent
    return np.linspace(a, b, n_q0), np.linspace(c, d, n_p0)


def cantor_exponent(s: int) -> float:
    """Uncertainty exponent of :func:`cantor_basins`: ``1 - log 2 / log s`` (boundary
    ``C_s x [0, 1]``; C_s the Cantor set of two branches of slope s, box dimension log 2 / log s)."""
    return float(1.0 - np.log(2.0) / np.log(float(s)))


def cantor_basins(n_q0: int, n_p0: int = 8, *, s: int = 3) -> Basins:
    """Exit basins of the open map ``x -> s x`` (x <= 1/s), ``x -> s x - (s - 1)`` (x >= 1 - 1/s)
    on [0, 1]: an orbit leaves through the hole ``(1/s, 1 - 1/s)``, label 0 through its left half,
    1 through its right half.  The labels depend on q0 = x only (p0 in [0, 1] is a second axis).

    The boundary of either basin is the closure of the preimages of the hole's centre: the Cantor
    set C_s of the two branches (the middle-thirds set for s = 3), box dimension ``log 2 / log s``
    (a self-similar set of two pieces of ratio 1/s: Falconer, *Fractal Geometry*, ch. 9), so in
    the plane ``d = 1 + log 2 / log s`` and, with ``alpha = D - d`` (McDonald, Grebogi, Ott &
    Yorke, Physica D 17, 125 (1985)), :func:`cantor_exponent` gives alpha.  Pixel centres ``(2 i + 1) / (2 n_q0)`` are
    iterated in exact integer arithmetic; the few centres on C_s itself (they never exit) take
    label 0.
    """
    if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 3:
        raise ValueError(f"s must be an integer >= 3 (two branches and a hole), got {s!r}")
    n_q0 = checks.check_positive_int("n_q0", n_q0)
    n_p0 = checks.check_positive_int("n_p0", n_p0)
    D = 2 * n_q0                                    # x = a / D
    a = 2 * np.arange(n_q0, dtype=np.int64) + 1
    label = np.zeros(n_q0, np.int64)
    alive = np.ones(n_q0, bool)
    for _ in range(CANTOR_ITERATIONS):
        sa = s * a
        hole = alive & (sa > D) & (sa < (s - 1) * D)
        label[hole] = (2 * a[hole] > D).astype(np.int64)
        alive &= ~hole
        if not alive.any():
            break
        a = np.where(sa <= D, sa, sa - (s - 1) * D)
    q0 = (2 * np.arange(n_q0) + 1) / D
    p0 = (2 * np.arange(n_p0) + 1) / (2 * n_p0)
    return np.repeat(label[:, None], n_p0, axis=1), q0, p0


def newton_basins(n_q0: int, n_p0: int | None = None, *, extent: Extent = NEWTON_WINDOW) -> Basins:
    """Basins of the three roots of z^3 = 1 under Newton's map ``z -> (2 z^3 + 1) / (3 z^2)``,
    ``z = q0 + i p0``: label k for the root ``exp(2 pi i k / 3)``.

    Their common boundary is the Julia set of the Newton map: for a rational map the boundary of
    the basin of any attracting cycle is the whole Julia set (Milnor, *Dynamics in One Complex
    Variable*, ch. 4), so the three basins have the Wada property, and the
    Julia set is not a smooth curve (its points see all three basins at every scale).  A node at
    z = 0 exactly (odd n with a symmetric extent) takes label 0.
    """
    q0, p0 = _axes(n_q0, n_q0 if n_p0 is None else n_p0, extent)
    z = q0[:, None] + 1j * p0[None, :]
    z = np.where(z == 0, 1e-300 + 0j, z)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        for _ in range(NEWTON_ITERATIONS):
            z = (2 * z ** 3 + 1) / (3 * z ** 2)
    roots = np.exp(2j * np.pi * np.arange(3) / 3)
    d = np.abs(z[..., None] - roots)
    d = np.where(np.isfinite(d), d, np.inf)
    return np.argmin(d, axis=-1).astype(np.int64), q0, p0


def half_plane(n_q0: int, n_p0: int | None = None, *, angle: float = 0.3, offset: float = 0.05,
               extent: Extent = WINDOW) -> Basins:
    """Label 1 where ``q0 cos(angle) + p0 sin(angle) > offset``, else 0: a straight boundary."""
    q0, p0 = _axes(n_q0, n_q0 if n_p0 is None else n_p0, extent)
    return ((q0[:, None] * np.cos(angle) + p0[None, :] * np.sin(angle)) > offset).astype(np.int64), q0, p0


def disc(n_q0: int, n_p0: int | None = None, *, radius: float = 0.6, centre: tuple[float, float] = (0.05, -0.03),
         extent: Extent = WINDOW) -> Basins:
    """Label 1 inside the disc ``|(q0, p0) - centre| < radius``, else 0: a smooth closed boundary."""
    q0, p0 = _axes(n_q0, n_q0 if n_p0 is None else n_p0, extent)
    r = np.hypot(q0[:, None] - centre[0], p0[None, :] - centre[1])
    return (r < radius).astype(np.int64), q0, p0


def sectors(n_q0: int, n_p0: int | None = None, *, k: int = 3, phase: float = 0.2,
            extent: Extent = WINDOW) -> Basins:
    """``k`` angular sectors about the origin, labels 0..k-1: smooth boundaries that meet only at
    the origin (three or more basins, not Wada: the boundary of one sector is two rays, not all k)."""
    q0, p0 = _axes(n_q0, n_q0 if n_p0 is None else n_p0, extent)
    theta = np.mod(np.arctan2(p0[None, :], q0[:, None]) - phase, 2 * np.pi)
    return np.minimum((theta / (2 * np.pi / k)).astype(np.int64), k - 1), q0, p0
