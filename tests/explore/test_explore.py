"""`safebasins explore` in a real browser: the command serves the page, a dragged slider redraws
the basin, the numeric run reports its IoU (headless Debian Chromium via playwright)."""
from __future__ import annotations

import io
import socket
import subprocess
import sys
import time

import numpy as np
import pytest
from PIL import Image

from safebasins.explore.server import free_port
from tests.docs.browser import chromium_page, require_chromium, screenshot_dir

pytestmark = pytest.mark.browser

READY = ("() => window.Bokeh && Bokeh.documents.length > 0 && "
         "Bokeh.documents[0].get_model_by_name('boundary_source') !== null")
MODEL = "Bokeh.documents[0].get_model_by_name"


@pytest.fixture(scope="module")
def explorer_url():
    """The command line's server on a free port (stopped afterwards)."""
    require_chromium()
    port = free_port("127.0.0.1")
    proc = subprocess.Popen([sys.executable, "-m", "safebasins.cli", "explore", "--port", str(port), "--no-browser"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        deadline = time.monotonic() + 60
        while True:
            if proc.poll() is not None:
                pytest.fail(f"safebasins explore exited with {proc.returncode}:\n{proc.stdout.read()}")
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", port)) == 0:
                    break
            if time.monotonic() > deadline:
                pytest.fail("safebasins explore did not listen within 60 s")
            time.sleep(0.2)
        yield f"http://127.0.0.1:{port}/"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _boundary(page):
    return page.evaluate(f"() => {MODEL}('boundary_source').data.xs.map(a => Array.from(a))")


def _pixels(locator):
    return np.asarray(Image.open(io.BytesIO(locator.screenshot())).convert("RGB"), dtype=int)


def test_slider_redraws_and_numerics_report_iou(explorer_url, tmp_path):
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path) as (page, errors):
        page.goto(explorer_url)
        page.wait_for_function(READY, timeout=60_000)
        page.wait_for_timeout(500)
        ic_plane = page.locator(".bk-Figure").first
        page.screenshot(path=str(shots / "explore_start.png"))
        before_xs, before_px = _boundary(page), _pixels(ic_plane)
        F0 = page.evaluate(f"() => {MODEL}('F').value")

        # drag the F slider's handle with the mouse, as a user would
        group = page.locator(".bk-input-group", has=page.locator(".bk-slider-title", has_text="Forcing amplitude F"))
        handle = group.locator(".noUi-handle")
        box = handle.bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down()
        for k in range(1, 11):
            page.mouse.move(x + 6 * k, y)
            page.wait_for_timeout(40)
        page.mouse.up()
        page.wait_for_function(f"() => {MODEL}('F').value > {F0}")
        page.wait_for_function(f"() => {MODEL}('status').text.includes('redrawn')")
        page.wait_for_function(f"(old) => JSON.stringify({MODEL}('boundary_source').data.xs.map(a => Array.from(a))) "
                               "!== old", arg=__import__("json").dumps(before_xs))
        page.wait_for_timeout(300)
        after_px = _pixels(ic_plane)
        changed = np.any(after_px != before_px, axis=-1).mean()
        assert changed > 0.01, f"only {changed:.2%} of the IC-plane pixels changed"
        redraw_ms = float(page.evaluate(f"() => {MODEL}('status').text").split("redrawn in ")[1].split(" ms")[0])
        assert redraw_ms < 1000
        page.screenshot(path=str(shots / "explore_after_slider.png"))

        # keyboard: the xi_max handle steps with the arrow keys
        xi0 = page.evaluate(f"() => {MODEL}('xi_max').value")
        group = page.locator(".bk-input-group", has=page.locator(".bk-slider-title", has_text="Escape threshold"))
        group.locator(".noUi-handle").focus()
        for _ in range(20):
            page.keyboard.press("ArrowLeft")
        page.wait_for_function(f"() => {MODEL}('xi_max').value < {xi0}")

        # the numeric run: progress, then the IoU
        page.get_by_role("button", name="Run numerics").click()
        page.wait_for_function(f"() => {MODEL}('iou').text.includes('IoU =')", timeout=120_000)
        text = page.evaluate(f"() => {MODEL}('iou').text")
        iou = float(text.split("IoU = ")[1][:5])
        assert 0.3 < iou <= 1.0, text
        assert page.evaluate(f"() => {MODEL}('numeric_basin').visible")
        page.wait_for_timeout(300)
        page.screenshot(path=str(shots / "explore_numerics.png"))
        assert errors == []


def test_damping_slider_changes_the_picture(explorer_url, tmp_path):
    """beta > 0 (issue 17): the damped slow flow's basin (its mask outlined), titles and key say so."""
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path) as (page, errors):
        page.goto(explorer_url)
        page.wait_for_function(READY, timeout=60_000)
        page.wait_for_timeout(500)
        ic_plane = page.locator(".bk-Figure").first
        before_xs, before_px = _boundary(page), _pixels(ic_plane)
        group = page.locator(".bk-input-group", has=page.locator(".bk-slider-title", has_text="Damping beta"))
        group.locator(".noUi-handle").focus()
        for _ in range(20):                                # 20 steps of 0.0005: beta = 0.01
            page.keyboard.press("ArrowRight")
        page.wait_for_function(f"() => {MODEL}('damping').value > 0.009")
        page.wait_for_function(f"() => {MODEL}('status').text.includes('damped slow flow redrawn')", timeout=60_000)
        page.wait_for_function(f"() => {MODEL}('key').text.includes('beta = 0.01:')", timeout=60_000)
        assert "beta = 0.01" in page.evaluate(f"() => {MODEL}('ic_plane').title.text")
        assert _boundary(page) != before_xs
        page.wait_for_timeout(300)
        changed = np.any(_pixels(ic_plane) != before_px, axis=-1).mean()
        assert changed > 0.01, f"only {changed:.2%} of the IC-plane pixels changed"
        page.screenshot(path=str(shots / "explore_damped.png"))
        assert errors == []
