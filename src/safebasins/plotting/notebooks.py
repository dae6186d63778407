"""The papermill notebook of a figure, built from its :class:`~safebasins.pipeline.registry.FigureSpec`.

Every notebook is: a title cell, a ``parameters`` cell (dataset paths relative to the
repository root, output paths, style options; Snakemake overrides the paths with papermill), a
summary cell (:func:`safebasins.plotting.data.describe`) and one call of the figure's builder,
which also writes the report caption with the numbers read from the datasets
(:func:`safebasins.plotting.captions.write_caption`, ``results/captions/<name>.rst``); the saved
PNG carries the datasets' provenance in its text chunks (:func:`safebasins.plotting.style.save_figure`);
the figure of an experiment declared in a config is headed by its ``title:``.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

if TYPE_CHECKING:
    from collections.abc import Mapping


class NotebookFigure(Protocol):
    """What a figure's notebook is built from: the fields of
    :class:`safebasins.pipeline.registry.FigureSpec` (a layer above: not imported here)."""

    @property
    def name(self) -> str: ...
    @property
    def stem(self) -> str: ...
    @property
    def builder(self) -> str: ...
    @property
    def inputs(self) -> Mapping[str, object]: ...
    @property
    def options(self) -> Mapping[str, object]: ...
    @property
    def caption(self) -> str: ...
    @property
    def look(self) -> str: ...
    @property
    def label(self) -> str: ...
    @property
    def category(self) -> str: ...
    @property
    def packaged(self) -> bool: ...
    @property
    def png(self) -> str: ...
    @property
    def pdf(self) -> str: ...
    @property
    def notebook(self) -> str: ...


KERNELSPEC = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
CAPTION_DIR = "results/captions"


def caption_path(fig: NotebookFigure) -> str:
    """The report caption the figure's notebook writes (the report shows it)."""
    return f"{CAPTION_DIR}/{fig.name}.rst"


def _literal(v: object) -> str:
    """Python literal for a notebook parameter."""
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_literal(x) for x in v) + "]"
    return repr(v)


def build_notebook(fig: NotebookFigure) -> nbformat.NotebookNode:
    module, function = fig.builder.split(":")
    heading = (f"# {fig.label} (`{fig.stem}`)\n\n"
               f"**Caption.** {fig.caption}\n\n"
               f"**What to look for.** {fig.look}\n\n"
               "Generated from the registry (`safebasins.pipeline`) by `scripts/make_notebooks.py`; edit the "
               f"catalog or the plotting code, not this file. Run through Snakemake: `snakemake {fig.png}`.")
    lines = ["# Parameters (papermill overrides these; paths are relative to the repository root)"]
    lines += [f"{name} = {_literal(path)}" for name, path in fig.inputs.items()]
    lines += [f"png = {_literal(fig.png)}", f"pdf = {_literal(fig.pdf)}", f"caption = {_literal(caption_path(fig))}",
              "dpi = 180",
              "title = None  # None: built from the datasets' parameters"]
    lines += [f"{k} = {_literal(v)}" for k, v in fig.options.items()]
    params = new_code_cell("\n".join(lines))
    params.metadata["tags"] = ["parameters"]
    inputs = ", ".join(f"{k}={k}" for k in fig.inputs)
    # an experiment of the user's config (not in the catalog: not packaged): its title on the figure too
    heading_arg = "" if fig.packaged else f", heading={fig.label!r}"
    opts = "".join(f", {k}={k}" for k in fig.options)
    setup = new_code_cell("from safebasins.plotting.captions import notes, write_caption\n"
                          "from safebasins.plotting.data import describe\n"
                          "from safebasins.plotting.style import apply_style, save_figure\n"
                          f"from {module} import {function}\n\n"
                          f"apply_style()\ndescribe({inputs});")
    draw = new_code_cell(f"fig = {function}({inputs}{opts}, title=title)\n"
                         f"save_figure(fig, png, pdf, dpi=dpi, datasets=[{', '.join(fig.inputs)}]{heading_arg})\n"
                         f"write_caption(caption, fig, label={fig.label!r}, "
                         f"{'paper' if fig.category == 'Figures' else 'shows'}={fig.caption!r},\n"
                         f"              look={fig.look!r},\n"
                         f"              notebook={fig.notebook!r}, datasets=[{', '.join(fig.inputs)}])\n"
                         "print('\\n'.join(notes(fig)))")
    nb = new_notebook(cells=[new_markdown_cell(heading), params, setup, draw])
    nb.metadata["kernelspec"] = dict(KERNELSPEC)
    nb.metadata["language_info"] = {"name": "python"}
    for i, c in enumerate(nb.cells):  # deterministic cell ids (no churn when regenerating)
        c["id"] = f"{fig.stem.replace('_', '-')}-cell{i}"
    return nb


def notebook_text(fig: NotebookFigure) -> str:
    return nbformat.writes(build_notebook(fig)) + "\n"


def write_notebook(fig: NotebookFigure, path: str | os.PathLike[str]) -> None:
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(notebook_text(fig))
