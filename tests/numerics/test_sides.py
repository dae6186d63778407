"""barrier_sides replays the chart's trajectory: its crossing step is bit for bit the chart's
first step beyond the barrier (the displacement threshold q_max = 1 of the quartic), and its
side is the sign of q there."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins.numerics import escape_chart
from safebasins.numerics.sides import LEFT, NONE, RIGHT, barrier_sides
from safebasins.wells import cubic

Q0 = np.linspace(-0.95, 0.95, 13)
P0 = np.linspace(-0.7, 0.7, 11)


@pytest.mark.parametrize("damping, F", [(0.0, 0.01), (0.1, 0.2)])
def test_crossing_step_is_the_charts(damping, F):
    ch = escape_chart(Q0, P0, F, 0.9, np.pi, xi_max=(), q_max=(1.0,), cycles=40, damping=damping, grid=True)
    Q, P = np.meshgrid(Q0, P0, indexing="ij")
    side, at = barrier_sides(Q, P, F, 0.9, np.pi, cycles=40, damping=damping)
    t = ch["escape_cycle_displacement"].sel(q_max=1.0).values.ravel()
    steps = np.where(np.isfinite(t), t * ch.attrs["steps_per_cycle"], -1).astype(np.int64)
    np.testing.assert_array_equal(at, steps)
    assert ((side == NONE) == (at < 0)).all()
    assert (side == LEFT).sum() > 5 and (side == RIGHT).sum() > 5 and (side == NONE).sum() > 5


def test_initial_conditions_beyond_a_barrier_and_one_sided_well():
    side, at = barrier_sides([1.2, -1.2, 0.0], [0.0, 0.0, 0.0], 0.0, 1.0, 0.0, cycles=3)
    assert side.tolist() == [RIGHT, LEFT, NONE] and at.tolist() == [0, 0, -1]
    # the cubic has no left barrier: a trajectory running off to the left is never LEFT
    side, _ = barrier_sides([-0.9, 0.5, 0.0], [0.5, 0.5, 0.0], 0.0, 1.0, 0.0, cycles=10, well=cubic())
    assert LEFT not in side.tolist() and side[1] == RIGHT


def test_bad_input():
    with pytest.raises(ValueError, match="q0 and p0"):
        barrier_sides([0.0, 0.1], [0.0], 0.1, 1.0, 0.0, cycles=2)
    with pytest.raises(ValueError, match="F"):
        barrier_sides([0.0], [0.0], -0.1, 1.0, 0.0, cycles=2)
    with pytest.raises(ValueError, match="cycles"):
        barrier_sides([0.0], [0.0], 0.1, 1.0, 0.0, cycles=0)
