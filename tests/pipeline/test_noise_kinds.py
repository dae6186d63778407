"""The escape_probability and stochastic_erosion kinds (config ``noise.quartic_escape_probability`` and
``noise.escape_equation_erosion``): resolved with the run's seed, schema defaults = the library's, the
cost guard counting paths x ICs x steps, refused where they cannot run (naming the key), and each build
function is the library call bit for bit."""
from __future__ import annotations

import inspect
import math
from typing import Any

import numpy as np
import pytest

from safebasins.analysis import stochastic_erosion
from safebasins.numerics import escape_probability
from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.cost import NOISE_STEP_COST
from safebasins.pipeline.kinds.noise import build_escape_probability, build_stochastic_erosion
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import KINDS, Job
from safebasins.wells import resolve_well
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)

MAP, EROSION = "noise_quartic_escape_probability", "noise_escape_erosion"
TINY = {"grid": {"n": [5, 4]}, "paths": 6, "t_eval": [1, 3], "cycles": 3, "steps_per_cycle": 16}


def test_resolved(base: dict[str, Any]) -> None:
    run = plan(base)
    p = run.experiments[MAP].params
    assert p["noise"] == [0.0025, 0.005, 0.01] and p["paths"] == 200 and p["Psi"] == math.pi
    assert p["seed"] == base["seed"] + 40000 and p["well"] == {"name": "quartic"}
    e = run.experiments[EROSION].params
    assert e["well"] == {"name": "cubic"} and e["noise"][0] == 0.0 and e["epsilon"] == [0.05, 0.5]
    assert e["seed"] == base["seed"] + 41000
    assert [x.path for x in run.experiments[EROSION].products] == [f"results/data/extras/{EROSION}.nc"]


def test_schema_defaults_are_the_library_defaults() -> None:
    lib = inspect.signature(escape_probability).parameters
    ero = inspect.signature(stochastic_erosion).parameters
    for kind in ("escape_probability", "stochastic_erosion"):
        props = KINDS[kind].schema["properties"]
        for key in ("cycles", "noise_time", "correction"):
            assert props[key]["default"] == lib[key].default, (kind, key)
    props = KINDS["stochastic_erosion"].schema["properties"]
    assert props["conservative"]["default"] == ero["conservative"].default
    assert tuple(props["bottom"]["default"]) == ero["bottom"].default


def test_cost_counts_paths_ics_and_steps(base: dict[str, Any]) -> None:
    run = plan(merged(base, {"noise": {"quartic_escape_probability": TINY}}))
    exp = run.experiments[MAP]
    steps = 5 * 4 * 3 * 16
    assert exp.kind.cost(exp.params) == int(steps * 3 * 6 * (1 + NOISE_STEP_COST))
    run = plan(merged(base, {"noise": {"escape_equation_erosion": {**TINY, "F": [0.0, 0.01], "noise": [0.0, 0.01],
                                                                   "epsilon": 0.5}}}))
    exp = run.experiments[EROSION]
    # two ensembles at noise 0 (one path each), two noisy ones, in steps of the cubic
    c = resolve_well("cubic").step_cost
    assert exp.kind.cost(exp.params) == pytest.approx(steps * (2 + 2 * 6 * (1 + NOISE_STEP_COST / c)), abs=1)
    doubled = merged(base, {"noise": {"escape_equation_erosion": {**TINY, "F": [0.0, 0.01], "noise": [0.0, 0.01],
                                                                  "epsilon": 0.5, "paths": 12}}})
    assert plan(doubled).experiments[EROSION].kind.cost(plan(doubled).experiments[EROSION].params) > \
        exp.kind.cost(exp.params)


@pytest.mark.parametrize("block,override,key", [
    ("quartic_escape_probability", {"paths": 0}, "quartic_escape_probability.paths"),
    ("quartic_escape_probability", {"noise": [0.01, 0.005]}, "quartic_escape_probability.noise[1]"),
    ("quartic_escape_probability", {"noise": -0.1}, "quartic_escape_probability.noise"),
    ("quartic_escape_probability", {"t_eval": [10, 60]}, "quartic_escape_probability.t_eval"),
    ("quartic_escape_probability", {"t_eval": [10, 10]}, "quartic_escape_probability.t_eval[1]"),
    ("quartic_escape_probability", {"correction": "gobet"}, "quartic_escape_probability.correction"),
    ("quartic_escape_probability", {"noise_time": 0.01}, "quartic_escape_probability.noise_time"),
    ("quartic_escape_probability", {"xi_max": 0.3}, "quartic_escape_probability.xi_max"),
    ("quartic_escape_probability", {"grid": {"q0": [1.0, -1.0]}}, "quartic_escape_probability.grid.q0"),
    ("escape_equation_erosion", {"paths": 20}, "escape_equation_erosion.paths"),
    ("escape_equation_erosion", {"epsilon": [0.5, 0.05]}, "escape_equation_erosion.epsilon[1]"),
    ("escape_equation_erosion", {"epsilon": 1.0}, "escape_equation_erosion.epsilon"),
    ("escape_equation_erosion", {"F": [0.01, 0.0]}, "escape_equation_erosion.F[1]"),
    ("escape_equation_erosion", {"bottom": [0.0]}, "escape_equation_erosion.bottom"),
    ("escape_equation_erosion", {"xi_max": 0.2}, "escape_equation_erosion.xi_max"),   # above the cubic's 1/6
])
def test_refused_naming_the_key(base: dict[str, Any], block: str, override: dict[str, Any], key: str) -> None:
    with pytest.raises(ConfigError, match=key.replace("[", r"\[").replace("]", r"\]")):
        plan(merged(base, {"noise": {block: override}}))


def test_conservative_false_takes_few_paths(base: dict[str, Any]) -> None:
    cfg = merged(base, {"noise": {"escape_equation_erosion": {"paths": 20, "conservative": False}}})
    assert plan(cfg).experiments[EROSION].params["conservative"] is False


def test_map_build_is_the_library_call(base: dict[str, Any]) -> None:
    p = plan(merged(base, {"noise": {"quartic_escape_probability": {**TINY, "noise": [0.0, 0.02]}}})
             ).experiments[MAP].params
    ds = build_escape_probability(p, {}, Job(threads=1))
    q0, p0 = np.linspace(-0.95, 0.95, 5), np.linspace(-0.75, 0.75, 4)
    assert ds["P_escape"].dims == ("noise", "q0", "p0", "t_eval")
    for i, (s, paths) in enumerate(((0.0, 1), (0.02, 6))):
        ref = escape_probability(q0, p0, 0.01, 0.9, math.pi, noise=s, paths=paths, xi_max=0.18, t_eval=[1, 3],
                                 seed=p["seed"], cycles=3, steps_per_cycle=16, threads=1)
        for k in ("P_escape", "P_escape_low", "P_escape_high"):
            np.testing.assert_array_equal(ds[k].values[i], ref[k].values, err_msg=f"{k} at sigma {s}")
    assert 0 < float(ds["P_escape"].sel(noise=0.02).mean()) < 1


def test_erosion_build_is_the_library_call(base: dict[str, Any]) -> None:
    over = {**TINY, "F": [0.0, 0.01], "noise": [0.0, 0.02], "epsilon": [0.3, 0.5], "paths": 12}
    p = plan(merged(base, {"noise": {"escape_equation_erosion": over}})).experiments[EROSION].params
    ds = build_stochastic_erosion(p, {}, Job(threads=1))
    q0, p0 = np.linspace(-0.46, 0.69, 5), np.linspace(-0.52, 0.52, 4)
    ref = stochastic_erosion(q0, p0, [0.0, 0.01], 0.9, math.pi, noise=[0.0, 0.02], epsilon=[0.3, 0.5], paths=12,
                             xi_max=0.12, t_eval=[1, 3], well="cubic", seed=p["seed"], cycles=3, steps_per_cycle=16,
                             threads=1)
    assert ds["GIM"].dims == ("F", "noise", "epsilon", "t_eval")
    for k in ("GIM", "LIM", "IF", "GIM_conservative", "LIM_conservative", "IF_conservative"):
        np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
