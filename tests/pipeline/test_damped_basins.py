"""The damped basin_chart experiment (config ``damped.quartic_basins``): resolved with
its damping, costed as damped slow trajectories, and built end to end on the quick config."""
from __future__ import annotations

import pytest
import xarray as xr

from safebasins.pipeline.cost import DAMPED_BASIN_EVALUATIONS, analytic_cost
from safebasins.pipeline.plan import plan
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

NAME = "damped_quartic_basins"


def test_damped_basin_chart_resolves_with_damping(base):
    run = plan(base)
    exp = run.experiments[NAME]
    p = exp.params
    assert exp.kind.name == "basin_chart" and exp.kind.damped
    assert p["damping"] > 0 and p["scan"] == "xi_max"
    nq, np_ = p["grid"]["n"]
    assert analytic_cost(exp, run) == (nq * np_ * DAMPED_BASIN_EVALUATIONS + p["n_points"]) * len(p["xi_max"])
    # the undamped figure of the same kind keeps its parameters (no damping key)
    assert "damping" not in run.experiments["fig14"].params


def test_basin_chart_with_zero_damping_is_the_undamped_experiment(base):
    run = plan(merged(base, {"damped": {"quartic_basins": {"damping": 0.0}}}))
    assert "damping" not in run.experiments[NAME].params


@pytest.mark.pipeline
def test_quick_run_builds_the_damped_figure(quick):
    wd, res = quick      # the shared quick run of `all` (tests/pipeline/conftest.py) builds it
    assert res.returncode == 0, res.stderr[-3000:]
    basin = xr.open_dataset(wd / f"results/data/analytic/basin_{NAME}.nc")
    chart = xr.open_dataset(wd / f"results/data/numeric/chart_{NAME}.nc")
    assert basin.attrs["damping"] == chart.attrs["damping"] > 0
    assert basin.attrs["boundary"] == "mask_outline"
    assert chart["iou"].sizes["xi_max"] == 2
    assert (wd / f"results/figures/{NAME}.png").stat().st_size > 0
