"""The minimal fatal shock figure: drawn from a library dataset (both norms, two attractors), its
caption notes read the dataset's numbers, and a dataset lacking a variable is named."""
from __future__ import annotations

import math

import matplotlib
import pytest
import xarray as xr

from safebasins.analysis.fatal_shock import minimal_fatal_shock
from safebasins.plotting.captions import notes
from safebasins.plotting.data import MissingData
from safebasins.plotting.fatal_shock import figure_fatal_shock

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def shock() -> xr.Dataset:
    """The escape equation's two attractors, two phases, both norms (a coarse, quick search)."""
    return minimal_fatal_shock(0.055, 0.85, 0.1, "cubic", phases=[0.0, math.pi], cycles=10, weights=(1.0, 4.0),
                               n_directions=16, n_radii=12, n_lim=21, n_seeds=5, steps_per_cycle=32, threads=1)


def test_figure_and_notes_from_the_data(shock: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = shock.copy(deep=True)
    ds["mfs"][1, 0, 0] = 0.012345          # a value the caption must report, read from the data
    fig = figure_fatal_shock(ds)
    text = "\n".join(notes(fig))
    assert len(fig.axes) == 2 and ds.sizes["attractor"] == 2
    assert "2 stable period-1 attractors" in text
    assert f"response amplitude {ds['response_amplitude'].values[1]:.4f}" in text
    assert "Attractor 1, energy norm: MFS 0.0123 (at φ = 0)" in text
    assert "Attractor 0, weighted norm" in text and "weighted sqrt(1 dq² + 4 dp²)" in text
    assert f"{int(ds.attrs['steps_per_cycle'])} steps per cycle" in text
    # the panel of the MFS over the phase draws every attractor in every norm (and the LIM beside it)
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert sum(t.startswith("attractor ") for t in labels) == 4 and "LIM" in labels[-1]
    plt.close(fig)


def test_escape_fate_counted_from_the_data(shock: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = shock.copy(deep=True)
    ds["escape_cycle"][0, :, 0] = [0.0, 0.5]
    fig = figure_fatal_shock(ds)
    line = [n for n in notes(fig) if n.startswith("Attractor 0, energy norm")][0]
    assert "at once (H0 > ξ_max) at 1 of 2 phases, in flight within 0.5 cycles" in line
    plt.close(fig)
    ds["escape_cycle"][0, :, 0] = [0.25, 0.75]
    fig = figure_fatal_shock(ds)
    line = [n for n in notes(fig) if n.startswith("Attractor 0, energy norm")][0]
    assert line.endswith("escapes in flight, within 0.75 cycles.")
    plt.close(fig)


def test_missing_variable_named(shock: xr.Dataset) -> None:
    with pytest.raises(MissingData, match="lim"):
        figure_fatal_shock(shock.drop_vars("lim"))


def test_lim_bound_counted(shock: xr.Dataset) -> None:
    import matplotlib.pyplot as plt

    ds = shock.copy(deep=True)
    ds["lim"][:] = ds["mfs"].values - 1e-3          # LIM below the MFS: the bound fails at every phase
    fig = figure_fatal_shock(ds)
    assert all("node diagonal at 0 of 2 phases" in n for n in notes(fig) if n.startswith("Attractor"))
    plt.close(fig)
