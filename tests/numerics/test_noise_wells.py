"""escape_probability in a well without the quartic's symmetry (the cubic, max q / max -q
tracking, one barrier): noise = 0 is escape_chart bitwise, damped and undamped, and a noisy
ensemble is the same for any thread count."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins.numerics import escape_chart, escape_probability

Q = np.linspace(-0.5, 0.6, 8)
P = np.linspace(-0.4, 0.4, 6)
KW = dict(F=0.02, Omega=0.9, Psi=1.0, xi_max=0.12, well="cubic")


@pytest.mark.parametrize("damping", [0.0, 0.01])
def test_zero_noise_is_escape_chart_in_the_cubic(damping):
    chart = escape_chart(Q, P, **KW, cycles=40, damping=damping)
    want = np.minimum(chart.escape_cycle_energy.isel(xi_max=0).values, 40.0)
    assert (want == 0).any() and (want == 40).any() and ((want > 0) & (want < 40)).any()
    ds = escape_probability(Q, P, **KW, noise=0.0, paths=1, t_eval=[40], cycles=40, damping=damping)
    np.testing.assert_array_equal(ds.first_passage_mean.values, want)
    assert ds.attrs["well"] == "cubic"


def test_noisy_cubic_does_not_depend_on_threads():
    kw = dict(noise=0.02, paths=30, t_eval=[5, 20], damping=0.01, seed=4)
    a = escape_probability(Q, P, **KW, threads=1, **kw)
    b = escape_probability(Q, P, **KW, threads=2, **kw)
    assert 0 < float(a.P_escape.sel(t_eval=20).mean()) < 1
    np.testing.assert_array_equal(a.P_escape.values, b.P_escape.values)
    np.testing.assert_array_equal(a.first_passage_mean.values, b.first_passage_mean.values)
