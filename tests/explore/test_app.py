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
from safebasins.explore.state import from_query


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


def _doc_with_query(arguments):
    """A document whose (fake) session request carries the query ``arguments``."""
    doc = Document()
    request = type("Request", (), {"arguments": arguments})()
    context = type("Context", (), {"request": request})()
    doc._session_context = lambda: context                 # (Bokeh keeps a weak reference)
    return doc


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
    """beta > 0: the IC plane is slow_flow_escapes(damping) on the coarser damped grid,
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


def test_typed_expression_becomes_the_well(explorer):
    c = explorer.controls
    c.expression.value = "1 - cos(q)"                      # Enter in the text input
    assert c.well.value == "expression" and not c.well_error.visible
    r = ranges.well_ranges({"expression": "1 - cos(q)"})
    assert explorer.ranges.spec == r.spec and explorer.ranges.barrier_energy == 2.0
    for name in ("Omega", "F", "xi_max"):
        s = getattr(r, name)
        assert (c.sliders[name].start, c.sliders[name].end, c.sliders[name].value) == (s.start, s.end, s.value)
    assert "your well V = 1 - cos(q)" in c.well_info.text
    assert explorer.figures.ic.x_range.end == pytest.approx(np.pi)
    explorer.redraw()
    assert "redrawn" in c.status.text, c.status.text
    assert np.isfinite(explorer.figures.analytic_source.data["image"][0]).any()
    assert "expression" in c.snapshot.text and "1+-+cos%28q%29" in c.snapshot.text
    c.well.value = "cubic"                                  # back to a named well, then to the typed one
    assert explorer.ranges.name == "cubic"
    c.well.value = "expression"
    assert explorer.ranges.spec == r.spec


@pytest.mark.parametrize("text, match", [("q**2 +", "cannot read"), ("x**2", "unknown name"),
                                         ("sin(q)", "V'(0)"), ("q**2/2 + q**4", "closed")])
def test_bad_expression_is_shown_on_the_page(explorer, text, match):
    c = explorer.controls
    c.expression.value = text
    assert c.well_error.visible and match in c.well_error.text, c.well_error.text
    assert "Traceback" not in c.well_error.text
    assert explorer.ranges.name == "quartic" and c.well.value == "quartic"   # the page stays as it was
    c.expression.value = "1 - cos(q)"
    assert not c.well_error.visible and explorer.ranges.barrier_energy == 2.0


def test_expression_menu_entry_without_a_formula_asks_for_one(explorer):
    explorer.controls.well.value = "expression"
    assert "type V(q)" in explorer.controls.well_error.text and explorer.ranges.name == "quartic"


def test_page_starts_at_the_command_line_state():
    e = Explorer(Document(), {"expression": "q**2/2 - q**3/3"}, {"F": 0.02, "Psi": 0.5})
    c = e.controls
    assert c.well.value == "expression" and c.expression.value == "q**2/2 - q**3/3"
    assert (c.sliders["F"].value, c.sliders["Psi"].value) == (0.02, 0.5)
    assert c.sliders["Omega"].value == ranges.well_ranges({"expression": "q**2/2 - q**3/3"}).Omega.value
    e = Explorer(Document(), "quartic", {"F": 0.3})          # beyond the slider: the slider widens
    assert c.sliders["F"].end < 0.3 == e.controls.sliders["F"].value == e.controls.sliders["F"].end


def test_polynomial_of_the_command_line_stays_in_the_menu():
    doc = Document()
    e = Explorer(doc, {"polynomial": [0, 0, 0.5, -0.1]})
    doc.add_next_tick_callback = lambda callback: callback()
    c = e.controls
    assert c.well.value == "polynomial" and ("polynomial", e.ranges.label) in c.well.options
    c.well.value = "pendulum"
    assert e.ranges.name == "pendulum"
    c.well.value = "polynomial"
    assert e.ranges.spec == {"name": "polynomial", "coefficients": [0.0, 0.0, 0.5, -0.1]}


def test_page_query_overrides_the_command_line():
    e = Explorer(_doc_with_query({"well": [b"pendulum"], "F": [b"0.125"], "bokeh-session-id": [b"x"]}),
                 "quartic", {"F": 0.02})
    assert e.ranges.name == "pendulum" and e.controls.sliders["F"].value == 0.125
    e = Explorer(_doc_with_query({"F": [b"lots"]}), "quartic", {"F": 0.02})
    assert "URL query ignored: F must be a number" in e.controls.status.text
    assert e.controls.sliders["F"].value == 0.02


def test_link_to_this_view_follows_the_sliders(explorer):
    explorer.controls.sliders["F"].value = 0.0375
    explorer.redraw()
    text = explorer.controls.snapshot.text
    query = text.split('href="snapshot?')[1].split('"')[0]
    well, values = from_query({k: [v] for k, v in (kv.split("=") for kv in query.split("&amp;" if "&amp;" in query
                                                                                       else "&"))})
    assert well == "quartic" and values["F"] == 0.0375 and values["xi_max"] == 0.18


def test_page_can_start_damped():
    doc = Document()
    e = Explorer(doc, "quartic", {"damping": 0.01})
    doc.add_next_tick_callback = lambda callback: callback()
    assert not e.figures.levels.visible and "beta = 0.01" in e.figures.ic.title.text
    assert "C is not conserved" in e.key.text
    e.controls.sliders["damping"].value = 0.0               # undamped again: the level curves come back
    e.redraw()
    assert e.figures.levels.visible and len(e.figures.levels.line_renderer.data_source.data["xs"]) > 1


def test_cli_without_bokeh_names_the_extra(monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "bokeh", None)     # import bokeh -> ImportError
    result = CliRunner().invoke(main, ["explore", "--no-browser"])
    assert result.exit_code == 1 and "pip install 'safebasins[explore]'" in result.output, result.output
