"""Every chart task of an experiment integrated in one job (``numerics.tiles`` = 0,
:func:`task_tiles`): what the ``chart_tile`` jobs (``Kind.compute_tile``,
:func:`safebasins.pipeline.registry.chart_tile`) would have written with one tile per task."""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import xarray as xr

    from safebasins.pipeline.registry import Job, Kind, Params


def task_tiles(kind: Kind, params: Params, job: Job) -> list[list[xr.Dataset]]:
    """Every chart task of an experiment integrated here, one whole-task tile each (the
    ``inputs["tiles"]`` of the product that reads them: tasks x 1, task-major)."""
    return [[kind.compute_tile(params, k, 0, 1, job)] for k in range(len(kind.tasks(params)))]
