"""Uncertainty exponent of the safe-basin boundary: 1 for a smooth boundary, below 1 once the
hilltop saddle's manifolds tangle (Thompson's escape equation, beta = 0.1, Omega = 0.85, Melnikov
tangency at F = 0.0634)."""
from __future__ import annotations

import pytest

from safebasins.analysis.fractality import uncertainty_exponent

BOX = ((-0.7, 1.0), (-0.7, 0.7))
KW = dict(n=30000, cycles=300, well="cubic", damping=0.1, eps=(3e-3, 1e-3, 3e-4, 1e-4, 3e-5))


def test_smooth_below_and_fractal_past_the_tangency():
    below = uncertainty_exponent(0.055, 0.85, 0.0, 1 / 6, BOX, **KW)
    past = uncertainty_exponent(0.065, 0.85, 0.0, 1 / 6, BOX, **KW)
    a, da = below.attrs["alpha"], below.attrs["alpha_err"]
    assert abs(a - 1.0) < 3 * da and da < 0.15                   # smooth: f(eps) ~ eps
    b, db = past.attrs["alpha"], past.attrs["alpha_err"]
    assert b < 0.85 and b + 3 * db < a and past.attrs["boundary_dimension"] > 1.15
    n_uncertain = past["n_uncertain"].values
    assert past.attrs["safe_fraction"] > 0.2 and (n_uncertain[:-1] >= n_uncertain[1:]).all()


@pytest.mark.parametrize("kw,name", [(dict(eps=(1e-3, 1e-3)), "eps"), (dict(eps=(-1e-3,)), "eps"), (dict(n=0), "n"),
                                     (dict(seed=-1), "seed"), (dict(box=((1, 0), (0, 1))), "box"),
                                     (dict(t_eval=1e4), "t_eval")])
def test_bad_input(kw, name):
    args = dict(box=BOX, n=10, cycles=5)
    args.update(kw)
    box = args.pop("box")
    with pytest.raises(ValueError, match=name):
        uncertainty_exponent(0.01, 0.9, 0.0, 0.1, box, **args)
