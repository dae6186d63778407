"""Atomic writes: a killed write leaves nothing half-written, and its temporaries are removed by
the next write of the same target."""
import os

import pytest
import xarray as xr

from safebasins.io.datasets import write_netcdf
from safebasins.io.files import atomic_path, stale_temporaries


def test_stale_temporaries_of_a_killed_write_are_removed(tmp_path):
    target = tmp_path / "fcr_fig10.nc"
    stale = tmp_path / ".fcr_fig10.nc.k9x2_1.tmp"      # what SIGKILL mid-write leaves
    stale.write_bytes(b"")
    other = tmp_path / ".fcr_fig11.nc.a1.tmp"          # another target's: not ours to touch
    other.write_bytes(b"")
    assert stale_temporaries(target) == [stale]
    write_netcdf(xr.Dataset({"x": ("a", [1.0])}), target)
    assert target.exists() and not stale.exists() and other.exists()


def test_interrupted_write_keeps_the_previous_file(tmp_path):
    target = tmp_path / "t.yaml"
    target.write_text("old\n")
    with pytest.raises(KeyboardInterrupt):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise KeyboardInterrupt
    assert target.read_text() == "old\n" and os.listdir(tmp_path) == ["t.yaml"]
