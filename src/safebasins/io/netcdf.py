"""netCDF reads and writes whose errors name the file and the likely cause.

The netCDF library reports a truncated file, a corrupted chunk and a write on a full disk alike
as ``NetCDF: HDF error``, without the file.  :func:`read` and :func:`write` turn such errors
into a :class:`NetCDFFileError` (an ``OSError``) whose message names the file, says what
probably happened and what to do:

* reading: the file is corrupted or truncated (a copy or a write that was cut short, a damaged
  disk): delete it and rerun the job that writes it;
* writing: the disk is full (``ENOSPC``/``EDQUOT``, or less space left on the target's file
  system than the dataset needs), with the free space; otherwise the netCDF library's message.

Writes go through :func:`safebasins.io.files.atomic_path`: whatever fails, no half-written file
survives (the temporary is removed, the target is left as it was).
"""
from __future__ import annotations

import errno
import os
import shutil
from pathlib import Path
from typing import Any

import xarray as xr

from safebasins.io.files import atomic_path

__all__ = ["NetCDFFileError", "read", "write"]

_NO_SPACE = (errno.ENOSPC, errno.EDQUOT)


class NetCDFFileError(OSError):
    """A netCDF file could not be read or written (the message names the file and the likely cause)."""

    def __init__(self, message: Any, path: Any, err: Any = None) -> None:
        super().__init__(message)
        self.filename = os.fspath(path)
        self.errno = err

    def __str__(self) -> str:
        return self.args[0]


def _netcdf_error(exc: Any) -> bool:
    """An error of the netCDF/HDF5 library (``NetCDF: ...``, ``HDF error``)."""
    text = str(exc)
    return "NetCDF:" in text or "HDF" in text


def read(path: Any, *, engine: str = "netcdf4") -> xr.Dataset:
    """Read the dataset at ``path`` fully into memory and close the file.

    A file the netCDF library cannot read (truncated, a corrupted chunk, not netCDF at all)
    raises :class:`NetCDFFileError` naming it; a missing file stays a ``FileNotFoundError``.
    """
    try:
        return xr.load_dataset(path, engine=engine)
    except FileNotFoundError:
        raise
    except (OSError, RuntimeError) as exc:
        if not _netcdf_error(exc):
            raise
        raise NetCDFFileError(f"cannot read {os.fspath(path)} ({exc}): the file is corrupted or truncated (a "
                              "copy or a write that was cut short, a damaged disk); delete it and rerun the job "
                              "that writes it", path, getattr(exc, "errno", None)) from exc


def _free_bytes(directory: Path) -> int | None:
    try:
        return shutil.disk_usage(directory).free
    except OSError:
        return None


def write(ds: xr.Dataset, path: Any, **to_netcdf: Any) -> Path:
    """Write ``ds`` to ``path`` atomically (``ds.to_netcdf(tmp, **to_netcdf)``, then rename).

    A failure leaves no file behind; a full disk (or a netCDF/HDF error while the target's file
    system has less free space than the dataset's size) raises :class:`NetCDFFileError` naming
    the file, the free space and what to do; another netCDF error names the file.
    """
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            ds.to_netcdf(tmp, **to_netcdf)
    except (OSError, RuntimeError) as exc:
        err = getattr(exc, "errno", None)
        if err not in _NO_SPACE and not _netcdf_error(exc):
            raise
        free = _free_bytes(path.parent)
        if err in _NO_SPACE or (free is not None and free < ds.nbytes):
            space = f"{free / 2**20:.1f} MiB free" if free is not None else "free space unknown"
            raise NetCDFFileError(f"cannot write {path} ({exc}): the disk is full ({space} on {path.parent}, the "
                                  f"dataset holds {ds.nbytes / 2**20:.1f} MiB uncompressed); free some space and "
                                  "rerun (nothing was written)", path, errno.ENOSPC) from exc
        raise NetCDFFileError(f"cannot write {path} ({exc}): the netCDF library failed (is the disk full or the file "
                              "system failing?); nothing was written", path, err) from exc
    return path
