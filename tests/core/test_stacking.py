"""safebasins.core.stacking: datasets stacked along a new dimension, parts padded, varying
attributes promoted to coordinates."""
import numpy as np
import xarray as xr

from safebasins.core.stacking import stack
from tests.io.test_datasets import small_chart


def boundary(nv, nc, F):
    return xr.Dataset(
        {"gamma": ("vertex", np.linspace(0, 1, nv)), "curve_index": ("vertex", np.zeros(nv, dtype=int)),
         "kind": ("curve", np.array(["island"] * nc, dtype=object)), "C_level": ("curve", np.ones(nc))},
        attrs={"F": F, "Omega": 0.9, "saddle_xi": np.nan})


def test_stack_pads_and_promotes_varying_attrs():
    st = stack([boundary(3, 1, 0.01), boundary(5, 2, 0.02)], "F", [0.01, 0.02])
    assert st.sizes["vertex"] == 5 and st.sizes["curve"] == 2
    assert np.isnan(st["gamma"].values[0, 3:]).all() and (st["curve_index"].values[0, 3:] == -1).all()
    assert st["kind"].values[0, 1] == "" and np.isnan(st["C_level"].values[0, 1])
    assert list(st["F"].values) == [0.01, 0.02] and st.attrs["Omega"] == 0.9 and "F" not in st.attrs
    assert st.attrs["saddle_xi"] != st.attrs["saddle_xi"]  # equal (NaN) attrs stay attributes
    st2 = stack([small_chart(0.01), small_chart(0.02)], "F", [0.01, 0.02], pad=())
    assert st2["escape_cycle_energy"].dims == ("F", "xi_max", "q0", "p0")


def test_stack_explicit_coords():
    st = stack([boundary(3, 1, 0.01), boundary(3, 1, 0.01)], "curve_set", coords={"label": ["a", "b"]})
    assert list(st["label"].values) == ["a", "b"] and st.attrs["F"] == 0.01
