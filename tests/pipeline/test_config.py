"""Configuration: schema + kind checks (bad configs stop with a message naming the key),
resolution into per-experiment parameters through the registry, quick-config merge."""
from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml
from jsonschema import Draft202012Validator
from safebasins.pipeline.config import merge_config as update_config

from safebasins import wells
from safebasins.pipeline import catalog
from safebasins.pipeline.config import REPO_ROOT, ConfigError, build_schema, load_yaml, validate_config
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import KINDS
from safebasins.pipeline.params_file import dump_params
from safebasins.pipeline.values import range_values, tile_slice
from safebasins.io.datasets import params_hash

ROOT = REPO_ROOT


@pytest.fixture(scope="module")
def base():
    return load_yaml(ROOT / "config" / "config.yaml")


def merged(base, override):
    cfg = copy.deepcopy(base)
    update_config(cfg, override)
    return cfg


def test_paper_config_plans_every_declared_experiment(base):
    run = plan(copy.deepcopy(base))
    declared = [d.name for d in catalog.DECLARATIONS]
    assert list(run.experiments) == declared + list(base["experiments"])
    for name, exp in run.experiments.items():
        assert exp.params["experiment"] == name and exp.params["kind"] == exp.kind.name
        assert yaml.safe_load(dump_params(exp.params)) == exp.params, name     # the YAML file round-trips
        assert exp.figure is not None and exp.figure.packaged == (name in declared)
        for f in exp.figure.dataset_files():  # a figure reads only datasets and parameter files of the run
            assert f in run.datasets() or f in run.param_files(), (name, f)
        assert len(exp.tasks) == len(exp.params.get("tasks", ())), name
    # random experiments never share a stream
    seeds = [s for e in run.experiments.values() for s in ([e.params["seed"]] if "seed" in e.params else [])
             + e.params.get("seeds", [])]
    assert len(seeds) == len(set(seeds)) > 5


def test_quick_config_merges_and_is_small(base):
    run = plan(merged(base, load_yaml(ROOT / "config" / "quick.yaml")))
    res = run.params()
    assert res["fig05"]["F"] == base["figures"]["fig05"]["F"]  # paper values inherited from config.yaml
    assert (res["fig13"]["grid"]["n"] == [24, 24]
            and res["fig13"]["grid"]["q0"] == base["figures"]["fig13"]["grid"]["q0"])
    assert res["fig21"]["cycles"] <= 300


def test_defaults_filled_from_the_schema(base):
    cfg = copy.deepcopy(base)
    del cfg["numerics"], cfg["fourier"]
    del cfg["figures"]["fig13"]["cycles"]
    validate_config(cfg)
    assert cfg["fourier"] == "paper" and cfg["numerics"] == {"steps_per_cycle": 32, "threads": 1, "tiles": 0,
                                                            "budget_core_hours": 1.0, "allow_expensive": False,
                                                            "budget_analytic_evaluations": 2e9, "backend": "cpu"}
    assert cfg["figures"]["fig13"]["cycles"] == 3000
    assert cfg["extensions"] == []


def test_schema_is_valid_and_library_default_agrees():
    """One schema assembled from the registry; its steps_per_cycle default is the engine's."""
    from safebasins.numerics import DEFAULT_STEPS_PER_CYCLE

    schema = build_schema()
    Draft202012Validator.check_schema(schema)
    assert set(KINDS) <= set(schema["$defs"])
    assert schema["properties"]["numerics"]["properties"]["steps_per_cycle"]["default"] == DEFAULT_STEPS_PER_CYCLE


def test_extras_defaults_match_config(base):
    """Without an `extras:` block the schema defaults give the same parameters as config.yaml."""
    cfg = copy.deepcopy(base)
    del cfg["extras"]
    a = plan(cfg).params()
    b = plan(copy.deepcopy(base)).params()
    extras = [d.name for d in catalog.DECLARATIONS if d.key[0] == "extras"]
    assert [a[e] for e in extras] == [b[e] for e in extras]


def test_resolution_is_per_experiment(base):
    """Changing Fig 16's F list changes only fig16's resolved parameters (and hash)."""
    a = plan(copy.deepcopy(base)).params()
    b = plan(merged(base, {"figures": {"fig16": {"F": [0.001, 0.002]}}})).params()
    changed = [e for e in a if params_hash(a[e]) != params_hash(b[e])]
    assert changed == ["fig16"]
    # tiles / threads do not change any result, so they are not part of any parameter file
    c = plan(merged(base, {"numerics": {"tiles": 4, "threads": 2}})).params()
    assert all(params_hash(a[e]) == params_hash(c[e]) for e in a)


def test_range_values():
    assert range_values({"start": 0.001, "stop": 0.071, "step": 0.005})[-1] == 0.071
    assert range_values({"start": 0.5, "stop": 1.0, "num": 3}) == [0.5, 0.75, 1.0]


def test_tile_slices_cover_exactly():
    for n in (1, 7, 24, 300):
        for tiles in range(1, min(n, 9) + 1):
            idx = []
            for t in range(tiles):
                sl = tile_slice(n, tiles, t)
                idx.extend(range(sl.start, sl.stop))
            assert idx == list(range(n))


# ---------------------------------------------------------------- bad configurations
# (override merged into the paper config, key that the message must name)
BAD = [
    ({"figures": {"fig13": {"xi_max": [0.1, 0.3]}}}, "figures.fig13.xi_max[1]", "barrier energy 0.25 of the quartic"),
    ({"figures": {"fig05": {"xi_max": 0.26}}}, "figures.fig05.xi_max", "barrier energy"),
    ({"figures": {"fig20": {"xi_max": [0.2501]}}}, "figures.fig20.xi_max[0]", "barrier energy"),
    ({"figures": {"fig05": {"F": -0.1}}}, "figures.fig05.F", "minimum"),
    ({"figures": {"fig16": {"F": [0.01, -0.01]}}}, "figures.fig16.F[1]", "minimum"),
    ({"figures": {"fig19": {"F": {"start": -0.01, "stop": 0.07, "step": 0.005}}}}, "figures.fig19.F.start", ">= 0"),
    ({"figures": {"fig05": {"F": "big"}}}, "figures.fig05.F", "type"),
    ({"figures": {"fig13": {"cycles": 2.5}}}, "figures.fig13.cycles", "type"),
    ({"figures": {"fig13": {"cycles": 0}}}, "figures.fig13.cycles", "minimum"),
    ({"figures": {"fig10": {"Omega": {"start": 1.0, "stop": 0.5, "num": 5}}}}, "figures.fig10.Omega", "empty range"),
    ({"figures": {"fig01": {"Omega": {"start": 0.5, "stop": 1.0, "num": 0}}}}, "figures.fig01.Omega.num", "minimum"),
    ({"figures": {"fig10": {"numeric": {"Omega": {"start": 0.9, "stop": 0.9, "num": 4}}}}},
     "figures.fig10.numeric.Omega", "empty range"),
    ({"figures": {"fig02": {"Omega": {"start": -0.5, "stop": 1.0, "num": 5}}}}, "figures.fig02.Omega.start", ""),
    ({"figures": {"fig99": {"F": 0.1}}}, "figures.fig99", "unknown figure name"),
    ({"figures": {"figure13": {}}}, "figures.figure13", "unknown figure name"),
    ({"figures": {"fig13": {"Fmax": 0.1}}}, "figures.fig13.Fmax", "unknown key"),
    ({"numerics": {"tiles": -1}}, "numerics.tiles", "minimum"),
    ({"numerics": {"threads": "two"}}, "numerics.threads", "type"),
    ({"numerics": {"steps_per_cycle": 16.5}}, "numerics.steps_per_cycle", "type"),
    ({"numerics": {"tiles": 500}}, "numerics.tiles", "q0 rows"),
    ({"fourier": "approximate"}, "fourier", ""),
    ({"unknown_knob": 1}, "unknown_knob", "unknown key"),
    ({"figures": {"fig13": {"Psi": "tau"}}}, "figures.fig13.Psi", ""),
    ({"figures": {"fig13": {"grid": {"q0": [1.0, -1.0]}}}}, "figures.fig13.grid.q0", "empty interval"),
    ({"extras": {"erosion": {"t_eval": [10, 5000]}}}, "extras.erosion.t_eval", "beyond the horizon"),
    ({"extras": {"erosion": {"F": {"start": -0.01, "stop": 0.1, "step": 0.01}}}}, "extras.erosion.F.start", ">= 0"),
    ({"extras": {"erosion": {"xi_max": [0.18, 0.25]}}}, "extras.erosion.xi_max[1]", "xi_max < 0.25"),
    ({"extras": {"erosion": {"fourier": ["paper", "truncated"]}}}, "extras.erosion.fourier", ""),
    ({"extras": {"true_basin": {"n_psi": 0}}}, "extras.true_basin.n_psi", "minimum"),
    ({"extras": {"true_basin": {"grid": {"p0": [0.5, -0.5]}}}}, "extras.true_basin.grid.p0", "empty interval"),
    ({"extras": {"fourier_compare": {"iou": ["fig13", "fig20"]}}}, "extras.fourier_compare.iou[1]",
     "'fig20' has no escape chart"),
    ({"extras": {"fourier_compare": {"fcr": ["fig10", "fig10"]}}}, "extras.fourier_compare.fcr[1]", "twice"),
    ({"extras": {"fourier_compare": {"t_eval": 5000}}}, "extras.fourier_compare.t_eval", "horizon"),
    ({"extras": {"phase_map": {}}}, "extras.phase_map", "unknown key"),
    ({"figures": {"fig13": {"grid": {"n": 0}}}}, "figures.fig13.grid.n", "minimum"),
    ({"figures": {"fig13": {"grid": {"p0": [0.5]}}}}, "figures.fig13.grid.p0", ""),
    ({"figures": {"fig01": {"xi_ini": [0.1, 0.3]}}}, "figures.fig01.xi_ini[1]", ""),
    ({"figures": {"fig01": {"xi_ini": [0.1, 0.245]}}}, "figures.fig01.xi_ini[1]", "below the truncation level"),
    ({"figures": {"fig04": {"xi_max": [0.1, 0.25]}}}, "figures.fig04.xi_max[1]", "separatrix"),
    ({"figures": {"fig01": {"xi_max": [0.2, 0.24], "xi_ini": [0.1, 0.15, 0.2]}}}, "figures.fig01", "equal length"),
    ({"figures": {"fig16": {"xi_max": [0.1, 0.2]}}}, "figures.fig16.F", "only one of F and xi_max"),
    ({"figures": {"fig18": {"n_trajectories": 5000}}}, "figures.fig18.n_trajectories", "n_candidates"),
    ({"figures": {"fig19": {"q_max": 1.5}}}, "figures.fig19.q_max", "maximum"),
    ({"figures": {"fig19": {"repeats": 0}}}, "figures.fig19.repeats", "minimum"),
    ({"figures": {"fig21": {"t_eval": [500, 20000]}}}, "figures.fig21.t_eval", "horizon"),
    ({"figures": {"fig22": {"source": "fig13"}}}, "figures.fig22.source", "not an escape-chart experiment"),
    ({"experiments": {"toy": {"kind": "no_such_kind"}}}, "experiments.toy.kind", ""),
    ({"experiments": {"fig13": {"kind": "chart"}}}, "experiments.fig13", "already an experiment"),
    ({"experiments": {"zoom": {"kind": "chart", "F": 0.01, "Omega": 0.9, "Psi": 0, "xi_max": 0.3,
                               "grid": {"q0": [-1, 1], "p0": [-1, 1], "n": 10}}}}, "experiments.zoom.xi_max",
     "barrier energy"),
    ({"extensions": ["no.such.module"]}, "extensions[0]", "cannot import"),
    ({"figures": {"fig10": {"numeric": {"F_bracket": [0.3, 0.1]}}}}, "figures.fig10.numeric.F_bracket",
     "empty bracket"),
    ({"figures": {"fig10": {"numeric": {"tol": 0}}}}, "figures.fig10.numeric.tol", ""),
    ({"seed": -3}, "seed", "minimum"),
    # non-finite numbers, degenerate grids, duplicates, ranges that stop short, num + step
    ({"figures": {"fig05": {"F": float("nan")}}}, "figures.fig05.F", "finite"),
    ({"figures": {"fig05": {"Omega": float("inf")}}}, "figures.fig05.Omega", "finite"),
    ({"figures": {"fig13": {"xi_max": [0.12, float("nan")]}}}, "figures.fig13.xi_max[1]", "finite"),
    ({"figures": {"fig13": {"grid": {"q0": [float("-inf"), 0.9]}}}}, "figures.fig13.grid.q0[0]", "finite"),
    ({"figures": {"fig10": {"numeric": {"tol": float("nan")}}}}, "figures.fig10.numeric.tol", "finite"),
    ({"figures": {"fig13": {"grid": {"n": 1}}}}, "figures.fig13.grid.n", "minimum of 3"),
    ({"figures": {"fig13": {"grid": {"n": [2, 200]}}}}, "figures.fig13.grid.n[0]", "minimum of 3"),
    ({"figures": {"fig16": {"F": [0.01, 0.01]}}}, "figures.fig16.F[1]", "listed twice"),
    ({"figures": {"fig14": {"xi_max": [0.16, 0.16]}}}, "figures.fig14.xi_max[1]", "listed twice"),
    ({"figures": {"fig21": {"t_eval": [500, 500]}}}, "figures.fig21.t_eval[1]", "listed twice"),
    ({"extras": {"erosion": {"t_eval": [10, 10]}}}, "extras.erosion.t_eval[1]", "listed twice"),
    ({"figures": {"fig01": {"xi_ini": [0.1, 0.1]}}}, "figures.fig01", "repeats an earlier curve"),
    ({"figures": {"fig19": {"F": {"start": 0.001, "stop": 0.07, "step": 0.005}}}}, "figures.fig19.F",
     "not reached by whole steps"),
    ({"figures": {"fig01": {"Omega": {"step": 0.01}}}}, "figures.fig01.Omega", "set the other one to null"),
    # the well of an experiment
    ({"figures": {"fig05": {"well": "sextic"}}}, "figures.fig05.well", ""),
    ({"figures": {"fig05": {"well": {"polynomial": [0, 0.1, 0.5, 0, -0.25]}}}}, "figures.fig05.well", "V'(0) = 0"),
    ({"figures": {"fig05": {"well": {"polynomial": [0, 0, -0.5, 0, 1]}}}}, "figures.fig05.well", "c_2"),
    ({"figures": {"fig05": {"well": {"polynomial": [0, 0, 0.5, 0, 0.25]}}}}, "figures.fig05.well", "no barrier"),
    ({"figures": {"fig05": {"well": "cubic", "xi_max": 0.2}}}, "figures.fig05.xi_max",
     "barrier energy 0.166667 of the cubic"),
    ({"figures": {"fig01": {"well": "cubic", "xi_max": [0.1, 0.15, 0.17]}}}, "figures.fig01.xi_max[2]", "cubic"),
    ({"figures": {"fig04": {"well": "cubic", "xi_max": [0.1, wells.cubic().barrier_energy]}}},
     "figures.fig04.xi_max[1]", "separatrix"),
    ({"figures": {"fig19": {"well": "cubic"}}}, "figures.fig19.well", "quartic only"),
    ({"figures": {"fig18": {"well": "cubic", "xi_max": 0.1}}}, "figures.fig18.well", "quartic only"),
    ({"extras": {"erosion": {"well": "cubic", "xi_max": [0.1]}}}, "extras.erosion.fourier", "exact first harmonic"),
    ({"experiments": {"c": {"kind": "chart", "well": "cubic", "F": 0.01, "Omega": 0.9, "Psi": 0, "xi_max": 0.1,
                            "q_max": 0.5, "grid": {"q0": [-1, 1], "p0": [-1, 1], "n": 10}}}}, "experiments.c.q_max",
     "symmetric displacement"),
]


@pytest.mark.parametrize("override,key,words", BAD, ids=[b[1] + ":" + (b[2] or "x") for b in BAD])
def test_bad_config_names_key(base, override, key, words):
    cfg = merged(base, override)
    with pytest.raises(ConfigError) as exc:
        validate_config(cfg)
    msg = str(exc.value)
    assert msg.startswith(f"config key {key}:") or msg.startswith(f"config key {key}"), msg
    assert words in msg, msg


@pytest.mark.parametrize("missing", [("figures", "fig07"), ("figures", "fig13", "xi_max"),
                                     ("figures", "fig05", "grid"), ("figures", "fig10", "numeric"),
                                     ("figures", "fig19", "Omega"), ("figures",)])
def test_missing_key_named(base, missing):
    cfg = copy.deepcopy(base)
    d = cfg
    for k in missing[:-1]:
        d = d[k]
    del d[missing[-1]]
    with pytest.raises(ConfigError) as exc:
        validate_config(cfg)
    assert f"config key {'.'.join(missing)}: missing required key" in str(exc.value)


def test_not_a_mapping():
    with pytest.raises(ConfigError, match="mapping"):
        validate_config([1, 2, 3])


def test_override_can_switch_a_range_from_num_to_step(base):
    cfg = merged(base, {"figures": {"fig01": {"Omega": {"num": None, "step": 0.01}}}})
    assert plan(cfg).params()["fig01"]["Omega"] == pytest.approx(list(np.arange(0.5, 1.2 + 1e-9, 0.01)))


def test_cost_guard_refuses_above_budget_unless_allowed(base):
    from safebasins.pipeline.cost import guard

    huge = {"figures": {"fig13": {"grid": {"n": 100000}, "cycles": 10000000}}}
    with pytest.raises(ConfigError) as exc:
        guard(plan(merged(base, huge)), cores=2)
    msg = str(exc.value)
    assert msg.startswith("config key numerics.budget_core_hours:") and "fig13" in msg and "allow_expensive" in msg
    line = guard(plan(merged(base, {**huge, "numerics": {"allow_expensive": True}})), cores=2)
    assert "core-hours" in line and "h on 2 core(s)" in line
    assert "core-hours" in guard(plan(copy.deepcopy(base)), cores=2)  # the paper run is within budget
