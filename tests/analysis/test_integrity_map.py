"""Integrity maps over (Omega, F): the batch of charts is the charts one by one, the maps are
the integrity measures of those charts, the fronts interpolate the level crossing."""
import numpy as np
import xarray as xr

from safebasins.analysis.integrity import integrity_measures
from safebasins.analysis.integrity_map import erosion_front, integrity_map_analytic, integrity_map_numeric
from safebasins.analysis.safe import is_safe
from safebasins.numerics import escape_chart, escape_chart_batch
from safebasins.theory import slow_flow_escapes
from safebasins.wells.quartic import QUARTIC

Q = np.linspace(-0.72, 0.72, 19)
P = np.linspace(-0.63, 0.63, 17)
OM, FF = [0.85, 1.0], [0.0, 0.02, 0.05]


def test_batch_equals_single_charts_bitwise():
    b = escape_chart_batch(Q, P, [0.01, 0.05, 0.0], [0.9, 1.0, 0.95], np.pi, xi_max=(0.18, 0.22), q_max=(0.8,),
                           cycles=60)
    for k, (F, Om) in enumerate([(0.01, 0.9), (0.05, 1.0), (0.0, 0.95)]):
        c = escape_chart(Q, P, F, Om, np.pi, xi_max=(0.18, 0.22), q_max=(0.8,), cycles=60)
        assert np.array_equal(c["escape_cycle_energy"].values, b["escape_cycle_energy"].values[k])
        assert np.array_equal(c["escape_cycle_displacement"].values, b["escape_cycle_displacement"].values[k])


def test_numeric_map_is_the_integrity_of_each_chart():
    m = integrity_map_numeric(OM, FF, np.pi, 0.18, Q, P, cycles=60, t_eval=[20, 60])
    assert m["GIM"].dims == ("Omega", "F", "t_eval")
    for i, om in enumerate(OM):
        for j, f in enumerate(FF):
            c = escape_chart(Q, P, f, om, np.pi, xi_max=(0.18,), cycles=60)
            safe = is_safe(c["escape_cycle_energy"].isel(xi_max=0), 60)
            ref = integrity_measures(safe.values, Q, P, 0.18, well="quartic")
            for k in ("GIM", "LIM", "IF"):
                assert m[k].values[i, j, -1] == ref[k], (k, om, f)
    np.testing.assert_allclose(m["GIM"].sel(F=0.0), 1.0)
    assert (m["GIM"].diff("t_eval") <= 0).all()


def test_analytic_map_per_phase_and_all_phase():
    a = integrity_map_analytic(OM, FF, np.pi, 0.18, Q, P, n_gamma=32, n_xi=16)
    Qm, Pm = np.meshgrid(Q, P, indexing="ij")
    direct = ~slow_flow_escapes(Qm, Pm, 0.02, 0.85, np.pi, 0.18) & QUARTIC.unforced_safe(Qm, Pm, 0.18)
    assert a["GIM"].sel(Omega=0.85, F=0.02) == integrity_measures(direct, Q, P, 0.18, well="quartic")["GIM"]
    np.testing.assert_allclose(a[["GIM", "LIM", "GIM_true", "LIM_true"]].sel(F=0.0).to_array(), 1.0)
    # the basin safe for every phase lies inside the basin of one phase (one pixel of slack)
    assert (a["GIM_true"] <= a["GIM"] + 0.05).all() and (a["LIM_true"] <= a["LIM"] + 0.1).all()


def test_erosion_front_interpolates_the_crossing():
    F = np.array([0.0, 0.01, 0.02, 0.03])
    ds = xr.Dataset({m: (("Omega", "F"), np.array([[1.0, 0.8, 0.4, 0.1], [1.0, 1.0, 0.9, 0.7]]))
                     for m in ("GIM", "LIM", "IF")}, coords={"Omega": [0.9, 1.0], "F": F})
    fr = erosion_front(ds, 0.5)
    np.testing.assert_allclose(fr["F_GIM"].values[0], 0.01 + 0.01 * (0.8 - 0.5) / 0.4)
    assert np.isnan(fr["F_GIM"].values[1])  # never falls to the level
