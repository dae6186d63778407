"""Configurations that were accepted but wrong: each is now a ConfigError naming the file
or the key and saying why, before any job; the cost guard counts analytic work and the targets
requested; `snakemake experiments` builds the experiments the user's config file names."""
from __future__ import annotations

import copy
import importlib.util

import pytest

from safebasins.pipeline.config import REPO_ROOT, ConfigError, load_yaml
from safebasins.pipeline.cost import analytic_costs, guard
from safebasins.pipeline.plan import plan
from tests.pipeline.sandbox import make_sandbox, run_snakemake
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)


def refused(cfg, key):
    with pytest.raises(ConfigError) as exc:
        plan(cfg)
    assert str(exc.value).startswith(f"config key {key}: "), str(exc.value)
    return str(exc.value)


# ------------------------------------------------------------------ values past the separatrix
def test_manifold_top_above_or_at_the_separatrix(base):
    for top in (0.26, 0.25):
        msg = refused(merged(base, {"figures": {"fig05": {"manifold": {"xi_top": top}}}}),
                      "figures.fig05.manifold.xi_top")
        assert "below the barrier energy 0.25 of the quartic well" in msg


def test_cubic_xi_max_one_sixth_is_at_the_barrier(base):
    """1/6 as a float lies below the computed barrier energy 0.16666666666666669 of the cubic: within
    a relative 1e-12 it counts as at the barrier, where the analytic products are singular."""
    for block, what in (("fcr_zero", "analytic F_cr"), ("basins_xi", "an analytic safe basin")):
        msg = refused(merged(base, {"escape_equation": {block: {"xi_max": [0.08, 1 / 6]}}}),
                      f"escape_equation.{block}.xi_max[1]")
        assert what in msg and "within a relative 1e-12" in msg
    refused(merged(base, {"escape_equation": {"true_basin": {"xi_max": 1 / 6}}}), "escape_equation.true_basin.xi_max")
    # just below stays accepted
    plan(merged(base, {"escape_equation": {"fcr_zero": {"xi_max": [0.08, 0.1666]}}}))


def test_polynomial_degree_above_the_compiled_classes(base):
    deg9 = {"polynomial": [0, 0, 0.5, -1 / 3, 0, 0, 0, 0, 0, 1e-4]}
    msg = refused(merged(base, {"escape_equation": {"basins_xi": {"well": deg9}}}), "escape_equation.basins_xi.well")
    assert "degree 9 exceeds the largest compiled polynomial class 8" in msg
    deg8 = {"polynomial": [0, 0, 0.5, -1 / 3, 0, 0, 0, 0, 1e-4]}
    plan(merged(base, {"escape_equation": {"basins_xi": {"well": deg8}}}))


# ------------------------------------------------------------------ the files themselves
def test_a_key_given_twice_names_file_key_and_line(tmp_path):
    f = tmp_path / "mine.yaml"
    f.write_text("figures:\n  fig13:\n    cycles: 100\n  fig14: {cycles: 100}\n  fig13:\n    cycles: 200\n")
    with pytest.raises(ConfigError, match=rf"^config file {f}, line 5: key figures.fig13 is given twice "
                                          r"\(first on line 2\)"):
        plan([REPO_ROOT / "config" / "config.yaml", f])
    f.write_text("numerics: {tiles: 1, tiles: 2}\n")
    with pytest.raises(ConfigError, match="line 1: key numerics.tiles is given twice"):
        load_yaml(f)


def test_yaml_syntax_error_names_file_and_line(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("figures:\n  fig13: {cycles: [100}\n")
    with pytest.raises(ConfigError, match=rf"^config file {f}, line 2, column \d+: not valid YAML"):
        load_yaml(f)
    f.write_text("a: 1\n\tb: 2\n")
    with pytest.raises(ConfigError, match="line 2, column 1: not valid YAML .*'\\\\t'"):
        load_yaml(f)
    with pytest.raises(ConfigError, match="cannot be read"):
        load_yaml(tmp_path / "missing.yaml")


# ------------------------------------------------------------------ analytic cost guard
@pytest.mark.parametrize("override, largest", [
    # 250,000 values of Omega x 6 curves x 2001 nodes
    ({"figures": {"fig01": {"Omega": {"start": 0.5, "stop": 1.2, "num": 250_000}}}}, "fig01"),
    ({"figures": {"fig05": {"manifold": {"n_gamma": 100_000, "n_xi": 100_000}}}}, "fig05"),
])
def test_analytic_cost_guard(base, override, largest):
    run = plan(merged(base, override))
    with pytest.raises(ConfigError) as exc:
        guard(run, cores=2)
    msg = str(exc.value)
    assert msg.startswith("config key numerics.budget_analytic_evaluations:") and f"largest: {largest}" in msg
    assert "allow_expensive" in msg
    assert "slow-flow evaluations" in guard(plan(merged(base, {**override, "numerics": {"allow_expensive": True}})))


def test_paper_run_within_the_analytic_budget_with_room(base):
    run = plan(copy.deepcopy(base))
    total = sum(analytic_costs(run).values())
    assert 1e7 < total < run.config["numerics"]["budget_analytic_evaluations"] / 5
    assert all(analytic_costs(run)[n] > 0 for n in ("fig01", "fig05", "fig13", "fig18", "extra_erosion",
                                                   "extra_true_basin", "extra_fourier", "integrity_map"))


def test_guard_counts_only_the_requested_targets(base):
    """A one-figure target is guarded (and reported) by its own cost, not the whole config's."""
    run = plan(merged(base, {"figures": {"fig13": {"grid": {"n": 2000}, "cycles": 100000}}}))
    fig01 = run.experiments_for(["results/figures/fig01.png"])
    assert fig01 == {"fig01"}
    assert "the requested targets (fig01)" in guard(run, cores=2, experiments=fig01)
    with pytest.raises(ConfigError, match="budget_core_hours: the requested targets \\(fig13\\)"):
        guard(run, cores=2, experiments=run.experiments_for(["results/figures/fig13.pdf"]))
    assert run.experiments_for(["results/figures/fig22.png"]) == {"fig21"}         # reads fig21's chart
    assert {"fig10", "fig17"} <= run.experiments_for(["results/figures/extra_fourier.png"])
    assert run.experiments_for(["results/params/fig01.yaml", "environment.lock"]) == set()
    assert run.experiments_for(["results/unknown.nc"]) is None
    assert run.experiments_for(run.datasets()) is None


# ------------------------------------------------------------------ scripts/estimate_cost.py
def _estimate_cost():
    spec = importlib.util.spec_from_file_location("estimate_cost", REPO_ROOT / "scripts" / "estimate_cost.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_estimate_cost_help_and_overlays(capsys, tmp_path):
    ec = _estimate_cost()
    with pytest.raises(SystemExit) as exc:
        ec.main(["--help"])
    assert exc.value.code == 0 and "--configfile" in capsys.readouterr().out
    quick = str(REPO_ROOT / "config" / "quick.yaml")
    assert ec.main(["--configfile", quick]) == 0
    out = capsys.readouterr().out
    assert ec.main([str(REPO_ROOT / "config" / "config.yaml"), quick]) == 0
    assert capsys.readouterr().out == out and "slow-flow evaluations" in out
    bad = tmp_path / "bad.yaml"
    bad.write_text("numerics: {tiles: 1, tiles: 2}\n")
    assert ec.main([str(bad)]) == 2
    assert "given twice" in capsys.readouterr().err


# ------------------------------------------------------------------ through snakemake
MINE = """experiments:
  my_map:
    kind: integrity_map
    Omega: {start: 0.8, stop: 1.0, num: 3}
    F: {start: 0.0, stop: 0.04, num: 3}
    Psi: pi
    xi_max: 0.18
    grid: {q0: [-0.72, 0.72], p0: [-0.63, 0.63], n: 15}
    cycles: 30
    t_eval: [10, 30]
"""


def test_experiments_target_builds_the_users_experiments(tmp_path):
    """`snakemake experiments --configfile mine.yaml` builds the experiments mine.yaml names (not the
    project's own integrity map), and the cost guard reports that target's cost."""
    wd = make_sandbox(tmp_path / "wd")
    (wd / "mine.yaml").write_text(MINE)
    r = run_snakemake(wd, "-n", "experiments", configfiles=("mine.yaml",))
    assert r.returncode == 0, r.stderr
    assert "results/figures/my_map.png" in r.stdout and "integrity_map_" not in r.stdout
    assert "cost estimate (the requested targets (my_map))" in r.stderr
    (wd / "dup.yaml").write_text(MINE + "numerics: {tiles: 1}\nnumerics: {tiles: 2}\n")
    r = run_snakemake(wd, "-n", "results/figures/fig13.png", configfiles=("dup.yaml",))
    assert r.returncode != 0
    assert "dup.yaml, line 12: key numerics is given twice (first on line 11)" in r.stdout + r.stderr
