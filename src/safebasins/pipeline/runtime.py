"""What the rule scripts call: one function per generic rule (``scripts/*.py`` stay thin).

* rule ``parameters`` (``results/params/<experiment>.yaml``): :mod:`safebasins.pipeline.params_file`;
* :func:`make_dataset` -- rules ``analytic``, ``numeric``, ``extras``: the product of the
  registry that the output path names is built from its inputs (with ``numerics.tiles`` = 0 a
  product reading charts integrates its experiment's chart tasks itself), given CF/provenance
  attributes and written atomically (:func:`build_dataset`, also callable without Snakemake);
* :func:`make_tile` -- rule ``chart_tile``: one tile (a contiguous block of q0 rows or of
  samples) of one escape-chart task.

Each receives the ``snakemake`` object of its script.  The product to build is looked up in
the registry by the kind named in the experiment's parameter file, so a rule never needs to
know the kinds.
"""
from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from typing import IO, Any

import numba
import xarray as xr
import yaml

from safebasins.pipeline.config import load_kinds
from safebasins.pipeline.registry import KINDS, Inputs, Job, Kind, Params

# a rule script's ``snakemake`` object (snakemake.script.Snakemake: untyped, attributes by rule)
Snakemake = Any


def redirect_output(log_path: str | os.PathLike[str]) -> IO[str]:
    """Send stdout and stderr of a rule script to its log file (line buffered)."""
    os.makedirs(os.path.dirname(os.fspath(log_path)) or ".", exist_ok=True)
    fh = open(log_path, "w", buffering=1)
    sys.stdout = fh
    sys.stderr = fh
    return fh


def set_threads(n: int) -> None:
    """Limit numba's thread pool to the rule's ``threads:`` (no oversubscription under -j2).

    Only the number of threads in use is set (``numba.set_num_threads``), never the environment's
    ``NUMBA_NUM_THREADS``: numba has read that at import (the wells import it, so it is loaded
    before any rule runs) and re-reads it when it compiles; a value changed after its threads
    started is refused ("Cannot set NUMBA_NUM_THREADS to a different value once the threads have
    been launched")."""
    n = max(1, int(n))
    # (numba.config sets NUMBA_NUM_THREADS at import from the environment: not declared to mypy)
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))  # type: ignore[attr-defined]


def load_params(path: str | os.PathLike[str]) -> Params:
    with open(path) as fh:
        params: Params = yaml.safe_load(fh)
    return params


def _job(smk: Snakemake) -> tuple[Params, Kind]:
    redirect_output(smk.log[0])
    set_threads(smk.threads)
    load_kinds(smk.params.extensions)
    params = load_params(smk.input.params)
    return params, KINDS[params["kind"]]


def load_inputs(inputs: Mapping[str, Any], ntasks: int) -> Inputs:
    """The datasets a product reads, loaded: ``tiles`` as one list of tile Datasets per task
    (task-major), every other named input (a path or a list of paths) as Dataset(s); the
    parameter file is read by the rule itself."""
    from safebasins.io.datasets import load
    from safebasins.io.gather import load_blocks

    out: Inputs = {}
    for k, v in inputs.items():
        if k == "params":
            continue
        if k == "tiles":
            out[k] = load_blocks(list(v), ntasks)
        elif isinstance(v, str):
            out[k] = load(v)
        else:
            out[k] = [load(f) for f in v]
    return out


def make_dataset(smk: Snakemake) -> None:
    """Rules ``analytic`` / ``numeric`` / ``extras``: build, finalize and write one product
    (:func:`build_dataset`)."""
    params, _ = _job(smk)
    ds = build_dataset(params, str(smk.output[0]), smk.input, Job(threads=smk.threads, backend=smk.params.backend),
                       integrate_tasks=bool(smk.params.integrate_tasks), rule=smk.rule)
    print(ds)


def build_dataset(params: Params, out: str, inputs: Mapping[str, Any], job: Job, *, integrate_tasks: bool,
                  rule: str) -> xr.Dataset:
    """The product of experiment ``params`` written to ``out`` (its path under results/), built
    from ``inputs`` (the rule's input files: :meth:`Plan.product_inputs`), given CF/provenance
    attributes and written atomically; returned.  A product reading the chart tiles gets them
    from the ``chart_tile`` jobs, or with ``integrate_tasks`` (``numerics.tiles`` = 0,
    ``Plan.integrates_tasks``) integrates every task here (one tile per task, the same values)."""
    from safebasins.io.datasets import finalize, params_hash, write_netcdf
    from safebasins.pipeline.tiles import task_tiles

    kind = KINDS[params["kind"]]
    product = next(p for p in kind.products(params["experiment"], params) if p.path == out)
    loaded = load_inputs(inputs, len(kind.tasks(params)))
    if integrate_tasks:
        loaded["tiles"] = task_tiles(kind, params, job)
    ds = product.build(params, loaded, job)
    finalize(ds, title=product.title, params=params, config_hash=params_hash(params),
             history=f"{product.history} (rule {rule})")
    write_netcdf(ds, out)
    return ds


def make_tile(smk: Snakemake) -> None:
    """Rule ``chart_tile``: one tile job of one task of a kind with escape-chart tasks
    (``Kind.compute_tile``; by default a block of q0 rows or samples of the task's chart)."""
    from safebasins.io.datasets import write_netcdf

    params, kind = _job(smk)
    k, tile, tiles = int(smk.wildcards.task), int(smk.wildcards.tile), int(smk.wildcards.tiles)
    ds = kind.compute_tile(params, k, tile, tiles, Job(threads=smk.threads, backend=smk.params.backend))
    ds.attrs.update(task=k, tile=tile, tiles=tiles)  # (dropped when gathered)
    write_netcdf(ds, smk.output[0])
    print(ds)
