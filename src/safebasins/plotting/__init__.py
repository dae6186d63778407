"""Figures: one module per figure family, each builder reading datasets by exact names.

style      rcParams, labels, number formatting, saving
data       reading datasets (exact names), summaries for the notebooks
fcr        F_cr(Omega): Figs 1-4, 10-12
basins     slow-flow safe basins on the manifold and the IC plane: Figs 5-9 (+ shared pieces)
charts     escape charts: Figs 13-17, 19, 20-22
maps       the period map: Fig 18
extras     beyond the paper: erosion, phase-invariant basin, first harmonic
notebooks  the papermill notebook of a figure (scripts/make_notebooks.py, rule figure_notebook)
"""
