"""Figures: one module per figure family, each builder reading datasets by exact names.

Public functions for any dataset of the API or the command line (each returns the Figure):
:func:`plot_escape_chart`, :func:`plot_basin`, :func:`plot_fcr`, :func:`plot_integrity_map`;
save with :func:`save_figure` (PNG text chunks carry the datasets' provenance).

api             the public functions above
style           rcParams, labels, number formatting, saving (with provenance)
data            reading datasets (exact names), provenance, summaries for the notebooks
curves          drawing pieces of every basin figure: boundary curves, fills, hatches, the well
fcr             F_cr(Omega): Figs 1-4, 10-12
basins          slow-flow safe basins on the manifold and the IC plane: Figs 5-9
charts          escape charts: Figs 13-17, 19, 20-22
maps            the period map: Fig 18
integrity_maps  integrity over the control plane (Omega, F)
extras          beyond the paper: erosion, phase-invariant basin, first harmonic
captions        report captions with numbers read from the data
notebooks       the papermill notebook of a figure (scripts/make_notebooks.py, rule figure_notebook)
"""
from __future__ import annotations

import importlib
from typing import Any

__all__ = ["plot_escape_chart", "plot_basin", "plot_fcr", "plot_integrity_map", "save_figure", "MissingData"]
_HOME = {"plot_escape_chart": "api", "plot_basin": "api", "plot_fcr": "api", "plot_integrity_map": "api",
         "save_figure": "style", "MissingData": "data"}


def __getattr__(name: str) -> Any:  # exported lazily: `import safebasins.plotting.data` stays light (no pyplot)
    if name in _HOME:
        return getattr(importlib.import_module(f"safebasins.plotting.{_HOME[name]}"), name)
    raise AttributeError(f"module 'safebasins.plotting' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
