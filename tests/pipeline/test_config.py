"""Configuration: schema + semantic validation (bad configs stop with a message naming the key),
resolution into per-experiment parameters, quick-config merge."""
from __future__ import annotations

import copy
import math

import pytest
import yaml
from snakemake.utils import update_config

from safebasins import config as sbc

ROOT = sbc.REPO_ROOT


@pytest.fixture(scope="module")
def base():
    return sbc.load_yaml(ROOT / "config" / "config.yaml")


def merged(base, override):
    cfg = copy.deepcopy(base)
    update_config(cfg, override)
    return cfg


def test_paper_config_valid_and_resolves(base):
    cfg = sbc.validate_config(copy.deepcopy(base))
    res = sbc.resolve(cfg)
    assert list(res) == list(sbc.EXPERIMENTS) + list(sbc.EXTRAS)
    ero, tb, fo = res["extra_erosion"], res["extra_true_basin"], res["extra_fourier"]
    assert ero["F"][0] == 0.0 and ero["xi_max"] == [0.18, 0.22] and ero["Psi"] == pytest.approx(math.pi)
    assert len(ero["tasks"]) == len(ero["F"]) and max(ero["t_eval"]) <= ero["cycles"]
    assert len(tb["tasks"]) == len(tb["Psi"]) == 16 and tb["tasks"][3]["Psi"] == tb["Psi"][3]
    assert fo["fcr"] == ["fig10", "fig11", "fig12"] and len(fo["iou"]) == 5
    assert sbc.dataset_files("extra_fourier", params=fo)[0] == "results/data/extras/fourier_fcr_fig10.nc"
    # paper values survive resolution
    assert res["fig05"]["F"] == 0.0876 and res["fig05"]["Omega"] == 0.92 and res["fig05"]["xi_max"] == 0.24
    assert res["fig13"]["scan"] == "xi_max" and res["fig13"]["Psi"] == pytest.approx(math.pi)
    assert res["fig16"]["scan"] == "F" and len(res["fig16"]["tasks"]) == len(res["fig16"]["F"])
    assert res["fig13"]["grid"]["n"] == [200, 200] and res["fig13"]["cycles"] == 3000
    f19 = res["fig19"]
    assert f19["F"][0] == 0.001 and f19["F"][-1] == 0.071 and len(f19["F"]) == 15
    assert f19["q_max"] == 1.0 and f19["n_ic"] == 10000 and f19["repeats"] == 5 and len(set(f19["seeds"])) == 5
    assert f19["Omega"] == 0.9 and f19["Psi"] == 0.0 and f19["xi_max"] == 0.25
    assert res["fig18"]["n_trajectories"] == 100 and res["fig18"]["n_iter"] == 3000
    for e in ("fig20", "fig21"):
        assert res[e]["grid"]["n"] == [300, 300] and res[e]["cycles"] == 11000 and res[e]["t_eval"] == [500, 11000]
    assert res["fig10"]["numeric"]["tol"] == 5e-5 and res["fig10"]["numeric"]["cycles"] == 3000
    assert 20 <= len(res["fig10"]["numeric"]["Omega"]) <= 30
    assert res["fig11"]["curves"][0]["gamma0"] == 0.25 and res["fig12"]["curves"][0]["xi0"] == 0.15


def test_quick_config_merges_and_is_small(base):
    cfg = sbc.validate_config(merged(base, sbc.load_yaml(ROOT / "config" / "quick.yaml")))
    res = sbc.resolve(cfg)
    assert res["fig05"]["F"] == 0.0876  # paper values inherited from config.yaml
    assert res["fig13"]["grid"]["n"] == [24, 24] and res["fig13"]["grid"]["q0"] == [-0.95, 0.95]
    assert res["fig21"]["cycles"] <= 300


def test_defaults_filled(base):
    cfg = copy.deepcopy(base)
    del cfg["numerics"], cfg["fourier"]
    del cfg["figures"]["fig13"]["cycles"]
    sbc.validate_config(cfg)
    assert cfg["fourier"] == "paper" and cfg["numerics"] == {"steps_per_cycle": 64, "threads": 1, "tiles": 1}
    assert cfg["figures"]["fig13"]["cycles"] == 3000


def test_extras_defaults_match_config(base):
    """Without an `extras:` block the schema defaults give the same parameters as config.yaml."""
    cfg = copy.deepcopy(base)
    del cfg["extras"]
    a = sbc.resolve_extras(sbc.validate_config(cfg))
    b = sbc.resolve_extras(sbc.validate_config(copy.deepcopy(base)))
    assert a == b and set(a) == set(sbc.EXTRAS)


def test_resolution_is_per_experiment(base):
    """Changing Fig 16's F list changes only fig16's resolved parameters (and hash)."""
    a = sbc.resolve(sbc.validate_config(copy.deepcopy(base)))
    b = sbc.resolve(sbc.validate_config(merged(base, {"figures": {"fig16": {"F": [0.001, 0.002]}}})))
    changed = [e for e in a if sbc.params_hash(a[e]) != sbc.params_hash(b[e])]
    assert changed == ["fig16"]
    # tiles / threads do not change any result, so they are not part of any parameter file
    c = sbc.resolve(sbc.validate_config(merged(base, {"numerics": {"tiles": 4, "threads": 2}})))
    assert all(sbc.params_hash(a[e]) == sbc.params_hash(c[e]) for e in a)


def test_range_values():
    assert sbc.range_values({"start": 0.001, "stop": 0.071, "step": 0.005})[-1] == 0.071
    assert sbc.range_values({"start": 0.5, "stop": 1.0, "num": 3}) == [0.5, 0.75, 1.0]
    assert sbc.q_max_from_xi(0.25) == 1.0


def test_tile_slices_cover_exactly():
    for n in (1, 7, 24, 300):
        for tiles in range(1, min(n, 9) + 1):
            idx = []
            for t in range(tiles):
                s = sbc.tile_slice(n, tiles, t)
                idx.extend(range(s.start, s.stop))
            assert idx == list(range(n))


# ---------------------------------------------------------------- bad configurations
# (override merged into the paper config, key that the message must name)
BAD = [
    ({"figures": {"fig13": {"xi_max": [0.1, 0.3]}}}, "figures.fig13.xi_max[1]", "maximum"),
    ({"figures": {"fig05": {"xi_max": 0.26}}}, "figures.fig05.xi_max", "maximum"),
    ({"figures": {"fig20": {"xi_max": [0.2501]}}}, "figures.fig20.xi_max[0]", "maximum"),
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
    ({"numerics": {"tiles": 0}}, "numerics.tiles", "minimum"),
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
    ({"extras": {"fourier_compare": {"iou": ["fig13", "fig20"]}}}, "extras.fourier_compare.iou[1]", "fig20"),
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
    ({"figures": {"fig22": {"source": "fig13"}}}, "figures.fig22.source", ""),
    ({"figures": {"fig10": {"numeric": {"F_bracket": [0.3, 0.1]}}}}, "figures.fig10.numeric.F_bracket", "empty bracket"),
    ({"figures": {"fig10": {"numeric": {"tol": 0}}}}, "figures.fig10.numeric.tol", ""),
    ({"seed": -3}, "seed", "minimum"),
]


@pytest.mark.parametrize("override,key,words", BAD, ids=[b[1] + ":" + (b[2] or "x") for b in BAD])
def test_bad_config_names_key(base, override, key, words):
    cfg = merged(base, override)
    with pytest.raises(sbc.ConfigError) as exc:
        sbc.validate_config(cfg)
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
    with pytest.raises(sbc.ConfigError) as exc:
        sbc.validate_config(cfg)
    assert f"config key {'.'.join(missing)}: missing required key" in str(exc.value)


def test_not_a_mapping():
    with pytest.raises(sbc.ConfigError, match="mapping"):
        sbc.validate_config([1, 2, 3])


def test_snakemake_validate_agrees(base):
    """The schema is also valid for snakemake.utils.validate (used by the workflow)."""
    from snakemake.utils import validate

    cfg = copy.deepcopy(base)
    validate(cfg, str(sbc.SCHEMA_PATH))
    bad = merged(base, {"figures": {"fig05": {"xi_max": 0.3}}})
    with pytest.raises(Exception, match="xi_max"):
        validate(bad, str(sbc.SCHEMA_PATH))


def test_params_yaml_roundtrip(base):
    res = sbc.resolve(sbc.validate_config(copy.deepcopy(base)))
    for e, p in res.items():
        assert yaml.safe_load(sbc.dump_params(p)) == p, e
