"""A step the scheme cannot integrate is refused; a NaN or inf state is never safe."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins import wells
from safebasins.numerics import critical_forcing_numeric, escape_chart, stroboscopic_map
from tests.numerics.ensemble import run_ensemble


@pytest.mark.parametrize("Omega,S,why", [(1e-4, 32, r"use steps_per_cycle >= \d+"),
                                         (0.02, 32, r"use steps_per_cycle >= 281"),   # 2 pi sqrt 2 / (0.02 * 1.5817)
                                         (1e-300, 32, r"Omega = 1e-300 is too small to integrate: .* use a larger "
                                                      r"Omega"),
                                         (1.0, 4, r"use steps_per_cycle >= \d+")])
def test_too_large_a_step_is_refused(Omega, S, why):
    q = np.linspace(-0.5, 0.5, 3)
    with pytest.raises(ValueError, match=r"^steps_per_cycle: .*" + why):
        escape_chart(q, q, 0.01, Omega, 0.0, cycles=2, steps_per_cycle=S)
    with pytest.raises(ValueError, match="steps_per_cycle"):
        stroboscopic_map(q, q, 0.01, Omega, 0.0, n_iter=2, steps_per_cycle=S)
    with pytest.raises(ValueError, match="steps_per_cycle"):
        critical_forcing_numeric([Omega, 1.0], 0.15, cycles=2, n_scan=0, steps_per_cycle=S)


def test_step_limit_follows_the_well():
    """omega_max = sqrt(max |V''|) over the well: sqrt(2) for the quartic (V'' = -2 at |q| = 1) and the
    cubic (at its turning point q = -1/2), 1 for the pendulum."""
    assert wells.QUARTIC.omega_max == pytest.approx(np.sqrt(2.0))
    assert wells.cubic().omega_max == pytest.approx(np.sqrt(2.0), rel=1e-6)
    assert wells.resolve_well("pendulum").omega_max == pytest.approx(1.0, rel=1e-6)
    # the suggested steps_per_cycle passes
    with pytest.raises(ValueError, match=r"steps_per_cycle >= (\d+)") as err:
        escape_chart([0.1], [0.0], 0.01, 0.1, 0.0, cycles=1, steps_per_cycle=32, grid=False)
    need = int(str(err.value).rsplit(">= ", 1)[1].split()[0])
    escape_chart([0.1], [0.0], 0.01, 0.1, 0.0, cycles=1, steps_per_cycle=need, grid=False)


def test_nan_state_counts_as_escape():
    """The engine itself (no step check) at Omega = 1e-4: h ~ 2000 blows every trajectory up to
    inf/NaN within a step or two; each is recorded as escaped under every threshold, none as safe."""
    q = np.linspace(-0.3, 0.3, 7)
    Q, P = (a.ravel() for a in np.meshgrid(q, q, indexing="ij"))
    for kw in (dict(xi_max=(0.2, 0.25), q_max=(0.9,)), dict(xi_max=(0.2,), q_bounds=((-0.9, 0.95),))):
        sE, sQ = run_ensemble(Q, P, np.zeros(Q.size, np.int64), [1e-4], [0.01], 0.0, cycles=3,
                                        steps_per_cycle=32, **kw)
        assert (sE >= 0).all() and (sQ >= 0).all()
    # a NaN state, given directly (the engine does not check its arrays): escaped at step 0, for
    # both lane machineries (|q| tracking, signed tracking) and every threshold kind
    for kw in (dict(xi_max=(0.2,), q_max=(0.5,)), dict(xi_max=(0.2,), q_bounds=((-0.5, 0.6),)),
               dict(xi_max=(0.2,), well="cubic")):
        sE, sQ = run_ensemble([np.nan, 0.1], [0.0, np.inf], [0, 0], [0.9], [0.01], 0.0, cycles=3,
                                        steps_per_cycle=32, **kw)
        assert (sE == 0).all() and (sQ[0] == 0).all() and (sQ >= 0).all()   # (0.1, inf): q is finite at step 0
    # the well bottom at rest with F = 0 stays put (a fixed point): not a NaN, correctly safe
    sE, _ = run_ensemble([0.0], [0.0], [0], [1e-4], [0.0], 0.0, xi_max=(0.2,), cycles=3,
                                   steps_per_cycle=32)
    assert (sE == -1).all()
