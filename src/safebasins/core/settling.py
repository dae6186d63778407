"""How long damped transients take: the map iterations after which the seeds of a damped
system have settled on its attractors.  Shared by the attractor analyses (minimal fatal shock,
continuation) and the pipeline's cost estimates, which plan without importing the analyses."""
from __future__ import annotations

import math

__all__ = ["SETTLE", "MIN_ITERATIONS", "settle_iterations"]

#: the damped transient is settled to exp(-SETTLE) when the seeds have been iterated
#: SETTLE / (beta T / 2) periods (the slowest decay rate of a focus is beta / 2)
SETTLE = 15.0
#: map iterations however strong the damping
MIN_ITERATIONS = 50


def settle_iterations(beta: float, Omega: float, n_iter: int | None = None) -> int:
    """Stroboscopic-map iterations that settle damped transients at forcing frequency ``Omega``:
    ``n_iter`` when given, else ``max(50, 2 SETTLE / (beta T))`` with ``T = 2 pi / Omega``."""
    if n_iter is not None:
        return int(n_iter)
    return max(MIN_ITERATIONS, math.ceil(2.0 * SETTLE / (beta * (2.0 * math.pi / Omega))))
