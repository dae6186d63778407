"""The merging test of the Wada property: Newton's three basins of z^3 = 1 are Wada (their
common boundary is the Julia set); three sectors and a Newton basin with a smooth fourth basin
cut out are not."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins.analysis import reference_basins as rb
from safebasins.analysis.wada import merged_boundaries, wada_test


@pytest.mark.parametrize("extent", [rb.NEWTON_WINDOW, ((-0.6, -0.2), (0.1, 0.5))])
def test_newton_basins_are_wada(extent):
    """Every merged boundary within 3 grid steps of every other but for <= 1% of its nodes, on
    the whole window and zoomed into a tongue of the Julia set."""
    lab = rb.newton_basins(200, extent=extent)[0]
    assert np.unique(lab).size == 3
    w = wada_test(lab)
    assert w["wada"].item() and w["W"].sel(r=3).item() <= 0.01
    assert w.attrs["max_hausdorff"] <= 6 and (w["n_boundary"] > 100).all()


def test_smooth_three_basins_are_not_wada():
    """Sectors: each merged boundary is two of the three rays, so half of one lies far from another."""
    w = wada_test(rb.sectors(200)[0])
    assert not w["wada"].item() and (w["W"] > 0.4).all() and w.attrs["max_hausdorff"] > 50


def test_a_smooth_fourth_basin_breaks_wada():
    lab, q0, p0 = rb.newton_basins(200)
    lab = lab.copy()
    lab[(q0[:, None] - 1.0) ** 2 + p0[None, :] ** 2 < 0.2 ** 2] = 3    # a disc inside the basin of z = 1
    w = wada_test(lab)
    assert not w["wada"].item() and w["W"].sel(r=16).item() > 0.5


def test_merged_boundaries_brute_force():
    rng = np.random.default_rng(2)
    lab = rng.integers(0, 3, (9, 7))
    B = merged_boundaries(lab, np.arange(3))
    for k in range(3):
        for i in range(9):
            for j in range(7):
                nb = [(i + a, j + b) for a, b in ((1, 0), (-1, 0), (0, 1), (0, -1))
                      if 0 <= i + a < 9 and 0 <= j + b < 7]
                assert B[k, i, j] == any((lab[i, j] == k) != (lab[x, y] == k) for x, y in nb)


def test_bad_input():
    lab = rb.newton_basins(30)[0]
    for kw, name in [(dict(r=(1, 1)), "r must"), (dict(r=(0, 2)), "r must"), (dict(r_wada=5), "r_wada"),
                     (dict(tol=1.0), "tol"), (dict(tol=-0.1), "tol")]:
        with pytest.raises(ValueError, match=name):
            wada_test(lab, **kw)
    with pytest.raises(ValueError, match="at least three basins"):
        wada_test(rb.half_plane(30)[0])
