"""safebasins.io.datasets: CF attributes, provenance, atomic zlib writes."""
import json

import numpy as np
import pytest
import xarray as xr

from safebasins.io import datasets as sd
from safebasins.io.compare import assert_same_content


def small_chart(F=0.01):
    q0 = np.linspace(-1, 1, 5)
    p0 = np.linspace(-0.5, 0.5, 4)
    e = np.full((2, 5, 4), np.inf)
    e[0, 0, :] = 0.0
    e[1, 1, 2] = 17.5
    return xr.Dataset({"escape_cycle_energy": (("xi_max", "q0", "p0"), e)},
                      coords={"xi_max": [0.1, 0.2], "q0": q0, "p0": p0},
                      attrs={"F": F, "Omega": 0.9, "Psi": np.pi, "cycles": 100})


def test_finalize_cf_and_provenance():
    params = {"experiment": "fig13", "kind": "basin_chart", "seeds": [1, 2], "steps_per_cycle": 64,
              "nested": {"seed": 7}}
    ds = sd.finalize(small_chart(), title="t", params=params)
    a = ds.attrs
    for k in ("Conventions", "title", "source", "history", "references", "safebasins_version", "git_commit",
              "config_hash", "parameters", "date_created"):
        assert k in a, k
    assert a["Conventions"].startswith("CF-") and "Karmi" in a["references"]
    assert json.loads(a["parameters"]) == params
    assert list(a["seeds"]) == [1, 2, 7]
    assert len(a["config_hash"]) == 64
    for c in ("q0", "p0", "xi_max", "escape_cycle_energy"):
        assert "units" in ds[c].attrs and "long_name" in ds[c].attrs, c


def test_write_is_atomic_compressed_and_roundtrips(tmp_path):
    ds = sd.finalize(small_chart(), title="t", params={"a": 1})
    ds["mask"] = (("q0", "p0"), np.eye(5, 4, dtype=bool))
    ds["label"] = ("xi_max", np.array(["low", "high"], dtype=object))
    path = sd.write_netcdf(ds, tmp_path / "sub" / "x.nc")
    assert path.exists() and [p.name for p in path.parent.iterdir()] == ["x.nc"]  # no temp left
    back = sd.load(path)
    assert back["escape_cycle_energy"].encoding.get("zlib") is True
    assert np.isinf(back["escape_cycle_energy"].values).sum() == np.isinf(ds["escape_cycle_energy"].values).sum()
    assert back["mask"].dtype == bool
    assert_same_content(ds, back)


def test_failed_write_leaves_nothing(tmp_path):
    ds = xr.Dataset({"x": ("a", [1.0])}, attrs={"bad": {1, 2}})  # a set is not a netCDF attribute
    with pytest.raises(Exception):  # noqa: B017  (whatever netCDF4 raises: the test is that nothing is left)
        sd.write_netcdf(ds, tmp_path / "y.nc")
    assert list(tmp_path.iterdir()) == []


def test_assert_same_content_ignores_volatile_only():
    a = sd.finalize(small_chart(), title="t", params={"a": 1})
    b = a.copy(deep=True)
    b.attrs["date_created"] = "other"
    assert_same_content(a, b)
    b["escape_cycle_energy"][0, 0, 0] = 3.0
    with pytest.raises(AssertionError):
        assert_same_content(a, b)


