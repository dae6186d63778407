"""The escape_probability and stochastic_erosion kinds (config ``noise.quartic_escape_probability`` and
``noise.escape_equation_erosion``): resolved with the run's seed, schema defaults = the library's, the
cost guard counting paths x ICs x steps (and the averaged theory's cells x steps), refused where they cannot
run (naming the key), and each build function is the library call bit for bit: the ensembles, the averaged
theory's map and its agreement with them, or an attribute saying why the theory does not apply."""
from __future__ import annotations

import inspect
import math
from typing import Any

import numpy as np
import pytest

from safebasins import theory
from safebasins.analysis import stochastic_erosion
from safebasins.analysis.agreement import probability_agreement
from safebasins.analysis.noise_theory import theory_evaluations
from safebasins.analysis.stochastic_integrity import stochastic_erosion_theory
from safebasins.numerics import escape_probability
from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.cost import NOISE_STEP_COSTS, analytic_cost
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
        for key in ("cycles", "noise_time", "correction", "variates"):
            assert props[key]["default"] == lib[key].default, (kind, key)
    th = inspect.signature(theory.escape_probability).parameters
    for kind in ("escape_probability", "stochastic_erosion"):
        props = KINDS[kind].schema["properties"]
        assert tuple(props["theory_cells"]["default"]) == th["cells"].default, kind
        assert props["theory_steps_per_cycle"]["default"] == th["steps_per_cycle"].default, kind
    props = KINDS["stochastic_erosion"].schema["properties"]
    assert props["conservative"]["default"] == ero["conservative"].default
    assert tuple(props["bottom"]["default"]) == ero["bottom"].default


def test_cost_counts_paths_ics_and_steps(base: dict[str, Any]) -> None:
    run = plan(merged(base, {"noise": {"quartic_escape_probability": TINY}}))
    exp = run.experiments[MAP]
    steps = 5 * 4 * 3 * 16
    assert exp.kind.cost(exp.params) == int(steps * 3 * 6 * (1 + NOISE_STEP_COSTS["gaussian"]))
    run = plan(merged(base, {"noise": {"escape_equation_erosion": {**TINY, "F": [0.0, 0.01], "noise": [0.0, 0.01],
                                                                   "epsilon": 0.5}}}))
    exp = run.experiments[EROSION]
    # two ensembles at noise 0 (one path each), two noisy ones, in steps of the cubic
    c = resolve_well("cubic").step_cost
    per_step = 1 + NOISE_STEP_COSTS["gaussian"] / c
    assert exp.kind.cost(exp.params) == pytest.approx(steps * (2 + 2 * 6 * per_step), abs=1)
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
    ("quartic_escape_probability", {"variates": "uniform"}, "quartic_escape_probability.variates"),
    ("escape_equation_erosion", {"variates": "three-point"}, "escape_equation_erosion.variates"),
    ("quartic_escape_probability", {"noise_time": 0.01}, "quartic_escape_probability.noise_time"),
    ("quartic_escape_probability", {"xi_max": 0.3}, "quartic_escape_probability.xi_max"),
    ("quartic_escape_probability", {"grid": {"q0": [1.0, -1.0]}}, "quartic_escape_probability.grid.q0"),
    ("quartic_escape_probability", {"theory": "yes"}, "quartic_escape_probability.theory"),
    ("quartic_escape_probability", {"theory_cells": [4, 160]}, "quartic_escape_probability.theory_cells"),
    ("quartic_escape_probability", {"theory_cells": [128]}, "quartic_escape_probability.theory_cells"),
    ("quartic_escape_probability", {"theory_steps_per_cycle": 0}, "quartic_escape_probability.theory_steps_per_cycle"),
    ("escape_equation_erosion", {"theory": "yes"}, "escape_equation_erosion.theory"),
    ("escape_equation_erosion", {"theory_cells": [128, 7]}, "escape_equation_erosion.theory_cells"),
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
    # a noise level 0 has the theory too: the noise-free slow flow's 0/1 map
    assert "theory_reason" not in ds.attrs
    assert set(np.unique(ds["P_escape_theory"].sel(noise=0.0).values)) <= {0.0, 1.0}


def test_five_point_variates_build_and_cost(base: dict[str, Any]) -> None:
    """variates: five-point reaches the library call (the dataset is its Dataset, attribute variates)
    and the cost counts that law's random numbers (NOISE_STEP_COSTS), below the Gaussian's."""
    five = {**TINY, "noise": [0.02], "variates": "five-point", "theory": False}
    exp = plan(merged(base, {"noise": {"quartic_escape_probability": five}})).experiments[MAP]
    gauss = plan(merged(base, {"noise": {"quartic_escape_probability": {**five, "variates": "gaussian"}}})
                 ).experiments[MAP]
    assert exp.kind.cost(exp.params) == int(5 * 4 * 3 * 16 * 6 * (1 + NOISE_STEP_COSTS["five-point"]))
    assert exp.kind.cost(exp.params) < gauss.kind.cost(gauss.params)
    ds = build_escape_probability(exp.params, {}, Job(threads=1))
    ref = escape_probability(np.linspace(-0.95, 0.95, 5), np.linspace(-0.75, 0.75, 4), 0.01, 0.9, math.pi, noise=0.02,
                             paths=6, xi_max=0.18, t_eval=[1, 3], seed=exp.params["seed"], cycles=3, steps_per_cycle=16,
                             threads=1, variates="five-point")
    np.testing.assert_array_equal(ds["P_escape"].values[0], ref["P_escape"].values)
    assert ds.attrs["variates"] == "five-point"


THEORY = {**TINY, "noise": [0.01, 0.02], "theory_cells": [16, 20], "theory_steps_per_cycle": 6}


def test_map_build_with_the_theory_is_the_library_calls(base: dict[str, Any]) -> None:
    p = plan(merged(base, {"noise": {"quartic_escape_probability": THEORY}})).experiments[MAP].params
    ds = build_escape_probability(p, {}, Job(threads=1))
    q0, p0 = np.linspace(-0.95, 0.95, 5), np.linspace(-0.75, 0.75, 4)
    assert ds["P_escape_theory"].dims == ("noise", "q0", "p0", "t_eval")
    assert ds["P_escape_mean_abs_difference"].dims == ("noise", "t_eval")
    means, maxima = [], []
    for i, s in enumerate((0.01, 0.02)):
        ens = escape_probability(q0, p0, 0.01, 0.9, math.pi, noise=s, paths=6, xi_max=0.18, t_eval=[1, 3],
                                 seed=p["seed"], cycles=3, steps_per_cycle=16, threads=1)
        th = theory.escape_probability(q0, p0, 0.01, 0.9, math.pi, 0.18, noise=s, t_eval=[1, 3], cells=(16, 20),
                                       steps_per_cycle=6)
        ref = probability_agreement(th, ens)
        np.testing.assert_array_equal(ds["P_escape"].values[i], ens["P_escape"].values)
        np.testing.assert_array_equal(ds["P_escape_theory"].values[i], th["P_escape"].values)
        for k in ("P_escape_mean_abs_difference", "P_escape_max_abs_difference"):
            np.testing.assert_array_equal(ds[k].values[i], ref[k].values, err_msg=f"{k} at sigma {s}")
            assert ds[k].attrs["units"] == "1" and ds[k].attrs["long_name"]
        for k in ("P_escape_mean_abs_difference_uncertain", "P_escape_theory_within_wilson"):
            assert float(ds[k].values[i]) == ref.attrs[k], (k, s)
            assert ds[k].dims == ("noise",) and ds[k].attrs["units"] == "1"
        means.append(ref.attrs["P_escape_mean_abs_difference"])
        maxima.append(ref.attrs["P_escape_max_abs_difference"])
    # the summary over noise levels (equal IC counts: the mean of the means), the solver's settings
    assert ds.attrs["P_escape_mean_abs_difference"] == pytest.approx(np.mean(means), rel=1e-14)
    assert ds.attrs["P_escape_max_abs_difference"] == max(maxima)
    assert 0 < ds.attrs["P_escape_mean_abs_difference"] < 0.2
    assert ds.attrs["theory"] == th.attrs["theory"] and ds.attrs["theory_solver"] == th.attrs["solver"]
    assert list(ds.attrs["theory_cells"]) == [16, 20] and ds.attrs["theory_steps_per_cycle"] == 6
    assert "theory_reason" not in ds.attrs


@pytest.mark.parametrize("override,reason", [
    ({"xi_max": 0.25}, "below the barrier energy"),            # the numerics' threshold at the barrier
    ({"theory": False}, "theory: false"),
])
def test_map_without_the_theory_says_why(base: dict[str, Any], override: dict[str, Any], reason: str) -> None:
    p = plan(merged(base, {"noise": {"quartic_escape_probability": {**THEORY, **override}}})).experiments[MAP].params
    ds = build_escape_probability(p, {}, Job(threads=1))
    assert ds.attrs["theory"] == "none" and reason in ds.attrs["theory_reason"]
    assert not [v for v in ds.data_vars if "theory" in str(v) or "abs_difference" in str(v)]
    assert ds["P_escape"].notnull().all()


def test_analytic_cost_counts_the_theory(base: dict[str, Any]) -> None:
    def cost(over: dict[str, Any]) -> int:
        return analytic_cost(plan(merged(base, {"noise": {"quartic_escape_probability": {**THEORY, **over}}}
                                         )).experiments[MAP])

    # the library's count (analysis.noise_theory.theory_evaluations, the command line's too): the
    # tables once, two noise levels x (16 x 20 cells x 3 cycles of 6 steps and 5 x 4 ICs)
    assert cost({}) == theory_evaluations(noise=[0.01, 0.02], t_eval=[1, 3], n_ics=20, solves=2, well="quartic",
                                          cells=(16, 20), steps_per_cycle=6)
    assert cost({"noise": [0.01, 0.02, 0.03]}) - cost({}) == cost({}) - cost({"noise": 0.01}) > 0
    assert cost({"t_eval": [1, 2.5]}) == cost({})      # the theory's horizon: the largest t_eval, up
    assert cost({"theory_cells": [32, 40]}) > cost({}) and cost({"theory_steps_per_cycle": 12}) > cost({})
    assert cost({"theory": False}) == 0
    assert cost({"noise": [0.0, 0.01]}) == cost({})      # noise 0 counted as a solve (an upper bound)
    assert cost({"noise_time": 1.0}) == cost({})          # coloured noise: the same tables and solves
    p = plan(base).experiments[MAP].params
    nq, np_ = p["grid"]["n"]
    assert analytic_cost(plan(base).experiments[MAP]) == theory_evaluations(
        noise=p["noise"], t_eval=p["t_eval"], n_ics=nq * np_, solves=3, well="quartic")


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
    # the cubic (asymmetric, in its sheared phase) from a noise level 0 (the noise-free slow flow): the
    # theory's profile is the library's
    th = stochastic_erosion_theory(q0, p0, [0.0, 0.01], 0.9, math.pi, noise=[0.0, 0.02], epsilon=[0.3, 0.5],
                                   xi_max=0.12, t_eval=[1, 3], well="cubic", cells=tuple(p["theory_cells"]),
                                   steps_per_cycle=p["theory_steps_per_cycle"])
    assert "theory_reason" not in ds.attrs
    for k in ("GIM", "LIM", "IF"):
        np.testing.assert_array_equal(ds[k + "_theory"].values, th[k].transpose(*ds[k].dims).values, err_msg=k)


QUARTIC_EROSION = {**TINY, "well": "quartic", "xi_max": 0.18, "F": [0.0, 0.01], "noise": [0.01, 0.02],
                   "epsilon": [0.3, 0.5], "paths": 12, "theory_cells": [16, 20], "theory_steps_per_cycle": 6,
                   "grid": {"q0": [-0.95, 0.95], "p0": [-0.75, 0.75], "n": [5, 4]}}


def test_erosion_build_with_the_theory_is_the_library_calls(base: dict[str, Any]) -> None:
    p = plan(merged(base, {"noise": {"escape_equation_erosion": QUARTIC_EROSION}})).experiments[EROSION].params
    ds = build_stochastic_erosion(p, {}, Job(threads=1))
    q0, p0 = np.linspace(-0.95, 0.95, 5), np.linspace(-0.75, 0.75, 4)
    ref = stochastic_erosion_theory(q0, p0, [0.0, 0.01], 0.9, math.pi, noise=[0.01, 0.02], epsilon=[0.3, 0.5],
                                    xi_max=0.18, t_eval=[1, 3], cells=(16, 20), steps_per_cycle=6)
    for k in ("GIM", "LIM", "IF"):
        assert ds[k + "_theory"].dims == ("F", "noise", "epsilon", "t_eval")
        np.testing.assert_array_equal(ds[k + "_theory"].values, ref[k].transpose(*ds[k].dims).values, err_msg=k)
        assert ds[k + "_theory"].attrs["units"] == "1" and "averaged theory" in ds[k + "_theory"].attrs["long_name"]
    assert 0 < float(ds["GIM_theory"].min()) < 1          # eroded somewhere, not empty: a profile to compare
    assert ds.attrs["theory_solver"] == ref.attrs["solver"] and list(ds.attrs["theory_cells"]) == [16, 20]
    assert analytic_cost(plan(merged(base, {"noise": {"escape_equation_erosion": QUARTIC_EROSION}}))
                         .experiments[EROSION]) == theory_evaluations(
        noise=[0.01, 0.02], t_eval=[1, 3], n_ics=20, solves=2 * 2, well="quartic", cells=(16, 20), steps_per_cycle=6)
    # the default (the cubic, from a noise level 0): its theory counted as for any well
    d = plan(base).experiments[EROSION].params
    assert analytic_cost(plan(base).experiments[EROSION]) == theory_evaluations(
        noise=d["noise"], t_eval=d["t_eval"], n_ics=int(np.prod(d["grid"]["n"])),
        solves=len(d["F"]) * len(d["noise"]), well="cubic") > 0
