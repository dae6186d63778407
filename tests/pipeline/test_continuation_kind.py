"""The continue_attractors kind (config ``damped.escape_equation_continuation`` and
``damped.quartic_continuation``): resolved with its sweep (the schema's defaults are the library's),
refused where it cannot run (naming the key), costed, its build function is the library call, and it
is built end to end on the quick config."""
from __future__ import annotations

import inspect
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

from safebasins.analysis.continuation import continue_attractors
from safebasins.core.settling import settle_iterations
from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.kinds.continuation import build_continuation
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import KINDS, Job
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

NAMES = ("damped_escape_continuation", "damped_quartic_continuation")
KEY = "escape_equation_continuation"


def test_resolved(base: dict[str, Any]) -> None:
    run = plan(base)
    esc, qua = (run.experiments[n] for n in NAMES)
    p = esc.params
    assert esc.kind.name == "continue_attractors" and p["sweep"] == "F" and p["damping"] == 0.1
    assert p["Omega"] == 0.85 and p["Psi"] == 0.0 and p["well"] == {"name": "cubic"}
    np.testing.assert_allclose(p["F"], np.arange(31) * 0.002 + 0.04, rtol=0, atol=1e-12)
    assert p["n_grid"] == 101 and p["n_iter"] is None and p["step_max"] is None and p["steps_per_cycle"] == 32
    q = qua.params
    assert q["Psi"] == math.pi and q["Omega"] == 0.9 and q["well"] == {"name": "quartic"} and q["xi_max"] == 0.25
    assert q["F"][0] == 0.01 and q["F"][-1] == 0.2 and len(q["F"]) == 39
    for exp, name in ((esc, NAMES[0]), (qua, NAMES[1])):
        assert [x.path for x in exp.products] == [f"results/data/extras/{name}.nc"]


def test_an_Omega_sweep_resolves(base: dict[str, Any]) -> None:
    cfg = merged(base, {"damped": {KEY: {"F": 0.055, "Omega": {"start": 0.7, "stop": 1.0, "num": 4}}}})
    p = plan(cfg).experiments[NAMES[0]].params
    assert p["sweep"] == "Omega" and p["F"] == 0.055 and p["Omega"] == [0.7, 0.8, 0.9, 1.0]


def test_schema_defaults_are_the_library_defaults() -> None:
    props = KINDS["continue_attractors"].schema["properties"]
    lib = inspect.signature(continue_attractors).parameters
    for key in ("Psi", "xi_max", "n_grid", "n_iter", "step_max", "max_points"):
        assert props[key]["default"] == lib[key].default, key
    # steps_per_cycle null: the run's numerics.steps_per_cycle, whose default is the library's
    assert props["steps_per_cycle"]["default"] is None


def test_cost_counts_the_labels_and_the_branches(base: dict[str, Any]) -> None:
    """The labels' map steps, counted here from the resolved parameters, plus the branches' share,
    which grows as step_max shrinks and is capped by max_points."""
    run = plan(base)
    p = run.experiments[NAMES[0]].params
    kind = KINDS["continue_attractors"]
    labels = len(p["F"]) * settle_iterations(0.1, 0.85) * 101 ** 2 * 32
    assert settle_iterations(0.1, 0.85) == 50
    branches = kind.cost(p) - labels
    assert branches > 0
    finer = kind.cost({**p, "step_max": 0.01}) - labels        # the cubic window's width 2.0: 200 steps a pass
    assert finer > 5 * branches
    capped = kind.cost({**p, "step_max": 1e-4, "max_points": 50}) - labels
    assert capped == kind.cost({**p, "step_max": 1e-5, "max_points": 50}) - labels < finer
    om = plan(merged(base, {"damped": {KEY: {"F": 0.055, "Omega": {"start": 0.7, "stop": 1.0, "num": 4}}}}))
    po = om.experiments[NAMES[0]].params
    assert kind.cost(po) - branches == sum(settle_iterations(0.1, w) for w in po["Omega"]) * 101 ** 2 * 32


@pytest.mark.parametrize("override,key", [
    ({"damping": 0.0}, f"{KEY}.damping"),
    ({"F": 0.05}, f"{KEY}.F"),                                                       # neither swept
    ({"Omega": {"start": 0.7, "stop": 1.0, "num": 4}}, f"{KEY}.Omega"),              # both swept
    ({"F": {"start": 0.1, "stop": 0.04, "num": 4}}, f"{KEY}.F"),                     # empty range
    ({"F": {"start": 0.04, "stop": 0.1, "step": 0.5}}, f"{KEY}.F.step"),
    ({"F": {"start": -0.01, "stop": 0.1, "step": 0.01}}, f"{KEY}.F"),
    ({"F": 0.05, "Omega": {"start": -0.5, "stop": 1.0, "num": 4}}, f"{KEY}.Omega"),
    ({"n_grid": 5}, f"{KEY}.n_grid"),
    ({"n_iter": 0}, f"{KEY}.n_iter"),
    ({"step_max": 0.0}, f"{KEY}.step_max"),
    ({"max_points": 2}, f"{KEY}.max_points"),
    ({"steps_per_cycle": 2}, f"{KEY}.steps_per_cycle"),
    ({"xi_max": 0.2}, f"{KEY}.xi_max"),                                # above the cubic's barrier 1/6
    ({"Psi": "two"}, f"{KEY}.Psi"),
])
def test_refused_naming_the_key(base: dict[str, Any], override: dict[str, Any], key: str) -> None:
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        plan(merged(base, {"damped": {KEY: override}}))


def test_build_is_the_library_call(base: dict[str, Any]) -> None:
    """Below the hysteresis band (one attractor, no fold): a run of a few seconds."""
    small = {"F": {"start": 0.03, "stop": 0.04, "step": None, "num": 3}, "n_grid": 15, "n_iter": 20,
             "steps_per_cycle": 16, "step_max": 0.3}
    p = plan(merged(base, {"damped": {KEY: small}})).experiments[NAMES[0]].params
    ds = build_continuation(p, {}, Job(threads=1))
    ref = continue_attractors(0.85, [0.03, 0.035, 0.04], 0.1, "cubic", Psi=0.0, xi_max=1.0 / 6.0, n_grid=15,
                              n_iter=20, step_max=0.3, steps_per_cycle=16, threads=1)
    assert set(ds.data_vars) == set(ref.data_vars) and ds.sizes == ref.sizes and ds.sizes["attractor"] == 1
    for k in ds.data_vars:
        np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
    np.testing.assert_array_equal(ds["F"].values, ref["F"].values)
    assert ds.attrs["damping"] == 0.1 and ds.attrs["parameter"] == "F" and ds.attrs["n_grid"] == 15


@pytest.mark.pipeline
def test_quick_run_builds_the_figures(quick: tuple[Path, Any]) -> None:
    wd, res = quick      # the shared quick run of `all` (tests/pipeline/conftest.py) builds them
    assert res.returncode == 0, res.stderr[-3000:]
    for name in NAMES:
        ds = xr.open_dataset(wd / f"results/data/extras/{name}.nc")
        assert ds["GIM"].dims == ("F", "attractor") and ds.attrs["damping"] > 0
        assert (wd / f"results/figures/{name}.png").stat().st_size > 0
        assert "Safe basin: GIM" in (wd / f"results/captions/{name}.rst").read_text()
