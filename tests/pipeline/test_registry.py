"""The registry: a toy kind defined through the registry alone (tests/pipeline/toy_kind.py)
resolves, appears in the DAG and in the catalog of figures, and runs end to end."""
from __future__ import annotations

import copy

import numpy as np
import pytest
import xarray as xr

from safebasins.pipeline.config import REPO_ROOT, load_yaml
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import KINDS, Kind, register
from safebasins.plotting.notebooks import build_notebook
from tests.pipeline.sandbox import ROOT, make_sandbox, run_snakemake, snakemake_env

TOY = {"extensions": ["tests.pipeline.toy_kind"],
       "experiments": {"toybox": {"kind": "toy_energy", "xi_max": 0.2, "title": "Toy: unforced safe set"}}}


def toy_config():
    cfg = load_yaml(REPO_ROOT / "config" / "config.yaml")
    cfg.update(copy.deepcopy(TOY))
    return cfg


def test_toy_kind_resolves_and_joins_the_catalog():
    run = plan(toy_config())
    exp = run.experiments["toybox"]
    assert exp.kind is KINDS["toy_energy"] and exp.key == "experiments.toybox"
    assert exp.params == {"experiment": "toybox", "kind": "toy_energy", "title": "Toy: unforced safe set",
                          "well": {"name": "quartic"}, "xi_max": 0.2,
                          "grid": {"q0": [-1.0, 1.0], "p0": [-0.75, 0.75], "n": [41, 41]}}
    assert run.datasets("analytic")[-1] == "results/data/analytic/toy_toybox.nc"
    fig = run.figures()[-1]
    assert fig.name == "toybox" and fig.category == "Experiments" and not fig.packaged
    assert fig.inputs == {"analytic": "results/data/analytic/toy_toybox.nc"}
    src = "".join(c["source"] for c in build_notebook(fig).cells)
    assert "from tests.pipeline.toy_kind import figure_unforced_basin" in src


def test_kind_names_are_unique():
    from safebasins.pipeline.config import load_kinds

    load_kinds()                     # the package's kinds registered (this test may run first)
    before = dict(KINDS)

    class Clash(Kind):
        name = "chart"

    with pytest.raises(ValueError, match="registered twice"):
        register(Clash)
    assert KINDS == before


@pytest.mark.pipeline
def test_toy_kind_in_the_dag_and_end_to_end(tmp_path):
    wd = make_sandbox(tmp_path / "wd")
    over = tmp_path / "toy.yaml"
    import yaml

    over.write_text(yaml.safe_dump(TOY))
    env = snakemake_env(PYTHONPATH=str(ROOT))
    dry = run_snakemake(wd, "-n", "experiments", configfiles=("config/quick.yaml", over), env=env)
    assert dry.returncode == 0, dry.stderr[-3000:]
    out = dry.stdout + dry.stderr
    assert "results/data/analytic/toy_toybox.nc" in out and "results/figures/toybox.png" in out
    # the toy's own chain only (the `experiments` target also holds the quick config's integrity map)
    r = run_snakemake(wd, "-j2", "results/figures/toybox.png", configfiles=("config/quick.yaml", over), env=env)
    assert r.returncode == 0, r.stderr[-3000:]
    ds = xr.load_dataset(wd / "results/data/analytic/toy_toybox.nc")
    assert ds.attrs["experiment"] == "toybox" and ds.attrs["title"] == "Toy: unforced safe set"
    assert ds["safe"].dtype == bool and 0 < ds["safe"].mean() < 1
    np.testing.assert_allclose(ds["H0"].sel(q0=0.0, p0=0.0), 0.0)
    assert (wd / "results/figures/toybox.png").stat().st_size > 10_000
