"""The explorer's document without a browser: pictures from the library, redraws, wells, numerics."""
from __future__ import annotations

import numpy as np
import pytest
from bokeh.document import Document
from click.testing import CliRunner

from safebasins import theory, wells
from safebasins.cli import main
from safebasins.explore import analytic, numeric, ranges
from safebasins.explore.app import Explorer
from safebasins.explore.controls import forcing


@pytest.fixture
def explorer():
    doc = Document()
    e = Explorer(doc)
    # run next-tick callbacks at once (no server loop here)
    doc.add_next_tick_callback = lambda callback: callback()
    return e


def test_wells_are_the_named_wells():
    assert ranges.well_names() == list(wells.NAMED_WELLS)
    assert ranges.well_names()[0] == "quartic"
    with pytest.raises(ValueError, match="well"):
        ranges.well_ranges("no such well")


def test_quartic_defaults_are_fig14():
    r = ranges.well_ranges("quartic")
    assert (r.F.value, r.Omega.value, r.Psi.value, r.xi_max.value) == (0.01, 0.9, np.pi, 0.18)
    assert r.xi_max.end < r.barrier_energy == 0.25


def test_ic_plane_is_the_library_basin():
    r = ranges.well_ranges("quartic")
    f = analytic.Forcing(F=0.01, Omega=0.9, Psi=np.pi, xi_max=0.18)
    pic = analytic.ic_plane(r, f, 41)
    q0, p0 = analytic.ic_grid(r, 41)
    expected = ~theory.slow_flow_escapes(q0[:, None], p0[None, :], F=0.01, Omega=0.9, Psi=np.pi, xi_max=0.18)
    np.testing.assert_array_equal(pic["safe"], expected)
    xs, ys, kinds = pic["boundaries"]
    assert len(xs) == len(ys) == len(kinds) >= 1          # Fig 14: a disjoint basin
    q, p = pic["orbit"]
    np.testing.assert_allclose(wells.QUARTIC.H0(q, p), 0.18, atol=1e-9)


def test_slider_change_redraws(explorer):
    before = [x.copy() for x in explorer.figures.boundary_source.data["xs"]]
    image = explorer.figures.analytic_source.data["image"][0].copy()
    explorer.controls.sliders["F"].value = 0.03
    assert explorer.pending is not None                    # one redraw scheduled
    explorer.controls.sliders["Omega"].value = 0.92
    explorer.redraw()
    after = explorer.figures.boundary_source.data["xs"]
    assert len(after) != len(before) or any(a.shape != b.shape or not np.allclose(a, b, equal_nan=True)
                                            for a, b in zip(after, before))
    assert not np.array_equal(explorer.figures.analytic_source.data["image"][0], image, equal_nan=True)
    assert explorer.figures.threshold.location == explorer.controls.sliders["xi_max"].value
    assert "redrawn" in explorer.controls.status.text


@pytest.mark.parametrize("name", list(wells.NAMED_WELLS))
def test_every_named_well_draws(explorer, name):
    explorer.controls.well.value = name
    r = ranges.well_ranges(name)
    assert explorer.controls.sliders["xi_max"].end == pytest.approx(r.xi_max.end)
    explorer.redraw()
    assert "redrawn" in explorer.controls.status.text, explorer.controls.status.text
    assert np.isfinite(explorer.figures.analytic_source.data["image"][0]).any()   # some safe ICs


def test_library_error_is_shown(explorer):
    explorer.controls.sliders["Omega"].value = -1.0        # a bad value reaches the library
    explorer.redraw()
    assert "Omega" in explorer.controls.status.text


def test_numeric_run_gives_iou(explorer):
    c = explorer.controls
    c.grid.value, c.cycles.value = "41", "100"
    explorer.on_run()
    for _ in range(600):                                   # the run is a thread; its callbacks run at once
        if not explorer.running:
            break
        __import__("time").sleep(0.05)
    assert not explorer.running
    assert "IoU = " in c.iou.text, c.status.text
    value = float(c.iou.text.split("IoU = ")[1][:5])
    assert 0.85 < value <= 1.0                             # Fig 14 parameters: the slow flow is accurate
    assert explorer.figures.numeric.visible


def test_numeric_run_is_abandoned_when_a_slider_moves(explorer):
    r = explorer.ranges
    f = forcing(explorer.controls)
    calls = []
    safe = numeric.numeric_safe(r, f, 41, 100, blocks=4, progress=lambda k, n: calls.append(k),
                                stop=lambda: len(calls) >= 2)
    assert safe is None and calls == [1, 2]


def test_cli_explore_options():
    runner = CliRunner()
    assert "explore" in runner.invoke(main, ["--help"]).output
    result = runner.invoke(main, ["explore", "--port", "70000", "--no-browser"])
    assert result.exit_code == 2 and "--port" in result.output
    result = runner.invoke(main, ["explore", "--host", "no-such-host.invalid", "--no-browser"])
    assert result.exit_code == 2 and "--host" in result.output


def test_damped_pictures_are_the_damped_slow_flow():
    """beta > 0 (issue 17): the IC plane is slow_flow_escapes(damping) on the coarser damped grid,
    outlined; the manifold classifies each point by its damped slow trajectory, with no levels."""
    r = ranges.well_ranges("quartic")
    f = analytic.Forcing(F=0.01, Omega=0.9, Psi=np.pi, xi_max=0.18, damping=0.01)
    pic = analytic.ic_plane(r, f, 161)
    n = analytic.DAMPED_IC_GRID
    q0, p0 = analytic.ic_grid(r, n)
    want = ~theory.slow_flow_escapes(q0[:, None], p0[None, :], F=0.01, Omega=0.9, Psi=np.pi, xi_max=0.18,
                                     damping=0.01)
    np.testing.assert_array_equal(pic["safe"], want)
    assert set(pic["boundaries"][2]) == {"mask_outline"}
    rm = analytic.manifold(r, f, 241, 161)
    assert rm["escapes"].shape == analytic.DAMPED_MANIFOLD_GRID[::-1] and rm["levels"].size == 0
    i = np.argmin(np.abs(rm["xi"] - 0.05))                 # low energies settle, xi >= xi_max escapes
    assert not rm["escapes"][i].all() and rm["escapes"][rm["xi"] >= 0.18].all()


def test_damping_slider_redraws_damped(explorer):
    c = explorer.controls
    assert c.sliders["damping"].value == 0.0
    c.sliders["damping"].value = 0.01
    explorer.redraw()
    assert "damped slow flow redrawn" in c.status.text, c.status.text
    assert "C is not conserved" in explorer.key.text and "beta = 0.01" in explorer.figures.ic.title.text
    assert "C not conserved" in explorer.figures.rm.title.text
    assert not explorer.figures.levels.visible
    c.grid.value, c.cycles.value = "41", "100"
    explorer.on_run()
    for _ in range(600):
        if not explorer.running:
            break
        __import__("time").sleep(0.05)
    value = float(c.iou.text.split("IoU = ")[1][:5])
    assert 0.85 < value <= 1.0, c.iou.text                 # the damped theory against the damped numerics
