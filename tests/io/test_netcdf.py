"""netCDF errors name the file and the likely cause (safebasins.io.netcdf): a truncated file or a
corrupted chunk on reading, a full disk on writing; a failed write leaves no file behind."""
from __future__ import annotations

import errno
import os
import shutil
from collections import namedtuple

import numpy as np
import pytest
import xarray as xr

from safebasins.io import netcdf
from safebasins.io.datasets import load, write_netcdf
from safebasins.plotting.data import open_dataset


@pytest.fixture
def good(tmp_path):
    ds = xr.Dataset({"escape_cycle_energy": (("q0", "p0"), np.random.default_rng(1).random((200, 200)))})
    return write_netcdf(ds, tmp_path / "chart_fig13.nc")


def _damaged(good, how):
    data = bytearray(good.read_bytes())
    bad = good.with_name(f"{how}.nc")
    if how == "truncated":
        data = data[: len(data) // 2]
    else:                                   # a corrupted chunk in the middle of the data
        mid = len(data) // 2
        data[mid:mid + 4096] = bytes(4096)
    bad.write_bytes(bytes(data))
    return bad


@pytest.mark.parametrize("how", ["truncated", "corrupted"])
@pytest.mark.parametrize("reader", [load, open_dataset])
def test_damaged_file_named_with_the_cause(good, how, reader):
    bad = _damaged(good, how)
    with pytest.raises(netcdf.NetCDFFileError) as info:
        reader(bad)
    msg = str(info.value)
    assert str(bad) in msg and "corrupted or truncated" in msg and "delete it and rerun" in msg
    assert info.value.filename == str(bad) and isinstance(info.value, OSError)


def test_missing_file_stays_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        load(tmp_path / "none.nc")


def _fail_writing(exc):
    def to_netcdf(self, path, **kw):
        with open(path, "wb") as fh:        # part of the file is written, then the disk fills up
            fh.write(b"\x89HDF\r\n\x1a\n" + bytes(1000))
        raise exc
    return to_netcdf


@pytest.mark.parametrize("exc", [OSError(errno.ENOSPC, "No space left on device"), RuntimeError("NetCDF: HDF error")])
def test_full_disk_named_and_nothing_left(tmp_path, monkeypatch, exc):
    target = tmp_path / "chart_fig13.nc"
    ds = xr.Dataset({"v": ("x", np.arange(1000.0))})
    monkeypatch.setattr(xr.Dataset, "to_netcdf", _fail_writing(exc))
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage(10**9, 10**9 - 100, 100))   # 100 bytes left
    with pytest.raises(netcdf.NetCDFFileError) as info:
        write_netcdf(ds, target)
    msg = str(info.value)
    assert str(target) in msg and "disk is full" in msg and "free some space" in msg, msg
    assert info.value.errno == errno.ENOSPC
    assert os.listdir(tmp_path) == []       # no half-written target, no temporary


def test_hdf_error_with_space_left_still_names_the_file(tmp_path, monkeypatch):
    target = tmp_path / "fcr_fig10.nc"
    target.write_bytes(b"previous")
    monkeypatch.setattr(xr.Dataset, "to_netcdf", _fail_writing(RuntimeError("NetCDF: HDF error")))
    with pytest.raises(netcdf.NetCDFFileError, match="cannot write .*fcr_fig10.nc .*NetCDF: HDF error"):
        write_netcdf(xr.Dataset({"v": ("x", [1.0])}), target)
    assert os.listdir(tmp_path) == ["fcr_fig10.nc"] and target.read_bytes() == b"previous"


def test_other_errors_pass_unchanged(tmp_path, monkeypatch):
    monkeypatch.setattr(xr.Dataset, "to_netcdf", _fail_writing(ValueError("bad encoding")))
    with pytest.raises(ValueError, match="bad encoding"):
        write_netcdf(xr.Dataset({"v": ("x", [1.0])}), tmp_path / "x.nc")
    assert os.listdir(tmp_path) == []
