"""A static picture of the explorer's state: a standalone HTML page with both figures at one well
and one point of the sliders, and a PNG of it taken by a headless Chromium.

The live page is built by the server after it has loaded (through a websocket), so a browser's
screenshot of it taken at load is blank.  The static page carries its figures' data and BokehJS
inline: it draws as soon as it loads, offline, without a server, so a plain
``chromium --headless --screenshot=out.png --window-size=1300,520 page.html`` captures it.  The
figures are the live page's (:class:`~safebasins.explore.figures.Figures`), their width follows
the window.

``safebasins explore --export page.html`` and ``--snapshot picture.png`` write them from the
command line; the live page links to the static page of its current view (``/snapshot?...``,
:mod:`safebasins.explore.state`).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from bokeh.embed import file_html
from bokeh.layouts import column, row
from bokeh.resources import INLINE
from PIL import Image

from safebasins.explore import analytic
from safebasins.explore.analytic import Forcing
from safebasins.explore.figures import Figures, key
from safebasins.explore.ranges import WellRanges
from safebasins.io.files import atomic_path

if TYPE_CHECKING:
    from bokeh.models import Column
    from bokeh.models.widgets.markups import Div
else:  # bokeh.models re-exports Div through a computed __all__, which mypy cannot read
    from bokeh.models import Div

__all__ = ["static_layout", "static_html", "write_html", "write_png", "find_chromium", "ink_fraction",
           "WINDOW", "CHROMIUM_NAMES"]

#: browser window of a PNG (px): both figures side by side with the header and the key
WINDOW = (1300, 520)
#: executables tried, in this order, for a PNG when no browser is given
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")
#: a picture with less than this fraction of non-white pixels is blank (the explorer's: about 0.2)
MIN_INK = 0.02
#: seconds a browser may take for one PNG
BROWSER_TIMEOUT = 120


def state_text(r: WellRanges, f: Forcing) -> str:
    """The well and the point in one line."""
    return (f"well {r.label}; F = {f.F:.6g}, Omega = {f.Omega:.6g}, Psi = {f.Psi:.6g}, xi_max = {f.xi_max:.6g}, "
            f"damping beta = {f.damping:.6g}")


def static_layout(r: WellRanges, f: Forcing) -> Column:
    """The static page's layout: a header naming the state, both figures, their key."""
    figures = Figures(r, *analytic.pictures(r, f), f.xi_max, f.damping)
    header = Div(name="state", text=f"<b>safebasins explorer</b>: {state_text(r, f)}", sizing_mode="stretch_width")
    return column(header, row(figures.ic, figures.rm, sizing_mode="stretch_width"),
                  Div(name="key", text=key(f.damping), sizing_mode="stretch_width"), sizing_mode="stretch_width")


def static_html(r: WellRanges, f: Forcing) -> str:
    """The static page (standalone HTML, BokehJS inline: about 2 MB)."""
    return file_html(static_layout(r, f), INLINE, title=f"safebasins explorer: {r.label}")


def write_html(path: str | os.PathLike[str], r: WellRanges, f: Forcing) -> Path:
    """Write the static page to ``path`` (atomically)."""
    path = Path(path)
    text = static_html(r, f)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def find_chromium(browser: str | os.PathLike[str] | None = None) -> str:
    """The Chromium (or Chrome) executable: ``browser`` if given, else the first of
    ``CHROMIUM_NAMES`` on PATH; ValueError naming ``browser`` when there is none."""
    if browser is not None:
        found = shutil.which(str(browser))
        if found is None:
            raise ValueError(f"browser: {browser!r} is not an executable")
        return found
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    raise ValueError(f"browser: no Chromium or Chrome found on PATH (tried {', '.join(CHROMIUM_NAMES)}): "
                     "install one, name it with --browser, or write the HTML page (--export) and open it")


def ink_fraction(png: str | os.PathLike[str]) -> float:
    """Fraction of the picture's pixels that are not (near) white."""
    with Image.open(png) as im:
        a = np.asarray(im.convert("L"))
    return float((a < 245).mean())


def write_png(path: str | os.PathLike[str], r: WellRanges, f: Forcing, browser: str | os.PathLike[str] | None = None,
              window: tuple[int, int] = WINDOW) -> Path:
    """Write a PNG of the static page, ``window`` (width, height) px, taken by a headless Chromium
    (:func:`find_chromium`); RuntimeError if the browser fails or returns a blank picture."""
    exe = find_chromium(browser)
    path = Path(path)
    with tempfile.TemporaryDirectory(prefix="safebasins-snapshot-") as tmp:
        page, shot = Path(tmp) / "explorer.html", Path(tmp) / "explorer.png"
        write_html(page, r, f)
        flags = ["--headless", "--disable-gpu", "--hide-scrollbars", "--no-first-run", "--no-default-browser-check",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 f"--user-data-dir={Path(tmp) / 'profile'}", f"--window-size={window[0]},{window[1]}",
                 "--virtual-time-budget=5000", f"--screenshot={shot}"]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            flags.append("--no-sandbox")          # Chromium refuses to run as root with its sandbox
        try:
            done = subprocess.run([exe, *flags, page.as_uri()], capture_output=True, text=True,
                                  timeout=BROWSER_TIMEOUT)
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"{exe} took more than {BROWSER_TIMEOUT} s for the picture") from None
        if done.returncode != 0 or not shot.exists():
            tail = "\n".join(done.stderr.strip().splitlines()[-5:])
            raise RuntimeError(f"{exe} exited with {done.returncode} without a picture:\n{tail}")
        ink = ink_fraction(shot)
        if ink < MIN_INK:
            raise RuntimeError(f"{exe} returned a blank picture ({ink:.1%} of its pixels not white)")
        with atomic_path(path) as out:
            shutil.copyfile(shot, out)
    return path
