"""Seeded random initial conditions."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from safebasins.core import checks


def random_initial_conditions(n: int, seed: int, box: npt.ArrayLike = ((-1, 1), (-1, 1))
                              ) -> tuple[np.ndarray, np.ndarray]:
    """n ICs uniform in box = ((q_lo, q_hi), (p_lo, p_hi)) from numpy.random.default_rng(seed).

    Returns (q0, p0), 1-D arrays of length n (q0 drawn first, then p0).  Pass them to
    escape_chart with grid=False (paired ICs -> dim 'sample').
    """
    n = checks.check_positive_int("n", n)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    b = checks.check_finite("box", box)
    if b.shape != (2, 2) or not (b[:, 1] > b[:, 0]).all():
        raise ValueError(f"box must be ((q_lo, q_hi), (p_lo, p_hi)) with lo < hi, got {box!r}")
    rng = np.random.default_rng(int(seed))
    q0 = rng.uniform(b[0, 0], b[0, 1], n)
    p0 = rng.uniform(b[1, 0], b[1, 1], n)
    return q0, p0
