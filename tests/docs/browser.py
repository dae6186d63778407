"""Headless Debian Chromium for the browser tests (tests/docs, tests/explore), driven by
playwright's Python API with the system browser (``executable_path``), a fresh profile each time.

Chromium is installed by ``.ci/run`` (tests/docs/install_chromium.sh).  Without it the browser
tests skip with the reason, except in CI (``SAFEBASINS_CI=1`` or ``CI`` set), where they fail.
"""
from __future__ import annotations

import contextlib
import os
from pathlib import Path

import pytest

CHROMIUM = Path(os.environ.get("SB_CHROMIUM", "/usr/bin/chromium"))
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def in_ci() -> bool:
    """True under CI (``.ci/run`` sets SAFEBASINS_CI=1; most CI services set CI)."""
    return os.environ.get("SAFEBASINS_CI") == "1" or os.environ.get("CI", "").lower() in ("1", "true", "yes")


def require_chromium():
    """Skip (fail in CI) when Debian's chromium is absent."""
    if CHROMIUM.exists():
        return
    message = (f"Debian's chromium is not installed ({CHROMIUM}): run tests/docs/install_chromium.sh as root "
               "(apt-get install chromium); .ci/run installs it")
    if in_ci():
        pytest.fail(message)
    pytest.skip(message)


def screenshot_dir(tmp_path: Path) -> Path:
    """Where screenshots go: $SB_SCREENSHOTS when set (to look at them), else the test's tmp dir."""
    out = Path(os.environ.get("SB_SCREENSHOTS") or tmp_path / "screenshots")
    out.mkdir(parents=True, exist_ok=True)
    return out


@contextlib.contextmanager
def chromium_page(tmp_path: Path, width=1400, height=900):
    """``(page, errors)``: a page of a fresh headless Chromium; ``errors`` collects console errors
    and uncaught page exceptions."""
    require_chromium()
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(
            str(tmp_path / "chromium-profile"), executable_path=str(CHROMIUM), args=FLAGS, headless=True,
            viewport={"width": width, "height": height})
        try:
            page = context.new_page()
            errors = []
            page.on("console", lambda m: errors.append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
            page.on("pageerror", lambda exc: errors.append(f"page error: {exc}"))
            yield page, errors
        finally:
            context.close()
