"""The default tile job of escape-chart tasks (rule ``chart_tile``, ``Kind.compute_tile``), and
every task of an experiment integrated in one job (``numerics.tiles`` = 0, :func:`task_tiles`).

Grid tasks: a contiguous block of q0 rows x all p0 (dims q0, p0).  Paired ICs: a contiguous
block of the samples (dim ``sample``, global index).  A task may carry its own forcing phase
``Psi`` or frequency ``Omega``.  Each trajectory is independent: the gathered chart is the same
for any tile count.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from safebasins.pipeline.values import base_well, damping, tile_slice

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import Job, Kind, Params


def chart_tile(kind: Kind, params: Params, k: int, tile: int, tiles: int, job: Job) -> xr.Dataset:
    from safebasins.numerics import escape_chart

    task = kind.tasks(params)[k]
    Psi = task.get("Psi", params.get("Psi"))
    Omega = task.get("Omega", params.get("Omega"))
    if Omega is None or Psi is None:
        raise ValueError(f"experiment {params['experiment']!r}, chart task {k}: no forcing "
                         f"{'frequency Omega' if Omega is None else 'phase Psi'} in the task or the parameters")
    q0, p0, grid = kind.chart_ics(params)
    sl = tile_slice(q0.size, tiles, tile)
    q0 = q0[sl]
    p0 = p0 if grid else p0[sl]
    print(f"{params['experiment']} task {k} tile {tile}/{tiles}: F={task['F']} Omega={Omega} Psi={Psi} "
          f"xi_max={task['xi_max']} q_max={task['q_max']} cycles={params['cycles']} "
          f"ICs={q0.size}x{p0.size if grid else 1}", flush=True)
    ds = escape_chart(q0, p0, task["F"], Omega, Psi, xi_max=tuple(task["xi_max"]), q_max=tuple(task["q_max"]),
                      cycles=params["cycles"], steps_per_cycle=params["steps_per_cycle"], threads=job.threads,
                      grid=grid, backend=job.backend, well=base_well(params),
                      damping=damping(params))
    if not grid:
        ds = ds.assign_coords(sample=np.arange(sl.start, sl.stop))
    return ds


def task_tiles(kind: Kind, params: Params, job: Job) -> list[list[xr.Dataset]]:
    """Every chart task of an experiment integrated here, one whole-task tile each (the
    ``inputs["tiles"]`` of the product that reads them: tasks x 1, task-major) -- what the
    ``chart_tile`` jobs would have written with one tile per task."""
    return [[kind.compute_tile(params, k, 0, 1, job)] for k in range(len(kind.tasks(params)))]
