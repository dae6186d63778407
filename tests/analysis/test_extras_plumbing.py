"""Erosion / true basin / Fourier comparison plumbing on a toy theory and toy numerics.

The toy models (patched into the analysis modules for the duration of each test) have the
contract signatures of ``safebasins.theory`` / ``safebasins.numerics`` and known answers,
so these tests check the bookkeeping independently of the physics.
Toy rule: an IC (theta, xi) escapes for phase Psi iff
``xi + k F (1 + cos(theta - Psi)) >= xi_max`` with k = 1 ("paper") or 1.1 ("exact");
the all-phase basin is then H0 < xi_max - 2 k F.
"""
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis import erosion, fourier_compare, integrity, phase_invariant
from safebasins.wells.quartic import QUARTIC

K = {"paper": 1.0, "exact": 1.1}


def _angle_energy(q, p, well=None):
    q = np.asarray(q, float)
    p = np.asarray(p, float)
    return np.mod(np.arctan2(-p, q), 2 * np.pi), QUARTIC.H0(q, p)


def _escapes_on_manifold(gamma, xi, F, Omega, xi_max, fourier="paper", well=None):
    fourier = fourier if well is None else well.fourier
    return np.asarray(xi) + K[fourier] * F * (1 + np.cos(gamma)) >= xi_max


def _slow_flow_escapes(q0, p0, F, Omega, Psi, xi_max, fourier="paper", well=None):
    fourier = fourier if well is None else well.fourier
    q0, p0 = np.broadcast_arrays(np.asarray(q0, float), np.asarray(p0, float))
    th, xi = _angle_energy(q0, p0)
    inside = integrity.unforced_safe_mask(np.array([0.0, 1.0]), np.array([0.0, 1.0]), xi_max)  # noqa: F841
    qm = QUARTIC.q_max(xi_max)
    out = (xi >= xi_max) | (np.abs(q0) >= qm)
    return out | _escapes_on_manifold(th - Psi, xi, F, Omega, xi_max, fourier)


def _critical_forcing(Omega, xi_max, xi_ini=0.0, gamma_ini=0.0, fourier="paper"):
    Om = np.atleast_1d(np.asarray(Omega, float))
    F = (xi_max - xi_ini) / (K[fourier] * (1 + np.cos(gamma_ini))) * (1 + (Om - 0.9) ** 2)
    return xr.Dataset({"F_cr": ("Omega", F)}, coords={"Omega": Om})


def _escape_chart(q0, p0, F, Omega, Psi, *, xi_max=(0.25,), q_max=(), cycles=3000, steps_per_cycle=32,
                  threads=None, well=None, damping=0.0):
    assert damping == 0.0, "the toy chart is undamped"
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    th, h = _angle_energy(Q, P)
    xi = np.asarray(xi_max, float)[:, None, None]
    reach = h + 1.05 * F * (1 + np.cos(th - Psi))
    cyc = np.where(reach >= xi, 1.0 + 50.0 * np.clip(xi - h, 0, None) / max(F, 1e-9), np.inf)
    cyc = np.where(h >= xi, 0.0, cyc)
    cyc = np.where(cyc > cycles, np.inf, cyc)
    return xr.Dataset({"escape_cycle_energy": (("xi_max", "q0", "p0"), cyc)},
                      coords={"xi_max": list(xi_max), "q0": q0, "p0": p0},
                      attrs={"F": F, "Omega": Omega, "Psi": Psi, "cycles": cycles,
                             "steps_per_cycle": steps_per_cycle, "integrator": "toy", "well": "quartic"})


def _critical_forcing_numeric(Omega, xi_max, *, q0=0, p0=0, Psi=0, cycles=3000, tol=5e-5, **kw):
    Om = np.atleast_1d(np.asarray(Omega, float))
    F = xi_max / (2 * 1.05) * (1 + (Om - 0.9) ** 2)
    return xr.Dataset({"F_cr": ("Omega", F), "non_monotone": ("Omega", np.zeros(Om.size, bool))},
                      coords={"Omega": Om},
                      attrs={"xi_max": xi_max, "q0": q0, "p0": p0, "Psi": Psi, "cycles": cycles, "tol": tol,
                             "well": "quartic"})


@pytest.fixture
def toy(monkeypatch):
    """Replace the theory and numerics functions each analysis module imports by the toys."""
    toys = {
        "angle_energy": _angle_energy, "escapes_on_manifold": _escapes_on_manifold,
        "slow_flow_escapes": _slow_flow_escapes, "critical_forcing": _critical_forcing,
        "initial_condition": lambda xi, g, Psi: (np.sqrt(2 * xi) * np.cos(g + Psi), -np.sqrt(2 * xi) * np.sin(g + Psi)),
        "escape_chart": _escape_chart, "critical_forcing_numeric": _critical_forcing_numeric,
    }
    for mod in (erosion, phase_invariant, fourier_compare):
        for name, fn in toys.items():
            if hasattr(mod, name):
                monkeypatch.setattr(mod, name, fn)
    return toys


Q = np.linspace(-1, 1, 41)
P = np.linspace(-0.75, 0.75, 31)


def test_analytic_profile_layout_and_values(toy):
    F = [0.0, 0.01, 0.02, 0.04, 0.2]
    ds = erosion.erosion_profile_analytic(F, 0.9, np.pi, [0.15, 0.24], Q, P, fourier=["paper", "exact"])
    assert ds["GIM"].dims == ("fourier", "F", "xi_max")
    np.testing.assert_allclose(ds[["GIM", "LIM", "IF"]].sel(F=0.0).to_array().values, 1.0)
    assert (ds["GIM"].diff("F") <= 0).all()          # toy basins are nested in F
    assert (ds["GIM"].sel(F=0.2) < 0.5).all()
    assert (ds["GIM"].sel(fourier="exact") <= ds["GIM"].sel(fourier="paper")).all()
    for k in ("GIM", "LIM", "IF"):
        assert ds[k].attrs["units"] == "1" and ds[k].attrs["long_name"]
    one = erosion.erosion_profile_analytic(F, 0.9, np.pi, 0.15, Q, P, keep_masks=True)
    assert "fourier" not in one.dims and one["safe"].dims == ("F", "xi_max", "q0", "p0")


def test_numeric_profile_reuses_one_chart_per_F(toy, monkeypatch):
    calls = []
    orig = toy["escape_chart"]

    def counting(*a, **k):
        calls.append(k["xi_max"])
        return orig(*a, **k)

    monkeypatch.setattr(erosion, "escape_chart", counting)
    F = [0.0, 0.01, 0.03]
    prof, charts = erosion.erosion_profile_numeric(F, 0.9, np.pi, [0.15, 0.24], Q, P, t_eval=[10, 100, 500],
                                                   cycles=500, keep_charts=True)
    assert len(calls) == 3 and all(c == (0.15, 0.24) for c in calls)
    assert prof["GIM"].dims == ("F", "xi_max", "t_eval")
    np.testing.assert_allclose(prof[["GIM", "LIM", "IF"]].sel(F=0.0).to_array().values, 1.0)
    for k in ("GIM", "LIM", "IF"):
        assert (prof[k].diff("t_eval") <= 0).all()
    again = erosion.profile_from_charts(charts, t_eval=[10, 100, 500])
    xr.testing.assert_identical(again["GIM"], prof["GIM"])
    with pytest.raises(ValueError, match="t_eval"):
        erosion.profile_from_charts(charts, t_eval=[1000])
    # list of charts is stacked by their attribute F
    lst = [charts.isel(F=i) for i in range(3)]
    np.testing.assert_allclose(erosion.profile_from_charts([c.drop_vars("F").assign_attrs(F=float(c.F)) for c in lst],
                                                           t_eval=100)["GIM"].values,
                               prof["GIM"].sel(t_eval=[100]).values)


def test_level_crossing_and_compare(toy):
    F = np.linspace(0, 0.1, 11)
    an = erosion.erosion_profile_analytic(F, 0.9, np.pi, 0.2, Q, P)
    nu = erosion.erosion_profile_numeric(F, 0.9, np.pi, 0.2, Q, P, t_eval=[100, 1000], cycles=1000)
    cmp = erosion.compare_profiles(an, nu)
    assert cmp["F_GIM_numeric"].dims == ("xi_max", "t_eval")
    f_an = float(cmp["F_GIM_analytic"].squeeze())
    assert 0 < f_an < 0.1
    g = an["GIM"].squeeze()
    assert float(g.interp(F=f_an)) == pytest.approx(0.5, abs=1e-9)
    da = xr.DataArray([1.0, 0.8, 0.6, 0.4, 0.2], dims="F", coords={"F": [0, 1, 2, 3, 4.0]}, name="GIM")
    assert float(erosion.level_crossing(da, 0.5)) == pytest.approx(2.5)
    assert np.isnan(float(erosion.level_crossing(da, 0.1)))


def test_true_basin_analytic_toy(toy):
    xi_max, F = 0.2, 0.02
    ds = phase_invariant.true_safe_basin_analytic(F, 0.9, xi_max, Q, P, n_psi=12, fourier=["paper", "exact"])
    assert ds["safe"].dims == ("Psi", "fourier", "xi_max", "q0", "p0")
    assert bool(ds["contained"].all())
    assert bool((ds["true_safe"] <= ds["safe"]).all())
    # continuous-phase limit: H0 < xi_max - 2 k F
    for f in ("paper", "exact"):
        assert float(ds["xi_true"].sel(fourier=f).squeeze()) == pytest.approx(xi_max - 2 * K[f] * F, abs=1e-6)
    assert bool((ds["true_safe_continuous"] <= ds["true_safe"]).all())
    assert float(ds["LIM_closed"].sel(fourier="paper").squeeze()) == pytest.approx(np.sqrt(0.16 / 0.2), abs=1e-5)
    # grid integrity of the continuous basin close to the closed form (one pixel)
    diag = np.hypot(Q[1] - Q[0], P[1] - P[0])
    r = float(ds["r_global_continuous"].sel(fourier="paper").squeeze())
    assert abs(r - np.sqrt(2 * 0.16)) <= diag
    # rotation: per-phase basin equals slow_flow_escapes called with that phase
    k = 5
    psi = float(ds["Psi"][k])
    direct = ~_slow_flow_escapes(*np.meshgrid(Q, P, indexing="ij"), F, 0.9, psi, xi_max)
    np.testing.assert_array_equal(ds["safe"].isel(Psi=k).sel(fourier="paper").squeeze().values, direct)


def test_true_basin_numeric_toy(toy):
    ds = phase_invariant.true_safe_basin_numeric(0.02, 0.9, [0.15, 0.2], Q, P, Psi_values=[0, 1, 2, 3],
                                                 t_eval=[50, 400], cycles=400)
    assert ds["true_safe"].dims == ("xi_max", "t_eval", "q0", "p0")
    assert bool(ds["contained"].all())
    assert ((ds["GIM_true"] <= ds["GIM"]).all())
    assert (ds["GIM_true"].diff("t_eval") <= 0).all()


def test_fourier_comparisons_toy(toy):
    ds = fourier_compare.fcr_fourier_comparison([0.8, 0.9, 1.0], 0.2)
    assert ds["F_cr_analytic"].dims == ("fourier", "Omega")
    # toy numerics uses k = 1.05: paper (k=1) and exact (k=1.1) equally far, relative +-
    assert float(ds["rel_error"].sel(fourier="paper")[0]) > 0 > float(ds["rel_error"].sel(fourier="exact")[0])
    stacked = xr.concat([_critical_forcing_numeric([0.8, 0.9], x) for x in (0.15, 0.2)], dim="curve")
    stacked = stacked.assign_coords(xi_max=("curve", [0.15, 0.2]), xi_ini=("curve", [0.0, 0.0]),
                                    gamma_ini=("curve", [0.0, 0.0]), Psi=("curve", [0.0, 0.0]))
    ds2 = fourier_compare.fcr_fourier_comparison_from_numeric(stacked)
    assert ds2["error"].dims == ("curve", "fourier", "Omega")

    chart = xr.concat([_escape_chart(Q, P, f, 0.9, np.pi, xi_max=(0.15, 0.2), cycles=300) for f in (0.005, 0.02)],
                      dim="F", combine_attrs="drop_conflicts").assign_coords(F=[0.005, 0.02])
    cmp = fourier_compare.iou_fourier_comparison(chart, t_eval=[300])
    assert cmp["iou"].dims == ("fourier", "F", "xi_max", "t_eval")
    assert ((cmp["iou"] > 0.8) & (cmp["iou"] <= 1)).all()
    assert cmp["mean_iou"].dims == ("fourier",)
