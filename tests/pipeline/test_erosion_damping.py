"""The erosion kind takes the damped equation: its config accepts damping > 0, the parameters
carry it, the analytic cost counts damped slow trajectories, the analytic product integrates the
damped slow flow and the chart tiles the damped equation (both record ``damping``)."""
from __future__ import annotations

import numpy as np

from safebasins.pipeline.cost import DAMPED_BASIN_EVALUATIONS, analytic_cost
from safebasins.pipeline.kinds.extras import build_erosion_analytic
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import Job
from safebasins.pipeline.registry import chart_tile
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

BLOCK = {"kind": "erosion", "damping": 0.05, "F": [0.0, 0.045], "Omega": 0.85, "xi_max": [0.18],
         "grid": {"q0": [-0.85, 0.85], "p0": [-0.7, 0.7], "n": 9}, "cycles": 20, "t_eval": [20],
         "fourier": "exact", "analytic_n": None}


def test_damped_erosion_plans_and_costs_damped_trajectories(base):
    run = plan(merged(base, {"experiments": {"my_erosion": BLOCK}}))
    exp = run.experiments["my_erosion"]
    assert exp.kind.damped and exp.params["damping"] == 0.05
    assert analytic_cost(exp, run) == 2 * 9 * 9 * DAMPED_BASIN_EVALUATIONS
    undamped = plan(merged(base, {"experiments": {"my_erosion": {**BLOCK, "damping": 0.0}}}))
    assert analytic_cost(undamped.experiments["my_erosion"], undamped) == 2 * 9 * 9


def test_damped_erosion_products_integrate_the_damped_equation(base):
    exp = plan(merged(base, {"experiments": {"my_erosion": BLOCK}})).experiments["my_erosion"]
    ana = build_erosion_analytic(exp.params, {}, Job())
    assert ana.attrs["damping"] == 0.05 and "n_undecided" in ana
    assert float(ana["GIM"].sel(F=0.0).squeeze()) == 1.0
    tile = chart_tile(exp.kind, exp.params, 1, 0, 1, Job())
    assert tile.attrs["damping"] == 0.05
    assert np.isfinite(ana["GIM"].values).all()
