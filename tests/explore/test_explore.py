"""`safebasins explore` in a real browser: the command serves the page, a dragged slider redraws
the basin, the numeric run reports its IoU, the page fits the window, a well typed in is drawn,
and the static picture of the current view is captured by a plain `chromium --screenshot`
(headless Debian Chromium via playwright)."""
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
from safebasins.explore.snapshot import ink_fraction
from tests.docs.browser import CHROMIUM, FLAGS, chromium_page, require_chromium, screenshot_dir

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
    """beta > 0: the damped slow flow's basin (its mask outlined), titles and key say so."""
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


#: every control and figure of the page, and the figures' toolbars (Bokeh's element classes)
ELEMENTS = (".bk-Toolbar", ".bk-Figure", ".bk-Slider", ".bk-Select", ".bk-TextInput", ".bk-Button", ".bk-Div")


def _outside(page):
    """Boxes of the page's visible elements that leave the viewport, and the document's width."""
    size = page.viewport_size
    out = []
    for selector in ELEMENTS:
        loc = page.locator(selector)
        for k in range(loc.count()):
            box = loc.nth(k).bounding_box()
            if box is None:                                  # hidden (the progress bar, an empty error line)
                continue
            if box["x"] < 0 or box["y"] < 0 or box["x"] + box["width"] > size["width"] + 0.5 \
                    or box["y"] + box["height"] > size["height"] + 0.5:
                out.append((selector, k, box))
    return out, page.evaluate("() => document.documentElement.scrollWidth")


def test_page_fits_the_window(explorer_url, tmp_path):
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path, width=1300, height=800) as (page, errors):
        page.goto(explorer_url)
        page.wait_for_function(READY, timeout=60_000)
        page.wait_for_timeout(500)
        widths = {}
        for width, height in ((1300, 800), (1920, 1080)):
            page.set_viewport_size({"width": width, "height": height})
            page.wait_for_timeout(500)
            page.screenshot(path=str(shots / f"explore_{width}x{height}.png"))
            outside, scroll_width = _outside(page)
            assert outside == [], f"{width}x{height}: outside the window: {outside}"
            assert scroll_width <= width
            assert page.locator(".bk-Toolbar").count() == 2
            widths[width] = page.locator(".bk-Figure").first.bounding_box()["width"]
        assert widths[1920] > widths[1300] + 200              # the figures take the room there is
        assert errors == []


def test_typed_well_is_drawn_and_a_bad_one_is_explained(explorer_url, tmp_path):
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path) as (page, errors):
        page.goto(explorer_url)
        page.wait_for_function(READY, timeout=60_000)
        box = page.get_by_placeholder("e.g. 1 - cos(q)")
        box.fill("q**2/2 - x")
        box.press("Enter")
        page.wait_for_function(f"() => {MODEL}('well_error').visible && {MODEL}('well_error').text.includes('unknown')")
        assert page.get_by_text("unknown name(s) x").is_visible()
        page.screenshot(path=str(shots / "explore_bad_expression.png"))
        box.fill("1 - cos(q)")
        box.press("Enter")
        page.wait_for_function(f"() => {MODEL}('well_info').text.includes('E_b = 2')", timeout=60_000)
        page.wait_for_function(f"() => {MODEL}('status').text.includes('redrawn')", timeout=60_000)
        assert abs(page.evaluate(f"() => {MODEL}('ic_plane').x_range.end") - np.pi) < 1e-12
        q_orbit = page.evaluate(f"() => Array.from({MODEL}('orbit_source').data.q)")
        assert max(q_orbit) > 1.5                            # the pendulum's orbit at xi_max = 1.44: q = 2.0
        assert not page.evaluate(f"() => {MODEL}('well_error').visible")
        assert page.evaluate(f"() => {MODEL}('well').value") == "expression"
        assert abs(page.evaluate(f"() => {MODEL}('xi_max').end") - 0.98 * 2) < 1e-12
        page.wait_for_timeout(300)
        page.screenshot(path=str(shots / "explore_expression_well.png"))
        assert errors == []


def test_static_picture_of_the_current_view(explorer_url, tmp_path):
    """The page's link gives the static picture of the view after a slider moved; a plain
    `chromium --screenshot` of it (no script, no waiting) is a picture, unlike one of the live page."""
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path) as (page, errors):
        page.goto(explorer_url + "?well=pendulum&Omega=0.8")
        page.wait_for_function(READY, timeout=60_000)
        assert page.evaluate(f"() => {MODEL}('Omega').value") == 0.8
        group = page.locator(".bk-input-group", has=page.locator(".bk-slider-title", has_text="Forcing amplitude F"))
        group.locator(".noUi-handle").focus()
        for _ in range(50):
            page.keyboard.press("ArrowRight")
        F = page.evaluate(f"() => {MODEL}('F').value")
        page.wait_for_function(f"(F) => {MODEL}('snapshot').text.includes('F=' + F)", arg=repr(F))
        href = page.get_by_role("link", name="Static picture of this view").get_attribute("href")
        assert errors == []
    url = explorer_url + href
    html = __import__("urllib.request").request.urlopen(url, timeout=60).read().decode()
    assert f"well pendulum; F = {F:.6g}, Omega = 0.8" in html
    picture = shots / "explore_static_view_plain_screenshot.png"
    subprocess.run([str(CHROMIUM), *FLAGS, f"--screenshot={picture}", "--window-size=1300,520", url],
                   check=True, capture_output=True, timeout=120)
    assert ink_fraction(picture) > 0.1
