"""Fractal boundary measures validated on basins with known answers (reference_basins): smooth
boundaries (a half plane, a disc, three sectors), the Cantor-set boundary of an expanding open map
(uncertainty exponent 1 - log 2 / log s in closed form) and the Julia set of Newton's method for
z^3 = 1; the box and ball entropies against brute-force loops."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from safebasins.analysis import reference_basins as rb
from safebasins.analysis.basin_measures import (PUY_BIAS, basin_entropy, fractal_test, grid_uncertainty_exponent,
                                                smooth_boundary_entropy)

LOG2 = np.log(2.0)


@pytest.fixture(scope="module")
def basins():
    return {"half_plane": rb.half_plane(300)[0], "disc": rb.disc(300)[0], "sectors": rb.sectors(300)[0],
            "newton": rb.newton_basins(300)[0], "cantor": rb.cantor_basins(2187, 300)[0]}


def _gibbs(cells):
    _, n = np.unique(cells, return_counts=True)
    p = n / n.sum()
    return float(-(p * np.log(p)).sum())


def test_smooth_boundary_entropy_is_puy_value():
    """Puy et al. (2021) tabulate 0.4395093 for a straight line through a disc."""
    assert abs(smooth_boundary_entropy() - 0.4395093) < 1e-7


def test_box_entropy_equals_brute_force():
    """S_b, S_bb of one tiling against a loop over the boxes (incomplete edge boxes left out)."""
    rng = np.random.default_rng(3)
    lab = (rng.random((23, 17)) < 0.3).astype(int) + (rng.random((23, 17)) < 0.1)
    lab[:, :6] = 0                                                      # some single-label boxes
    b = 4
    S = [_gibbs(lab[i:i + b, j:j + b]) for i in range(0, 23 - b + 1, b) for j in range(0, 17 - b + 1, b)]
    S = np.array(S)
    ds = basin_entropy(lab, box=b)
    assert ds["n_boxes"].item() == S.size == 5 * 4
    assert ds["S_b"].item() == pytest.approx(S.mean(), rel=1e-12)
    assert ds["S_bb"].item() == pytest.approx(S[S > 0].mean(), rel=1e-12)
    assert ds["n_boundary_boxes"].item() == (S > 0).sum()
    assert ds["S_bb_err"].item() == pytest.approx(S[S > 0].std(ddof=1) / np.sqrt((S > 0).sum()), rel=1e-12)


@pytest.mark.parametrize("name", ["half_plane", "disc", "sectors"])
def test_smooth_boundaries(basins, name):
    """Smooth: S_bb below log 2 (the criterion does not fire) and the ball test says smooth."""
    be = basin_entropy(basins[name], box=(3, 5), offsets=9)
    assert (be["S_bb"] + 3 * be["S_bb_err"] < LOG2).all() and not be["fractal_log2"].any()
    assert (be["S_b"] < 0.05).all()                                    # a curve fills few boxes
    for radius in (5, 10):
        ft = fractal_test(basins[name], radius=radius, n_balls=500, seed=1)
        assert not ft["fractal"] and ft["p_value"] > 0.05, (radius, float(ft["S_bb"]))
        assert ft["multi_fraction"] < 0.05                    # the sectors meet at one point only
        band = smooth_boundary_entropy() + PUY_BIAS[0] * radius ** -PUY_BIAS[1]
        width = band - smooth_boundary_entropy() + 4 * ft["S_bb_err"].item()
        assert abs(ft["S_bb"].item() - smooth_boundary_entropy()) < width


def test_fractal_boundaries(basins):
    """Newton's three basins: S_bb > log 2 in 3 x 3 boxes (Daza's criterion fires); the ball test
    says fractal for Newton and for the Cantor boundary (two labels: log 2 cannot decide there)."""
    be = basin_entropy(basins["newton"], box=3, offsets=9)
    assert be["fractal_log2"].item() and be["log2_z"].item() > 3 and be.attrs["max_entropy"] == pytest.approx(np.log(3))
    ft = fractal_test(basins["newton"], radius=8, n_balls=500)
    assert ft["fractal"] and ft["p_value"] < 1e-6 and ft["multi_fraction"] > 0.3      # all three basins meet
    # parallel Cantor lines: S_bb 0.51, only 0.07 above a smooth boundary's, so more and wider balls
    ft = fractal_test(basins["cantor"], radius=10, n_balls=2000)
    assert ft["fractal"] and ft["p_value"] < 1e-10 and ft["S_bb"] > smooth_boundary_entropy() + 0.05
    two = basin_entropy(basins["cantor"], box=5)
    assert two["S_bb"].item() <= LOG2 + 1e-12 and not two["fractal_log2"].item()


def test_ball_entropy_brute_force():
    """One boundary ball's entropy from the centres the test draws (same seed), by a loop."""
    from safebasins.analysis.basin_measures import _ball_entropies

    lab = rb.sectors(60)[0]
    h, bnd = _ball_entropies(lab, 3, 4.5, np.random.default_rng(7), 50)
    rng = np.random.default_rng(7)
    cq, cp = rng.uniform(4.5, 59 - 4.5, 50), rng.uniform(4.5, 59 - 4.5, 50)
    I, J = np.meshgrid(np.arange(60), np.arange(60), indexing="ij")
    for k in range(50):
        cells = lab[(I - cq[k]) ** 2 + (J - cp[k]) ** 2 <= 4.5 ** 2]
        assert h[k] == pytest.approx(_gibbs(cells), abs=1e-12) and bnd[k] == np.unique(cells).size


@pytest.mark.parametrize("s,n,eps", [(3, 3 ** 9, (9, 27, 81, 243)), (4, 4 ** 7, (4, 16, 64, 256)),
                                     (5, 5 ** 6, (5, 25, 125))])
def test_uncertainty_exponent_of_cantor_boundary(s, n, eps):
    """alpha = 1 - log 2 / log s (boundary C_s x interval) within 0.03 at eps of powers of s
    (grid steps; the log-periodic wiggle of a self-similar set and the pixels bound the accuracy)."""
    lab = rb.cantor_basins(n, 4, s=s)[0]
    ue = grid_uncertainty_exponent(lab, eps=eps, axes="q0", n=100_000)
    a = ue.attrs["alpha"]
    assert abs(a - rb.cantor_exponent(s)) < 0.03 and ue.attrs["alpha_err"] < 0.01, (s, a)
    assert ue.attrs["boundary_dimension"] == pytest.approx(2 - a)


def test_uncertainty_exponent_smooth_and_coordinates():
    q0, p0 = rb.disc(400)[1:]
    da = xr.DataArray(rb.disc(400)[0], dims=("q0", "p0"), coords={"q0": q0, "p0": p0})
    ue = grid_uncertainty_exponent(da, eps=(2, 4, 8, 16), n=50_000)
    assert abs(ue.attrs["alpha"] - 1.0) < 0.05
    np.testing.assert_allclose(ue["eps_q0"].values, ue["eps"].values * (q0[1] - q0[0]))
    assert "parameters" in ue.attrs and "history" in ue.attrs


def test_bad_input():
    lab = rb.half_plane(40)[0]
    for call, name in [(lambda: basin_entropy(lab.astype(float) / 2), "labels"),
                       (lambda: basin_entropy(np.where(lab > 0, np.nan, 0.0)), "labels"),
                       (lambda: basin_entropy(lab[0]), "labels"),
                       (lambda: basin_entropy(lab, box=1), "box"), (lambda: basin_entropy(lab, box=41), "box"),
                       (lambda: basin_entropy(lab, offsets=0), "offsets"),
                       (lambda: basin_entropy(lab, significance=1.0), "significance"),
                       (lambda: fractal_test(lab, radius=20), "radius"),
                       (lambda: fractal_test(lab, n_balls=50), "n_balls"),
                       (lambda: fractal_test(np.zeros((40, 40), int), radius=3), "single label"),
                       (lambda: fractal_test(lab, seed=-1, radius=3), "seed"),
                       (lambda: grid_uncertainty_exponent(lab, eps=(4, 30)), "eps"),
                       (lambda: grid_uncertainty_exponent(lab, eps=(2, 2)), "eps"),
                       (lambda: grid_uncertainty_exponent(lab, axes="x"), "axes"),
                       (lambda: basin_entropy(xr.DataArray(lab, dims=("a", "b"))), "dims")]:
        with pytest.raises(ValueError, match=name):
            call()
