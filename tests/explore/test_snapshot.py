"""A static picture of a view: the standalone page draws the library's pictures, the command line
writes it (``--export``) and a PNG of it (``--snapshot``), and a plain ``chromium --screenshot`` of
the page is not blank (headless Debian Chromium)."""
from __future__ import annotations

import subprocess

import numpy as np
import pytest
from click.testing import CliRunner

from safebasins import theory
from safebasins.cli import main
from safebasins.explore import analytic, ranges, snapshot, state
from tests.docs.browser import CHROMIUM, FLAGS, require_chromium, screenshot_dir


def test_static_page_draws_the_library_pictures():
    r = ranges.well_ranges("pendulum")
    f = state.forcing_of(r, {"F": 0.1, "Omega": 0.8})
    layout = snapshot.static_layout(r, f)
    image = layout.select_one({"name": "analytic_source"}).data["image"][0]
    q0, p0 = analytic.ic_grid(r, analytic.IC_GRID)
    safe = ~theory.slow_flow_escapes(q0[:, None], p0[None, :], F=0.1, Omega=0.8, Psi=f.Psi, xi_max=f.xi_max,
                                     well="pendulum")
    np.testing.assert_array_equal(np.isfinite(image), safe.T)
    assert layout.select_one({"name": "threshold"}).location == f.xi_max
    assert "well pendulum; F = 0.1, Omega = 0.8" in layout.select_one({"name": "state"}).text


def test_export_writes_the_static_page(tmp_path):
    out = tmp_path / "view.html"
    result = CliRunner().invoke(main, ["explore", "--well", "expression:q**2/2 - q**3/3", "--F", "0.02",
                                       "--export", str(out)])
    assert result.exit_code == 0, result.output
    html = out.read_text()
    assert "well V = -q**3/3 + q**2/2; F = 0.02" in html
    assert "cdn.bokeh.org" not in html                     # BokehJS inline: the page opens offline


@pytest.mark.parametrize("args, option", [(["--xi-max", "0.25"], "--xi-max"), (["--F", "-1"], "--F"),
                                          (["--well", "{expression: x**2}"], "--well"),
                                          (["--well", "expression:sin(q)"], "--well"),
                                          (["--snapshot", "view.jpg"], "--snapshot"),
                                          (["--export", "view.png"], "--export"),
                                          (["--snapshot", "view.png", "--browser", "/no/such/chromium"], "--browser")])
def test_bad_options_are_usage_errors(tmp_path, args, option):
    result = CliRunner().invoke(main, ["explore", *args], catch_exceptions=False)
    assert result.exit_code == 2 and option in result.output, result.output
    assert "Traceback" not in result.output


def test_browser_is_looked_up_on_path(tmp_path, monkeypatch):
    fake = tmp_path / "chromium-browser"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", str(tmp_path))
    assert snapshot.find_chromium() == str(fake)
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    with pytest.raises(ValueError, match="browser: no Chromium or Chrome found on PATH"):
        snapshot.find_chromium()
    result = CliRunner().invoke(main, ["explore", "--snapshot", str(tmp_path / "view.png")])
    assert result.exit_code == 2 and "--snapshot" in result.output and "--export" in result.output


@pytest.mark.browser
def test_snapshot_and_plain_chromium_screenshot_are_pictures(tmp_path):
    require_chromium()
    shots = screenshot_dir(tmp_path)
    png = shots / "explore_snapshot_morse.png"
    result = CliRunner().invoke(main, ["explore", "--well", "morse", "--F", "0.03", "--snapshot", str(png),
                                       "--browser", str(CHROMIUM), "--export", str(tmp_path / "morse.html")])
    assert result.exit_code == 0, result.output
    assert snapshot.ink_fraction(png) > 0.1

    # the exported page, captured by a plain chromium --screenshot (no waiting, no script)
    plain = shots / "explore_export_plain_screenshot.png"
    subprocess.run([str(CHROMIUM), *FLAGS, f"--screenshot={plain}", "--window-size=1300,520",
                    (tmp_path / "morse.html").as_uri()], check=True, capture_output=True, timeout=120)
    assert snapshot.ink_fraction(plain) > 0.1
