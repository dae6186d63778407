"""Figure notebooks: generated from the registry, current, and each calls an existing builder
with arguments it accepts (static checks; the quick pipeline test executes them all)."""
from __future__ import annotations

import importlib
import inspect
import re
import subprocess
import sys

import nbformat
import pytest

from safebasins.pipeline.plan import plan
from safebasins.plotting.notebooks import caption_path
from tests.pipeline.sandbox import ROOT

FIGURES = [f for f in plan(ROOT / "config" / "config.yaml").figures() if f.packaged]


def test_every_package_figure_has_notebook_writing_its_caption():
    assert len([f for f in FIGURES if f.category == "Figures"]) == 22
    for fig in FIGURES:
        assert (ROOT / fig.notebook).exists()
        code = "\n".join(c.source for c in nbformat.read(ROOT / fig.notebook, as_version=4).cells
                         if c.cell_type == "code")
        assert f"caption = {caption_path(fig)!r}" in code and "write_caption(caption, fig," in code


def test_generated_files_are_up_to_date():
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "make_notebooks.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, "run scripts/make_notebooks.py:\n" + r.stdout


@pytest.mark.parametrize("fig", FIGURES, ids=[f.name for f in FIGURES])
def test_notebook_calls_its_builder(fig):
    nb = nbformat.read(ROOT / fig.notebook, as_version=4)
    nbformat.validate(nb)
    assert nb.metadata["kernelspec"]["name"] == "python3"
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert "parameters" in code[0].metadata.get("tags", [])
    params = {}
    exec(code[0].source, {}, params)  # plain literals only
    assert {k: params[k] for k in fig.inputs} == dict(fig.inputs)
    assert (params["png"], params["pdf"], params["caption"]) == (fig.png, fig.pdf, caption_path(fig))
    text = "\n".join(c.source for c in code)
    assert not re.search(r"['\"]/(work|home|tmp|root)/", text), "hard-coded absolute path"
    assert "def " not in text and all(not c.get("outputs") for c in code)
    # the builder exists and accepts the notebook's arguments
    module, function = fig.builder.split(":")
    builder = getattr(importlib.import_module(module), function)
    assert f"from {module} import {function}" in text
    inspect.signature(builder).bind(**{k: params[k] for k in (*fig.inputs, *fig.options)}, title=None)
