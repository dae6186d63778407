"""The minimal_fatal_shock kind (config ``damped.escape_equation_fatal_shock`` and
``damped.quartic_fatal_shock``): resolved with its phases, horizon and search (the schema's defaults
are the library's), refused where it cannot run (naming the key), its build function is the library
call, and it is built end to end on the quick config."""
from __future__ import annotations

import inspect
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

from safebasins.analysis.fatal_shock import minimal_fatal_shock
from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.kinds.fatal_shock import build_fatal_shock, shock_phases
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import KINDS, Job
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

NAMES = ("damped_escape_fatal_shock", "damped_quartic_fatal_shock")
#: a run of a few seconds: 2 phases, a short horizon, a coarse search
SMALL = {"n_phases": 2, "cycles": 10, "steps_per_cycle": 32,
         "search": {"n_directions": 16, "n_radii": 12, "n_lim": 21, "n_seeds": 5}}


def test_resolved(base: dict[str, Any]) -> None:
    run = plan(base)
    for name, Psi in zip(NAMES, (0.0, math.pi)):
        exp = run.experiments[name]
        p = exp.params
        assert exp.kind.name == "minimal_fatal_shock" and p["damping"] == 0.1 and p["Psi"] == Psi
        assert len(p["phases"]) == 8 and p["phases"][0] == Psi
        np.testing.assert_allclose(np.sort(p["phases"]), np.arange(8) * np.pi / 4, rtol=0, atol=1e-15)
        assert p["steps_per_cycle"] == 128 and p["cycles"] == 100 and p["weights"] is None
        assert p["search"]["n_lim"] == 201
        assert [x.path for x in exp.products] == [f"results/data/extras/{name}.nc"]
        assert exp.kind.cost(p) > 0
    assert run.experiments[NAMES[0]].params["well"] == {"name": "cubic"}
    assert run.experiments[NAMES[1]].params["well"] == {"name": "quartic"}


def test_schema_defaults_are_the_library_defaults() -> None:
    props = KINDS["minimal_fatal_shock"].schema["properties"]
    lib = inspect.signature(minimal_fatal_shock).parameters
    for key in ("cycles", "weights", "radius_max"):
        assert props[key]["default"] == lib[key].default, key
    for key, spec in props["search"]["properties"].items():
        assert spec["default"] == lib[key].default, key


def test_shock_phases() -> None:
    assert shock_phases(0.0, 4) == [0.0, math.pi / 2, math.pi, 3 * math.pi / 2]
    ph = shock_phases(-math.pi / 2, 3)
    assert ph[0] == pytest.approx(3 * math.pi / 2) and all(0 <= x < 2 * math.pi for x in ph)


@pytest.mark.parametrize("override,key", [
    ({"damping": 0.0}, "escape_equation_fatal_shock.damping"),
    ({"search": {"n_lim": 20}}, "escape_equation_fatal_shock.search.n_lim"),
    ({"search": {"n_directions": 4}}, "escape_equation_fatal_shock.search.n_directions"),
    ({"search": {"tol": 0.5}}, "escape_equation_fatal_shock.search.tol"),
    ({"weights": [1.0, 0.0]}, "escape_equation_fatal_shock.weights"),
    ({"weights": [1.0]}, "escape_equation_fatal_shock.weights"),
    ({"n_phases": 0}, "escape_equation_fatal_shock.n_phases"),
    ({"steps_per_cycle": 2}, "escape_equation_fatal_shock.steps_per_cycle"),
    ({"radius_max": -1.0}, "escape_equation_fatal_shock.radius_max"),
    ({"xi_max": 0.2}, "escape_equation_fatal_shock.xi_max"),       # above the cubic's barrier 1/6
])
def test_refused_naming_the_key(base: dict[str, Any], override: dict[str, Any], key: str) -> None:
    with pytest.raises(ConfigError, match=key):
        plan(merged(base, {"damped": {"escape_equation_fatal_shock": override}}))


def test_build_is_the_library_call(base: dict[str, Any]) -> None:
    cfg = merged(base, {"damped": {"quartic_fatal_shock": {**SMALL, "weights": [0.25, 1.0]}}})
    p = plan(cfg).experiments["damped_quartic_fatal_shock"].params
    ds = build_fatal_shock(p, {}, Job(threads=1))
    ref = minimal_fatal_shock(0.01, 0.9, 0.1, "quartic", phases=[math.pi, 0.0], xi_max=0.25, cycles=10,
                              weights=(0.25, 1.0), n_directions=16, n_radii=12, n_lim=21, n_seeds=5,
                              steps_per_cycle=32, threads=1)
    assert list(ds["norm"].values) == ["energy", "weighted"]
    np.testing.assert_array_equal(ds["phase"].values, [math.pi, 0.0])
    for k in ("mfs", "mfs_safe", "mfs_grid", "lim", "shock_dq", "shock_dp", "escape_cycle", "q_attractor"):
        np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
    assert ds.attrs["damping"] == 0.1 and ds.attrs["cycles"] == 10 and ds.attrs["steps_per_cycle"] == 32


@pytest.mark.pipeline
def test_quick_run_builds_the_figures(quick: tuple[Path, Any]) -> None:
    wd, res = quick      # the shared quick run of `all` (tests/pipeline/conftest.py) builds them
    assert res.returncode == 0, res.stderr[-3000:]
    for name in NAMES:
        ds = xr.open_dataset(wd / f"results/data/extras/{name}.nc")
        assert ds["mfs"].dims == ("attractor", "phase", "norm") and ds.attrs["damping"] > 0
        assert (wd / f"results/figures/{name}.png").stat().st_size > 0
        assert "MFS" in (wd / f"results/captions/{name}.rst").read_text()
