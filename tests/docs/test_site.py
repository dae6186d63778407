"""The built documentation site (make docs) in headless Debian Chromium: the index, the API
reference and an executed tutorial render with their headings and images, without console
errors; every page's images load; the equations are typeset by the bundled MathJax, offline.  Screenshots go to
$SB_SCREENSHOTS or the test's tmp dir.

The site must be built first (`make docs`); without it the tests skip, unless SB_REQUIRE_DOCS=1
(.ci/run runs them after `make docs` that way).  Without Debian's chromium they skip, except in CI.
"""
from __future__ import annotations

import functools
import os
import re
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from tests.docs.browser import chromium_page, require_chromium, screenshot_dir

pytestmark = [pytest.mark.browser, pytest.mark.docs]

SITE = Path(__file__).resolve().parents[2] / "docs" / "_build" / "html"
#: page -> headings it must show (h1 first)
PAGES = {
    "index.html": ["safebasins", "In ten lines", "Where to go"],
    "api/theory.html": ["safebasins.theory", "safebasins.theory.critical", "safebasins.theory.basins"],
    "api/numerics.html": ["safebasins.numerics", "safebasins.numerics.charts"],
    "tutorials/getting-started.html": ["Getting started"],
}
#: API entries that must be documented (anchor ids of autodoc)
API = {"api/theory.html": ["safebasins.theory.critical.critical_forcing",
                           "safebasins.theory.slow_flow.slow_flow_escapes",
                           "safebasins.theory.basins.safe_basin_boundaries"],
       "api/numerics.html": ["safebasins.numerics.charts.escape_chart"],
       "api/wells.html": ["safebasins.wells.resolve_well"],
       "api/analysis.html": ["safebasins.analysis.agreement.iou"]}
#: the hosts the site may load from: none (MathJax is bundled into _static/mathjax by
#: sphinx-mathjax-offline); any other request is answered with an empty script and recorded
EXTERNAL_HOSTS: set[str] = set()
IMAGES_LOADED = "() => [...document.images].filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src)"


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def site_url():
    """docs/_build/html on a local HTTP server."""
    if not (SITE / "index.html").exists():
        message = f"the documentation site is not built ({SITE}): run `make docs` first"
        if os.environ.get("SB_REQUIRE_DOCS") == "1":
            pytest.fail(message)
        pytest.skip(message)
    require_chromium()
    server = ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(SITE)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


def offline(page):
    """Answer every request that leaves localhost with an empty script; the hosts asked for."""
    hosts = set()

    def fulfil(route):
        hosts.add(re.match(r"^https?://([^/:]+)", route.request.url).group(1))
        route.fulfill(status=200, content_type="application/javascript", body="")

    page.route(re.compile(r"^https?://(?!127\.0\.0\.1[:/])"), fulfil)
    return hosts


def _headings(page):
    return [t.replace("¶", "").replace("#", "").strip()
            for t in page.locator("article h1, article h2, article h3").all_inner_texts()]


def test_index_api_and_tutorial_render(site_url, tmp_path):
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path, width=1300, height=1000) as (page, errors):
        hosts = offline(page)
        for path, expected in PAGES.items():
            page.goto(site_url + path)
            page.wait_for_load_state("load")
            headings = _headings(page)
            assert headings and expected[0] in headings[0], (path, headings)
            for text in expected[1:]:
                assert any(text in h for h in headings), (path, text, headings)
            assert page.evaluate(IMAGES_LOADED) == [], path
            page.screenshot(path=str(shots / (path.replace("/", "_").replace(".html", ".png"))), full_page=True)
        assert errors == []
        assert hosts <= EXTERNAL_HOSTS, hosts


def test_api_reference_documents_the_library(site_url, tmp_path):
    with chromium_page(tmp_path) as (page, errors):
        offline(page)
        for path, ids in API.items():
            page.goto(site_url + path)
            for anchor in ids:
                entry = page.locator(f"dt[id='{anchor}']")
                assert entry.count() == 1, (path, anchor)
                assert entry.is_visible()
        # the docstrings keep the paper's equation numbers
        page.goto(site_url + "api/theory.html")
        assert "eqs 22-26" in page.locator("dl[class*='function']", has=page.locator(
            "dt[id='safebasins.theory.critical.critical_forcing']")).inner_text()
        assert errors == []


def test_tutorial_shows_executed_figures(site_url, tmp_path):
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path, width=1300, height=1000) as (page, errors):
        offline(page)
        for name in ("getting-started", "own-well", "own-experiment"):
            page.goto(site_url + f"tutorials/{name}.html")
            outputs = page.locator(".cell_output img")
            assert outputs.count() >= 1, f"{name}: no executed figure"
            sizes = page.evaluate("() => [...document.querySelectorAll('.cell_output img')].map(i => i.naturalWidth)")
            assert all(w > 100 for w in sizes), (name, sizes)
            assert page.locator(".cell_output .output.traceback, .cell_output .output.error").count() == 0, name
            outputs.first.scroll_into_view_if_needed()
            page.screenshot(path=str(shots / f"tutorial_{name}.png"), full_page=True)
        assert errors == []


def test_every_page_loads_its_images(site_url, tmp_path):
    pages = sorted(p.relative_to(SITE).as_posix() for p in SITE.rglob("*.html")
                   if not p.relative_to(SITE).as_posix().startswith(("_", "genindex", "search", "py-modindex")))
    assert len(pages) >= 20
    with chromium_page(tmp_path) as (page, errors):
        hosts = offline(page)
        for path in pages:
            page.goto(site_url + path)
            page.wait_for_load_state("load")
            assert page.evaluate(IMAGES_LOADED) == [], path
        assert errors == [], errors
        assert hosts <= EXTERNAL_HOSTS, hosts


def test_equations_typeset_offline(site_url, tmp_path):
    """Every display and inline equation of the damping derivation is typeset (MathJax's CHTML
    output, mjx-container) from the site's own files, with every other host unreachable."""
    shots = screenshot_dir(tmp_path)
    with chromium_page(tmp_path, width=1300, height=1000) as (page, errors):
        hosts = offline(page)
        page.goto(site_url + "damping.html")
        page.wait_for_load_state("load")
        n_math = page.locator("article .math").count()
        assert n_math >= 10
        page.wait_for_function(f"() => document.querySelectorAll('article mjx-container').length >= {n_math}",
                               timeout=30_000)
        # typeset, not raw TeX: no TeX control sequence left in the visible text
        assert "\\frac" not in page.locator("article").inner_text()
        page.screenshot(path=str(shots / "damping_equations.png"), full_page=False)
        assert errors == [] and hosts == set(), (errors, hosts)
