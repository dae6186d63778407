"""Integrity measures on hand-made masks: geometric values within one pixel diagonal."""
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis.agreement import iou, pixel_agreement
from safebasins.analysis.integrity import integrity_measures, unforced_safe_mask
from safebasins.wells.quartic import QUARTIC

N = 161
Q = np.linspace(-1.0, 1.0, N)
P = np.linspace(-0.8, 0.8, N - 20)  # anisotropic spacing on purpose
DQ, DP = Q[1] - Q[0], P[1] - P[0]
DIAG = np.hypot(DQ, DP)
QQ, PP = np.meshgrid(Q, P, indexing="ij")


def disk(c, r):
    return np.hypot(QQ - c[0], PP - c[1]) < r


def test_disk_at_origin():
    R = 0.5
    m = integrity_measures(disk((0, 0), R), Q, P)
    assert abs(m["r_local"] - R) <= DIAG
    assert abs(m["r_global"] - R) <= DIAG
    assert abs(m["area"] - np.pi * R ** 2) <= 2 * np.pi * R * DIAG
    assert abs(m["if_q0"]) <= DIAG and abs(m["if_p0"]) <= DIAG


def test_offcentre_disk_lim_is_distance_to_edge():
    R, c = 0.3, (0.2, 0.1)
    m = integrity_measures(disk(c, R), Q, P)
    assert abs(m["r_local"] - (R - np.hypot(*c))) <= DIAG
    assert abs(m["r_global"] - R) <= DIAG
    assert abs(m["if_q0"] - c[0]) <= DIAG and abs(m["if_p0"] - c[1]) <= DIAG


def test_annulus():
    r1, r2 = 0.2, 0.7
    rr = np.hypot(QQ, PP)
    mask = (rr > r1) & (rr < r2)
    m = integrity_measures(mask, Q, P)
    assert m["r_local"] == 0.0  # the well bottom is not safe
    assert abs(m["r_global"] - (r2 - r1) / 2) <= DIAG
    assert abs(m["area"] - np.pi * (r2 ** 2 - r1 ** 2)) <= 2 * np.pi * (r1 + r2) * DIAG


def test_two_disjoint_disks():
    R1, R2 = 0.35, 0.2
    mask = disk((-0.5, 0.2), R1) | disk((0.6, -0.3), R2)
    m = integrity_measures(mask, Q, P)
    assert m["r_local"] == 0.0
    assert abs(m["r_global"] - R1) <= DIAG
    assert abs(m["if_q0"] + 0.5) <= DIAG
    assert abs(m["area"] - np.pi * (R1 ** 2 + R2 ** 2)) <= 2 * np.pi * (R1 + R2) * DIAG


def test_one_pixel_bound_is_tight_and_converges():
    """The error bound scales with the pixel: refine the grid, the error shrinks."""
    R = 0.37
    errs = []
    for n in (21, 41, 81, 161, 321):
        q = np.linspace(-1, 1, n)
        qq, pp = np.meshgrid(q, q, indexing="ij")
        m = integrity_measures(np.hypot(qq - 0.013, pp + 0.007) < R, q, q)
        diag = np.hypot(q[1] - q[0], q[1] - q[0])
        err = abs(m["r_global"] - R)
        assert err <= diag
        errs.append(err)
    assert errs[-1] < errs[0]


def test_basin_touching_grid_edge_counts_outside_as_unsafe():
    mask = np.ones((N, N - 20), bool)
    m = integrity_measures(mask, Q, P)
    # padded by unsafe nodes one step beyond the edges
    assert m["r_local"] == pytest.approx(0.8 + DP)
    assert m["r_global"] == pytest.approx(0.8 + DP)


def test_empty_mask():
    m = integrity_measures(np.zeros((N, N - 20), bool), Q, P, xi_max=0.2, well="quartic")
    assert m["area"] == 0 and m["r_local"] == 0 and m["r_global"] == 0
    assert m["GIM"] == 0 and m["LIM"] == 0 and m["IF"] == 0
    assert np.isnan(m["if_q0"])


@pytest.mark.parametrize("xi", [0.05, 0.15, 0.24, 0.25])
def test_unforced_normalisation_is_one_and_matches_analytic(xi):
    q = np.linspace(-1, 1, 201)
    p = np.linspace(-0.75, 0.75, 151)
    S0 = unforced_safe_mask(q, p, xi)
    m = integrity_measures(S0, q, p, xi, well="quartic")
    assert m["GIM"] == 1 and m["LIM"] == 1 and m["IF"] == 1
    diag = np.hypot(q[1] - q[0], p[1] - p[0])
    # analytic values of the normalisers: r = sqrt(2 xi), area = 2 pi J(xi)
    assert abs(m["r_local_unforced"] - np.sqrt(2 * xi)) <= diag
    assert abs(m["r_global_unforced"] - np.sqrt(2 * xi)) <= diag
    from scipy.integrate import quad
    qm = float(QUARTIC.q_max(xi))
    area = 2 * quad(lambda x: np.sqrt(max(2 * xi - x * x + x ** 4 / 2, 0)), -qm, qm)[0]
    assert abs(m["area_unforced"] - area) <= 4 * 2 * qm * diag


def test_stack_vectorised_and_normalised_per_threshold():
    q = np.linspace(-1, 1, 81)
    xi = np.array([0.1, 0.2, 0.25])
    S0 = unforced_safe_mask(q, q, xi)             # (3, 81, 81)
    stack = np.stack([S0, S0 & (QUARTIC.H0(*np.meshgrid(q, q, indexing="ij")) < 0.05)])  # (2, 3, 81, 81)
    m = integrity_measures(stack, q, q, xi, well="quartic")
    assert m["GIM"].shape == (2, 3)
    np.testing.assert_array_equal(m["GIM"][0], 1.0)
    assert (m["GIM"][1] < 1).all() and (np.diff(m["GIM"][1]) < 0).all()
    # each element equals the single-mask computation
    one = integrity_measures(stack[1, 2], q, q, 0.25, well="quartic")
    for k in ("GIM", "LIM", "IF", "area", "r_global"):
        assert m[k][1, 2] == one[k]


def test_xarray_in_dataset_out():
    q = np.linspace(-1, 1, 61)
    p = np.linspace(-0.8, 0.8, 51)
    xi = [0.12, 0.2]
    F = [0.0, 0.01, 0.02]
    S0 = unforced_safe_mask(q, p, np.array(xi))
    hh = QUARTIC.H0(*np.meshgrid(q, p, indexing="ij"))
    data = np.stack([S0 & (hh < 0.2 - 4 * f) for f in F])  # shrinking with F
    da = xr.DataArray(data, dims=("F", "xi_max", "q0", "p0"),
                      coords={"F": F, "xi_max": xi, "q0": q, "p0": p})
    ds = integrity_measures(da, well="quartic")  # xi_max taken from the coordinate
    assert isinstance(ds, xr.Dataset)
    assert ds["GIM"].dims == ("F", "xi_max")
    assert ds["GIM"].attrs["units"] == "1" and "long_name" in ds["LIM"].attrs
    np.testing.assert_allclose(ds["GIM"].sel(F=0.0).values, 1.0)
    for k in ("GIM", "LIM", "IF"):
        assert (ds[k].diff("F") <= 0).all()
    # transposed input gives the same numbers
    ds2 = integrity_measures(da.transpose("p0", "xi_max", "q0", "F"), well="quartic")
    xr.testing.assert_allclose(ds["GIM"], ds2["GIM"].transpose("F", "xi_max"))
    # scalar threshold on a DataArray without xi_max coordinate
    ds3 = integrity_measures(da.isel(xi_max=0, drop=True), xi_max=0.12, well="quartic")
    np.testing.assert_allclose(ds3["GIM"].values, ds["GIM"].isel(xi_max=0).values)


def test_argument_errors():
    q = np.linspace(-1, 1, 11)
    with pytest.raises(ValueError, match="safe"):
        integrity_measures(np.ones((11, 11)), q, q)
    with pytest.raises(ValueError, match="uniform"):
        integrity_measures(np.ones((11, 11), bool), q ** 3, q)
    with pytest.raises(ValueError, match="xi_max"):
        integrity_measures(np.ones((11, 11), bool), q, q, 0.3, well="quartic")
    with pytest.raises(ValueError, match="shape"):
        integrity_measures(np.ones((11, 10), bool), q, q)


def test_iou_and_agreement():
    a = disk((0, 0), 0.5)
    b = disk((0.1, 0), 0.5)
    assert iou(a, a) == 1.0
    assert 0 < iou(a, b) < 1
    assert iou(np.zeros_like(a), np.zeros_like(a)) == 1.0
    stack = np.stack([a, b])
    np.testing.assert_allclose(iou(stack, a), [1.0, iou(a, b)])
    assert 0 < pixel_agreement(a, b) < 1
    da = xr.DataArray(stack, dims=("F", "q0", "p0"))
    np.testing.assert_allclose(iou(da, xr.DataArray(a, dims=("q0", "p0"))).values, [1.0, iou(a, b)])


def test_displacement_threshold_equivalent_energy():
    assert QUARTIC.xi_from_q_max(1.0) == pytest.approx(0.25)
    assert QUARTIC.q_max(QUARTIC.xi_from_q_max(0.7)) == pytest.approx(0.7)
