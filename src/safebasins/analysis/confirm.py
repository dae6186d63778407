"""Numeric confirmation of the connected parts of an analytic safe basin.

The slow flow (isolated 1:1 resonance) can predict safe regions the full dynamics does not
have, e.g. the thin islands just below the separatrix that the ``xi -> 1/4`` singularity of the
first harmonic creates (``G'(xi) -> -inf``): Fig 8 at ``xi_max = 0.2499``.  Integrating the ICs of
each connected part of the analytic basin tells them apart from the real basin.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from safebasins.analysis.safe import is_safe

__all__ = ["confirm_regions"]


def confirm_regions(safe_analytic: npt.ArrayLike, escape_cycle: npt.ArrayLike, t_eval: float
                    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    """Connected parts of an analytic safe mask and the fraction of each that the numerics keep.

    Parameters
    ----------
    safe_analytic
        Bool array (q0, p0), True = safe in the slow flow.
    escape_cycle
        Numeric escape cycles of the same grid (only the analytic-safe entries are
        read; ``inf`` = no escape within the horizon).
    t_eval
        Evaluation time (forcing cycles): numerically safe = ``escape_cycle > t_eval``.

    Returns
    -------
    labels, size, fraction
        Region label per grid point (0 = analytic escape, 1..n = regions, 8-connected,
        numbered by decreasing size), the pixel count and the numerically safe fraction of
        each region (arrays of length n).
    """
    s = np.asarray(safe_analytic, bool)
    e = np.asarray(escape_cycle, float)
    if s.shape != e.shape or s.ndim != 2:
        raise ValueError(f"safe_analytic and escape_cycle must be 2-D of one shape, got {s.shape} and {e.shape}")
    lab, n = ndimage.label(s, structure=np.ones((3, 3), bool))
    size = np.bincount(lab.ravel(), minlength=n + 1)[1:]
    order = np.argsort(-size, kind="stable")
    relabel = np.zeros(n + 1, np.int64)
    relabel[order + 1] = np.arange(1, n + 1)
    lab = relabel[lab]
    size = size[order]
    ok = np.where(s, is_safe(np.where(s, e, -np.inf), t_eval), False)
    kept = np.bincount(lab.ravel(), weights=ok.ravel(), minlength=n + 1)[1:]
    return lab, size.astype(np.int64), kept / np.maximum(size, 1)
