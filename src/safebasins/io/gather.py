"""Gather the tiles of chart tasks (rule ``chart_tile``) back into whole escape charts.

Tiles are contiguous blocks of q0 rows (grids) or of ``sample`` (random ICs); each trajectory
is independent, so the gathered chart is the same for any tile count.  The rule runtime loads
the tile files (:func:`load_blocks`); the functions here take Datasets.
"""
from __future__ import annotations

import xarray as xr
from typing import Any

from safebasins.core.stacking import stack
from safebasins.io.datasets import load

TILE_ATTRS = ("task", "tile", "tiles")


def gather_tiles(parts: Any) -> xr.Dataset:
    """Concatenate the tiles (Datasets) of one chart task (rule `chart_tile`) in order.

    Grid tiles are blocks of q0 rows; random-IC tiles are blocks of ``sample``. The tile
    bookkeeping attributes (``task``, ``tile``, ``tiles``) are dropped.
    """
    parts = list(parts)
    dim = "sample" if "sample" in parts[0].dims else "q0"
    ds = xr.concat(parts, dim=dim, data_vars="minimal", coords="minimal", compat="override",
                   join="exact" if dim == "sample" else "outer", combine_attrs="override")
    for k in TILE_ATTRS:
        ds.attrs.pop(k, None)
    return ds


def task_blocks(paths: Any, ntasks: int) -> list[list]:
    """The flat tile list (tasks x tiles, task-major) split into the tiles of each task (any
    items: paths or Datasets)."""
    paths = list(paths)
    if ntasks < 1 or len(paths) % ntasks:
        raise ValueError(f"{len(paths)} tile files do not split into {ntasks} tasks")
    per_task = len(paths) // ntasks
    return [paths[i * per_task:(i + 1) * per_task] for i in range(ntasks)]


def load_blocks(paths: Any, ntasks: int) -> list[list[xr.Dataset]]:
    """The tile files (tasks x tiles, task-major) loaded, as one list of tiles per task."""
    return [[load(f) for f in block] for block in task_blocks(paths, ntasks)]


def task_charts(blocks: Any) -> list[xr.Dataset]:
    """The gathered chart of every task from its tiles (one list of tile Datasets per task)."""
    return [gather_tiles(block) for block in blocks]


def gather_chart(charts: Any, *, cycles: Any, scan: Any = None, F: Any = None, t_eval: Any = None) -> xr.Dataset:
    """One dataset of the gathered task charts: stacked over ``F`` (values ``F``) for an F scan,
    else the single chart; attributes ``scan``, ``t_eval`` (if given) and ``cycles``."""
    if scan == "F":
        out = stack(charts, "F", list(F), pad=())
        out.attrs["scan"] = "F"
    else:
        out = charts[0]
        if scan is not None:
            out.attrs["scan"] = scan
    if t_eval is not None:
        out.attrs["t_eval"] = t_eval
    out.attrs.setdefault("cycles", cycles)
    return out
