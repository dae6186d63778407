"""Gather the tile files of chart tasks (rule ``chart_tile``) back into whole escape charts.

Tiles are contiguous blocks of q0 rows (grids) or of ``sample`` (random ICs); each trajectory
is independent, so the gathered chart is the same for any tile count.
"""
from __future__ import annotations

import xarray as xr

from safebasins.io.datasets import load

TILE_ATTRS = ("task", "tile", "tiles")


def gather_tiles(paths) -> xr.Dataset:
    """Concatenate the tile files of one chart task (rule `chart_tile`) in order.

    Grid tiles are blocks of q0 rows; random-IC tiles are blocks of ``sample``. The tile
    bookkeeping attributes (``task``, ``tile``, ``tiles``) are dropped.
    """
    parts = [load(f) for f in paths]
    dim = "sample" if "sample" in parts[0].dims else "q0"
    ds = xr.concat(parts, dim=dim, data_vars="minimal", coords="minimal", compat="override",
                   join="exact" if dim == "sample" else "outer", combine_attrs="override")
    for k in TILE_ATTRS:
        ds.attrs.pop(k, None)
    return ds


def task_blocks(paths, ntasks: int) -> list[list]:
    """The flat tile list (tasks x tiles, task-major) split into the tiles of each task."""
    paths = list(paths)
    if ntasks < 1 or len(paths) % ntasks:
        raise ValueError(f"{len(paths)} tile files do not split into {ntasks} tasks")
    per_task = len(paths) // ntasks
    return [paths[i * per_task:(i + 1) * per_task] for i in range(ntasks)]


def task_charts(paths, ntasks: int) -> list[xr.Dataset]:
    """The gathered chart of every task from the flat tile list (tasks x tiles, task-major)."""
    return [gather_tiles(block) for block in task_blocks(paths, ntasks)]
