"""Fast workflow checks (no job runs): dry run, bad config stops before any job, lint."""
import re

import subprocess

from tests.pipeline.sandbox import BIN, run_snakemake, snakemake_env


def test_dry_run_quick_and_full(sandbox):
    tiles = sandbox / "tiles.yaml"
    tiles.write_text("numerics:\n  tiles: 2\n")
    for cfg in (("config/quick.yaml",), (), ("config/quick.yaml", tiles)):
        r = run_snakemake(sandbox, "-n", "all", "archive", configfiles=cfg)
        assert r.returncode == 0, r.stderr[-3000:]
        out = r.stdout + r.stderr
        for rule in ("parameters", "analytic_dataset", "numeric_dataset", "extras_dataset",
                     "fig01", "extra_fourier", "archive"):
            assert re.search(rf"^{rule}\s+\d+", out, re.M), rule
        # numerics.tiles = 0 (the default): the datasets integrate their chart tasks, no tile jobs
        assert bool(re.search(r"^chart_tile\s+\d+", out, re.M)) == (tiles in cfg), cfg
    assert not (sandbox / "results").exists()


def test_bad_config_stops_before_any_job(sandbox):
    bad = sandbox / "bad.yaml"
    bad.write_text("figures:\n  fig13:\n    xi_max: [0.1, 0.3]\n")
    r = run_snakemake(sandbox, "-n", configfiles=("config/quick.yaml", bad))
    assert r.returncode != 0
    assert ("config key figures.fig13.xi_max[1]: 0.3 must be at most the barrier energy 0.25 of the quartic well"
            in r.stderr + r.stdout)
    bad.write_text("figures:\n  fig23:\n    F: 0.1\n")
    r = run_snakemake(sandbox, "-j1", configfiles=("config/quick.yaml", bad))
    assert r.returncode != 0 and "unknown figure name 'fig23'" in r.stderr + r.stdout
    assert not (sandbox / "results").exists()


def test_lint(sandbox):
    """`snakemake --lint`: no findings except the conda/container one (the environment is the
    hashed environment.lock venv, not conda)."""
    r = run_snakemake(sandbox, "--lint", configfiles=())
    text = r.stdout + r.stderr
    findings = []
    where = None
    for line in text.splitlines():
        m = re.match(r"Lints for (rule \S+|snakefile \S+) \(?(.*?)\)?:?$", line)
        if m:
            where = line
            continue
        m = re.match(r"\s+\* (.+?):?$", line)
        if m and where:
            findings.append((where, m.group(1)))
    other = [(w, f) for w, f in findings if not f.startswith("Specify a conda environment or container")]
    assert not other, other


def test_config_found_beside_the_snakefile_from_another_directory(sandbox, tmp_path):
    """`snakemake -s path/Snakefile` from elsewhere still loads config/config.yaml (the paper run)."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    r = subprocess.run([str(BIN / "snakemake"), "-n", "-s", str(sandbox / "Snakefile"), "-d", str(sandbox), "datasets"],
                       capture_output=True, text=True, cwd=elsewhere, env=snakemake_env(), timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "cost estimate" in r.stderr and "numeric_dataset" in r.stdout + r.stderr


def test_cost_guard_stops_before_any_job(sandbox):
    big = sandbox / "big.yaml"
    big.write_text("figures:\n  fig13:\n    grid: {n: 100000}\n    cycles: 10000000\n")
    r = run_snakemake(sandbox, "-n", configfiles=("config/quick.yaml", big))
    assert r.returncode != 0 and "config key numerics.budget_core_hours" in r.stderr + r.stdout
    assert not (sandbox / "results").exists()
