"""The binomial statistics of escape counts: the 95% Wilson interval of a fraction of paths, and
what a number of paths can certify.  Used by the noisy ensembles (their P_escape intervals), the
stochastic safe basin (its conservative set) and the pipeline's config checks, which plan
without importing the numerics."""
from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from safebasins.core import checks

__all__ = ["WILSON_Z", "wilson_interval", "certifiable_epsilon", "paths_needed"]

#: the normal quantile of the 95% Wilson interval
WILSON_Z = 1.959963984540054


def wilson_interval(k: npt.ArrayLike, n: int, z: float = WILSON_Z) -> tuple[np.ndarray, np.ndarray]:
    """The Wilson score interval (low, high) of a binomial proportion k / n (95% for the default z)."""
    kk = np.asarray(k, dtype=float)
    p = kk / n
    z2 = z * z
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = z / (1 + z2 / n) * np.sqrt(p * (1 - p) / n + z2 / (4 * n * n))
    # the ends are exactly 0 at k = 0 and 1 at k = n (the rounding of centre -+ half is not)
    low = np.where(kk == 0, 0.0, np.clip(centre - half, 0.0, 1.0))
    high = np.where(kk == n, 1.0, np.clip(centre + half, 0.0, 1.0))
    return low, high


def certifiable_epsilon(paths: int) -> float:
    """The smallest upper end of the 95% Wilson interval ``paths`` paths can give (none escaped):
    ``z^2 / (paths + z^2)``; a conservative basin of a smaller epsilon is empty."""
    n = checks.check_positive_int("paths", paths)
    return float(wilson_interval(0, n)[1])


def paths_needed(epsilon: float) -> int:
    """The fewest paths whose Wilson upper bound at no escape is <= ``epsilon`` (a probability in
    (0, 1), checked by the caller): ``ceil(z^2 (1 - epsilon) / epsilon)``, then checked against
    :func:`certifiable_epsilon`."""
    n = max(1, math.ceil(WILSON_Z ** 2 * (1.0 - epsilon) / epsilon))
    while certifiable_epsilon(n) > epsilon:    # the closed form's last-bit rounding
        n += 1
    return n
