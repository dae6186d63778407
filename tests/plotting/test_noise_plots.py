"""The noise figures of the pipeline kinds: the escape-probability maps over noise levels and the
stochastic erosion profile, drawn from library datasets, their caption notes reading the data, and a
dataset of the wrong shape or lacking a variable named."""
from __future__ import annotations

import math
from typing import Any

import matplotlib
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis import stochastic_erosion
from safebasins.numerics import escape_probability
from safebasins.plotting.captions import notes
from safebasins.plotting.data import MissingData
from safebasins.plotting.noise import figure_escape_probability_levels
from safebasins.plotting.stochastic_erosion import figure_stochastic_erosion

matplotlib.use("Agg")

Q0, P0 = np.linspace(-0.9, 0.9, 5), np.linspace(-0.7, 0.7, 4)
KW: dict[str, Any] = dict(xi_max=0.18, t_eval=[1, 3], cycles=3, steps_per_cycle=16, threads=1)


@pytest.fixture(scope="module")
def levels() -> xr.Dataset:
    maps = [escape_probability(Q0, P0, 0.01, 0.9, math.pi, noise=s, paths=10, **KW).expand_dims(noise=[s])
            for s in (0.005, 0.02)]
    out = xr.concat(maps, dim="noise", combine_attrs="override", data_vars="all")
    out.attrs.pop("noise")
    return out


@pytest.fixture(scope="module")
def erosion() -> xr.Dataset:
    return stochastic_erosion(Q0, P0, [0.0, 0.01], 0.9, math.pi, noise=[0.0, 0.02], epsilon=[0.3, 0.5], paths=12,
                              **KW)


def test_levels_figure_and_notes(levels: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = levels.copy(deep=True)
    ds["P_escape"][1, :, :, -1] = 0.25            # a mean the caption must report, read from the data
    fig = figure_escape_probability_levels(ds)
    text = "\n".join(notes(fig))
    assert len(fig.axes) == 2 * 2 + 1              # panels and the colour bar
    assert "10 paths from each of 5 x 4 initial conditions" in text
    assert "σ = 0.02, within 3 cycles: mean P_escape 0.250" in text
    mean = float(ds["P_escape"][0, :, :, -1].mean())
    assert f"σ = 0.005, within 3 cycles: mean P_escape {mean:.3f}" in text
    plt.close(fig)
    with pytest.raises(ValueError, match="noise, q0, p0, t_eval"):
        figure_escape_probability_levels(ds.isel(noise=0))


@pytest.fixture(scope="module")
def with_theory(levels: xr.Dataset) -> xr.Dataset:
    from safebasins.analysis.noise_theory import escape_probability_with_theory

    return escape_probability_with_theory(levels, 0.01, 0.9, math.pi, KW["xi_max"], cells=(16, 20))


def test_levels_figure_with_the_theory(with_theory: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = with_theory.copy(deep=True)
    ds["P_escape_mean_abs_difference"].loc[{"noise": 0.02}] = [0.0123, 0.0456]   # numbers the notes must read
    ds["P_escape_theory_within_wilson"].loc[{"noise": 0.005}] = 0.87
    fig = figure_escape_probability_levels(ds)
    text = "\n".join(notes(fig))
    assert "on 16 x 20 cells" in text
    assert "σ = 0.02, theory vs ensembles within 1 / 3 cycles: mean |ΔP| 0.012 / 0.046" in text
    assert "Wilson interval at 87% of (IC, t)" in text
    high = ds["P_escape_max_abs_difference"].sel(noise=0.005).values
    assert f"max {high[0]:.2f} / {high[1]:.2f}" in text
    # the contours: one set per panel where a level lies inside the theory's map, and the legend's two lines
    drawn = sum(len(ax.collections) - 1 for ax in fig.axes[:4])
    inside = sum(int(any(P.min() < v < P.max() for v in (0.05, 0.5)))
                 for P in ds["P_escape_theory"].transpose("noise", "t_eval", "q0", "p0").values.reshape(4, -1))
    assert drawn == inside > 0
    assert len(fig.legends[0].get_lines()) == 2
    plt.close(fig)
    ds.attrs.pop("theory_cells")
    with pytest.raises(MissingData, match="theory_cells"):
        figure_escape_probability_levels(ds)


def test_levels_figure_says_why_there_is_no_theory(levels: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    fig = figure_escape_probability_levels(levels.assign_attrs(theory="none", theory_reason="not computed (theory: "
                                                                                           "false)"))
    assert "No averaged theory: not computed (theory: false)." in notes(fig)
    assert not fig.legends and all(len(ax.collections) == 1 for ax in fig.axes[:4])
    plt.close(fig)


def test_erosion_figure_and_notes(erosion: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = erosion.copy(deep=True)
    ds["GIM"].loc[{"F": 0.01, "noise": 0.02, "epsilon": 0.3, "t_eval": 3.0}] = 0.123
    fig = figure_stochastic_erosion(ds)
    text = "\n".join(notes(fig))
    assert len(fig.axes) == 6
    assert "12 paths per initial condition" in text and "within 3 cycles" in text
    assert "F = 0.01: GIM (ε = 0.3) " in text and "0.123 at σ = 0, 0.02" in text
    # one solid, one dashed and one dotted line per curve value in every panel
    assert all(len(ax.get_lines()) == 2 * 3 for ax in fig.axes)
    plt.close(fig)
    with pytest.raises(MissingData, match="LIM"):
        figure_stochastic_erosion(ds.drop_vars("LIM"))


def test_erosion_figure_with_the_theory(erosion: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = erosion.copy(deep=True)
    for m in ("GIM", "LIM", "IF"):
        ds[m + "_theory"] = ds[m].copy()
    ds["GIM_theory"].loc[{"F": 0.01, "noise": 0.02, "epsilon": 0.3, "t_eval": 3.0}] += 0.2   # read from the data
    fig = figure_stochastic_erosion(ds.assign_attrs(theory_cells=[16, 20]))
    text = "\n".join(notes(fig))
    assert "crosses: the averaged theory's P_escape <= 0.3 (docs/noise-theory.md, 16 x 20 cells)" in text
    assert "differs from the ensembles' by 0.050 on average, at most 0.200" in text
    # a line of crosses per curve value in every panel, after the solid, dashed and dotted ones
    assert all(len(ax.get_lines()) == 2 * 4 for ax in fig.axes)
    assert all(line.get_marker() == "x" for ax in fig.axes for line in ax.get_lines()[3::4])
    plt.close(fig)
    fig = figure_stochastic_erosion(erosion.assign_attrs(theory="none", theory_reason="not computed (theory: false)"))
    assert "No averaged theory: not computed (theory: false)." in notes(fig)
    plt.close(fig)
