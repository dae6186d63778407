"""Figure notebooks and rules: static checks (fast) and one figure end to end on the quick
configuration (marked `pipeline`)."""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
import numpy as np
import pytest

from safebasins.plotting.catalog import (
    EXTRA_FIGURES,
    FIGURES,
    executed_notebook_path,
    extra_figure_paths,
    extra_notebook_path,
    figure_paths,
    notebook_path,
)

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def test_catalog_covers_all_22_figures():
    assert list(FIGURES) == [f"{i:02d}" for i in range(1, 23)]
    assert len({f["slug"] for f in FIGURES.values()}) == 22
    for nn, f in FIGURES.items():
        assert all(not os.path.isabs(p) for p in f["inputs"].values())
        assert (ROOT / "workflow" / "report" / f"fig{nn}.rst").exists()


def test_generated_files_are_up_to_date():
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "make_notebooks.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, "run scripts/make_notebooks.py:\n" + r.stdout


@pytest.mark.parametrize("nn", list(FIGURES))
def test_notebook_structure(nn):
    nb = nbformat.read(ROOT / notebook_path(nn), as_version=4)
    nbformat.validate(nb)
    assert nb.metadata["kernelspec"]["name"] == "python3"
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert "parameters" in code[0].metadata.get("tags", [])
    params = {}
    exec(code[0].source, {}, params)  # plain literals only
    assert set(FIGURES[nn]["inputs"]) <= set(params)
    assert (params["png"], params["pdf"]) == figure_paths(nn)
    text = "\n".join(c.source for c in code)
    assert not re.search(r"['\"]/(work|home|tmp|root)/", text), "hard-coded absolute path"
    # the drawing lives in safebasins.plotting: the notebook only calls into it
    assert "import safebasins.plotting" in text and "def " not in text
    assert all(not c.get("outputs") for c in code)


@pytest.mark.parametrize("name", list(EXTRA_FIGURES))
def test_extra_notebook_structure(name):
    nb = nbformat.read(ROOT / extra_notebook_path(name), as_version=4)
    nbformat.validate(nb)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert "parameters" in code[0].metadata.get("tags", [])
    params = {}
    exec(code[0].source, {}, params)
    assert set(EXTRA_FIGURES[name]["inputs"]) <= set(params)
    assert (params["png"], params["pdf"]) == extra_figure_paths(name)
    text = "\n".join(c.source for c in code)
    assert "import safebasins.plotting_extras" in text and "def " not in text
    assert (ROOT / "workflow" / "report" / f"extra_{name}.rst").exists()


def test_extra_rules_declare_notebook_report_and_log():
    smk = (ROOT / "workflow" / "rules" / "extras.smk").read_text()
    for word in ("papermill", "-k python3", 'category="Beyond the paper"', "log:", "EXTRA_TARGETS", "rule extras",
                 "src/safebasins/plotting_extras.py", "tile_files("):
        assert word in smk


def test_rules_declare_notebook_plotting_and_datasets():
    smk = (ROOT / "workflow" / "rules" / "figures.smk").read_text()
    for word in ("papermill", "-k python3", 'category="Figures"', "log:", "FIGURE_TARGETS",
                 "rule figures", "src/safebasins/plotting/core.py"):
        assert word in smk


# ------------------------------------------------------------------ end to end (quick config)
def _sandbox(tmp_path):
    """Repository view in tmp_path (symlinks) so results/ of the checkout stay untouched."""
    for name in ("Snakefile", "config", "workflow", "scripts", "src", "notebooks"):
        (tmp_path / name).symlink_to(ROOT / name)
    return tmp_path


def _snakemake(wd, targets, *options, timeout=900):
    """Targets first: several snakemake options take a variable number of values."""
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    return subprocess.run([str(BIN / "snakemake"), *targets, *options, "-j2", "--directory", str(wd),
                           "-s", str(wd / "Snakefile"), "--configfile", "config/quick.yaml"],
                          capture_output=True, text=True, timeout=timeout, env=env, cwd=wd)


def _check_outputs(wd, nn):
    import matplotlib.image as mpimg

    png, pdf = (wd / p for p in figure_paths(nn))
    assert png.stat().st_size > 20_000 and pdf.stat().st_size > 5_000
    img = mpimg.imread(png)
    assert img.shape[0] > 400 and img.shape[1] > 400
    assert float(np.var(img[..., :3])) > 1e-3, "blank figure"
    nb = json.loads((wd / executed_notebook_path(nn)).read_text())
    errors = [o for c in nb["cells"] for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors
    assert nb["metadata"]["papermill"]["exception"] in (None, False)


@pytest.mark.pipeline
@pytest.mark.skipif(not (ROOT / "config" / "quick.yaml").exists(), reason="needs config/quick.yaml")
def test_fig05_and_fig01_end_to_end(tmp_path):
    wd = _sandbox(tmp_path)
    targets = [figure_paths(nn)[0] for nn in ("05", "01")]
    r = _snakemake(wd, targets)
    assert r.returncode == 0, r.stderr[-4000:]
    for nn in ("05", "01"):
        _check_outputs(wd, nn)
    # changing only the plot code reruns the figure, never the dataset
    r = _snakemake(wd, targets[:1], "-n", "--forcerun", "fig05")
    assert r.returncode == 0, r.stderr[-4000:]
    out = r.stdout + r.stderr
    assert "rule fig05" in out and "analytic_basin" not in out and "parameters" not in out.split("Job stats")[-1]
