"""Shared plotting for the paper's figures (see :mod:`safebasins.plotting.core`).

The figure table (datasets, options, captions) is :mod:`safebasins.plotting.catalog`;
notebooks are generated from it by ``scripts/make_notebooks.py``.
"""
from .core import (  # noqa: F401
    DEFAULT_DPI,
    LABELS,
    MECHANISMS,
    apply_style,
    curve_labels,
    describe,
    draw_boundaries,
    draw_dsb_esb,
    draw_fcr,
    draw_fcr_curve,
    draw_fcr_numeric,
    draw_ic_basin,
    draw_nested_safe,
    draw_rm_portrait,
    draw_well,
    figure_area_vs_time,
    figure_criteria,
    figure_dsb_esb,
    figure_fcr,
    figure_fcr_comparison,
    figure_nested_basins,
    figure_period_map,
    figure_rm_basin,
    fmt_value,
    open_dataset,
    param_text,
    safe_area_curve,
    safe_from_cycles,
    save_figure,
    style,
)
