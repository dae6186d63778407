"""The figure of the attractors followed across a parameter: drawn from a library dataset (the escape
equation across its hysteresis band: two folds, two attractors, the exit from the well), the branches
drawn as the data's stable and unstable stretches, its caption notes read the dataset's numbers, and a
dataset lacking a variable is named."""
from __future__ import annotations

import matplotlib
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis.continuation import continue_attractors
from safebasins.plotting.captions import notes
from safebasins.plotting.continuation import UNSTABLE_COLOUR, figure_continuation
from safebasins.plotting.data import MissingData

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def branches() -> xr.Dataset:
    """Four F across the escape equation's band (coarse labels, long arclength steps: ~10 s)."""
    return continue_attractors(0.85, [0.04, 0.06, 0.08, 0.1], 0.1, "cubic", n_grid=21, n_iter=20, step_max=0.3,
                               steps_per_cycle=16, threads=1)


def _runs(stable: np.ndarray, curve: np.ndarray) -> tuple[int, int]:
    """(stable, unstable) stretches of the curves, counted point by point."""
    n = [0, 0]
    for c in np.unique(curve):
        s = stable[curve == c]
        starts = np.r_[True, s[1:] != s[:-1]]
        n[0] += int((starts & s).sum())
        n[1] += int((starts & ~s).sum())
    return n[0], n[1]


def test_branches_drawn_from_the_data(branches: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = branches
    kinds = ds["event_kind"].attrs["flag_meanings"].split()
    assert sorted(kinds[k] for k in ds["event_kind"].values) == ["fold", "fold", "left_well", "range_end"]
    fig = figure_continuation(ds)
    axB, axG = fig.axes
    lines = [ln for ln in axB.get_lines() if ln.get_linestyle() in ("-", "--") and len(ln.get_xdata()) > 1]
    solid = [ln for ln in lines if ln.get_linestyle() == "-"]
    dashed = [ln for ln in lines if ln.get_linestyle() == "--"]
    assert (len(solid), len(dashed)) == _runs(ds["stable"].values, ds["curve"].values) == (2, 1)
    assert all(ln.get_color() == UNSTABLE_COLOUR for ln in dashed)
    # every point of the branches is drawn, stable ones solid
    drawn = np.concatenate([ln.get_xdata() for ln in solid])
    assert set(ds["parameter"].values[ds["stable"].values]) <= set(drawn)
    # the folds at their located F and amplitude
    folds = [ln for ln in axB.get_lines() if ln.get_marker() == "o" and ln.get_linestyle() in ("None", "")]
    fold = ds["event_kind"].values == kinds.index("fold")
    np.testing.assert_array_equal(folds[0].get_xdata(), ds["event_parameter"].values[fold])
    np.testing.assert_array_equal(folds[0].get_ydata(), ds["event_amplitude"].values[fold])
    # one GIM curve per attractor and the safe basin's
    np.testing.assert_array_equal(axG.get_lines()[0].get_ydata(), ds["GIM"].values[:, 0])
    assert any(np.array_equal(ln.get_ydata(), ds["GIM_safe"].values) for ln in axG.get_lines())
    plt.close(fig)


def test_notes_read_the_data(branches: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = branches.copy(deep=True)
    ds["cliff_drop"][1] = 0.12345          # a value the caption must report, read from the data
    kinds = ds["event_kind"].attrs["flag_meanings"].split()
    fold = np.sort(ds["event_parameter"].values[ds["event_kind"].values == kinds.index("fold")])
    fig = figure_continuation(ds)
    text = "\n".join(notes(fig))
    assert "F swept from 0.04 to 0.1 (4 values); basins labelled on 21 x 21 ICs" in text
    assert f"folds at F = {fold[0]:.6g}, {fold[1]:.6g}; no branch points; no period doublings" in text
    assert "2 attractors (stable stretches" in text and "1 continued curve" in text
    line = [n for n in notes(fig) if n.startswith("Attractor 1")][0]
    assert f"its Dover cliff: GIM 0.123 lost to escape between F = {float(ds['cliff_low'][1]):.4g}" in line
    assert f"from {fold[0]:.6g} (fold)" in line
    safe = [n for n in notes(fig) if n.startswith("Safe basin")][0]
    g = ds["GIM_safe"].values
    k = int(np.flatnonzero(ds["F"].values == float(ds["safe_cliff_high"]))[0])
    assert f"GIM {float(ds['safe_cliff_drop']):.3f} lost to escape" in safe
    assert f"(GIM {g[k - 1]:.3f} to {g[k]:.3f})" in safe
    plt.close(fig)


def test_unfollowed_unsettled_and_unlocated_are_reported(branches: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = branches.copy(deep=True)
    ds["n_unfollowed"][:] = [0, 0, 1, 0]
    ds["n_unsettled"][:] = [0, 7, 0, 3]
    ds["event_located"][1] = False
    fig = figure_continuation(ds)
    text = "\n".join(notes(fig))
    assert "At 1 of 4 values the grid settles on attractors no branch follows" in text
    assert "1 event(s) not located" in text
    assert "at 2 of 4 values, the most 7 of 441 at F = 0.06." in text
    plt.close(fig)
    ds["n_unfollowed"][:] = 0
    ds["event_located"][:] = True
    ds["n_unsettled"][:] = 0
    text = "\n".join(notes(figure_continuation(ds)))
    assert "no branch follows" not in text and "not located" not in text and "not settled" not in text
    plt.close("all")


def test_missing_variable_named(branches: xr.Dataset) -> None:
    with pytest.raises(MissingData, match="cliff_drop"):
        figure_continuation(branches.drop_vars("cliff_drop"))
