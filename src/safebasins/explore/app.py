"""The explorer's document: widgets wired to redraws and to the numeric run.

Redraws are coalesced: a slider change schedules one redraw ``REDRAW_DELAY_MS`` later unless
one is already pending, and that redraw reads the sliders' values when it runs, so a dragged
slider redraws continuously at the rate the computation allows.  The numeric run integrates in
a background thread, reports its blocks to the progress bar through the document's next-tick
callbacks, and is abandoned (its result discarded) when a parameter changes meanwhile.
Errors of the library (a ValueError naming the argument) are shown in the status line, those of
a well typed in under the well menu.

The page starts at the state of the command line (``safebasins explore --well ... --F ...``),
which the page's URL query overrides (``/?well=pendulum&F=0.05``, :mod:`safebasins.explore.state`);
its static-picture link (``/snapshot?...``) follows the sliders.  The layout follows the window:
a fixed column of controls beside figures that stretch to the remaining width.
"""
from __future__ import annotations

import logging
import threading
import time
from collections.abc import Mapping
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
from bokeh.layouts import column, row
from numpy.typing import NDArray

from safebasins.explore import analytic, numeric
from safebasins.explore.controls import WIDTH, forcing, make_controls, set_ranges
from safebasins.explore.figures import Figures, key
from safebasins.explore.ranges import EXPRESSION, well_names, well_ranges
from safebasins.explore.state import to_query, view

if TYPE_CHECKING:
    from bokeh.document import Document
    from bokeh.models.widgets.markups import Div
    from bokeh.server.callbacks import TimeoutCallback

    from safebasins.explore.analytic import Forcing
    from safebasins.explore.ranges import WellRanges
else:  # bokeh.models re-exports Div through a computed __all__, which mypy cannot read
    from bokeh.models import Div

__all__ = ["Explorer", "make_document", "REDRAW_DELAY_MS", "HEADER"]

log = logging.getLogger(__name__)

#: delay of a scheduled redraw (ms)
REDRAW_DELAY_MS = 40

HEADER = ("<b>safebasins explorer</b>: q'' + beta q' + V'(q) = F sin(Omega t + Psi). Left: initial conditions "
          "(q0, p0) that the slow flow keeps below xi_max (eq 21; with damping beta > 0: whose damped slow "
          "trajectory settles below xi_max, docs/damping.md). Right: the slow flow on the resonance manifold "
          "(gamma, xi).")


def error_text(exc: Exception) -> str:
    """A library error for the page: a ValueError's message names the argument; anything else
    also names its type."""
    return str(exc) if isinstance(exc, ValueError) else f"{type(exc).__name__}: {exc}"


def _query_arguments(doc: Document) -> dict[str, Any]:
    """The page request's query arguments (none outside a server session); Bokeh's own
    (``bokeh-...``) left out."""
    context = getattr(doc, "session_context", None)
    request = getattr(context, "request", None)
    arguments = getattr(request, "arguments", None) or {}
    return {k: v for k, v in arguments.items() if not k.startswith("bokeh-")}


class Explorer:
    """One browser session: its controls, figures and numeric run, starting at the well ``well``
    (any form of :func:`safebasins.explore.ranges.well_ranges`) and the point ``values``
    (parameter -> value; missing: the well's defaults), both overridden by the page's query."""

    def __init__(self, doc: Document, well: object = "quartic", values: Mapping[str, Any] | None = None) -> None:
        self.doc = doc
        problem = None
        try:
            self.ranges, f = view(well, values, _query_arguments(doc))
        except Exception as exc:  # noqa: BLE001 - a bad query: the command line's state, the error shown
            problem = f"URL query ignored: {error_text(exc)}"
            self.ranges, f = view(well, values)
        #: wells of the menu that are neither named nor typed in (a polynomial of the command line)
        self.other_wells = ({} if self.ranges.name in (EXPRESSION, *well_names())
                            else {self.ranges.name: self.ranges.spec})
        self.controls = make_controls(self.ranges, f)
        self.figures = Figures(self.ranges, *analytic.pictures(self.ranges, f), f.xi_max, f.damping)
        self.key = Div(name="key", text=key(f.damping), sizing_mode="stretch_width")
        self.version = 0          # bumped by every parameter change: a numeric run checks it
        self.pending: TimeoutCallback | None = None       # the scheduled redraw
        self.running = False
        self.setting_well = False  # the menu is being set to match a well typed in
        c = self.controls
        c.well.on_change("value", self.on_well)
        c.expression.on_change("value", self.on_expression)
        for slider in c.sliders.values():
            slider.on_change("value", self.on_parameter)
        c.grid.on_change("value", self.on_parameter)
        c.cycles.on_change("value", self.on_parameter)
        c.run.on_click(self.on_run)
        self.link(f)
        if problem:
            self.status(problem)
        doc.title = "safebasins explorer"
        figures = column(row(self.figures.ic, self.figures.rm, sizing_mode="stretch_width"), self.key,
                         sizing_mode="stretch_width")
        doc.add_root(column(Div(text=HEADER, sizing_mode="stretch_width"),
                            row(column(*c.widgets(), width=WIDTH + 10), figures, sizing_mode="stretch_width"),
                            sizing_mode="stretch_width", name="layout"))

    # ------------------------------------------------------------------ wells
    def on_well(self, attr: str, old: str, new: str) -> None:
        if self.setting_well:
            return
        if new == EXPRESSION:
            text = self.controls.expression.value.strip()
            if not text:
                self.well_error("type V(q) in the box below and press Enter")
                return
            self.set_well({"expression": text})
        else:
            self.set_well(self.other_wells.get(new, new))

    def on_expression(self, attr: str, old: str, new: str) -> None:
        if new.strip() and self.set_well({"expression": new.strip()}):
            self.setting_well = True
            try:
                self.controls.well.value = EXPRESSION
            finally:
                self.setting_well = False

    def set_well(self, well: object) -> bool:
        """Show the well ``well`` at its defaults; False (the error shown under the well menu, the
        page unchanged) when it does not resolve."""
        try:
            r = well_ranges(well)
        except Exception as exc:  # noqa: BLE001 - a user's formula: shown on the page, which stays usable
            self.well_error(error_text(exc))
            return False
        self.well_error("")
        self.ranges = r
        self.figures.set_windows(r)
        set_ranges(self.controls, r)
        self.changed()
        return True

    def well_error(self, text: str) -> None:
        """The error of a well under the well menu (hidden when there is none)."""
        self.controls.well_error.update(text=text, visible=bool(text))

    # ------------------------------------------------------------------ analytic pictures
    def on_parameter(self, attr: str, old: Any, new: Any) -> None:
        self.changed()

    def changed(self) -> None:
        """A parameter changed: invalidate a numeric result and schedule one redraw."""
        self.version += 1
        self.controls.iou.text = ""
        if self.pending is None:
            self.pending = self.doc.add_timeout_callback(self.redraw, REDRAW_DELAY_MS)

    def redraw(self) -> None:
        self.pending = None
        r, f = self.ranges, forcing(self.controls)
        t0 = time.perf_counter()
        try:
            ic, rm = analytic.pictures(r, f)
        except Exception as exc:  # noqa: BLE001
            self.status(error_text(exc))
            return
        self.figures.show(r, f.xi_max, ic, rm, f.damping)
        self.key.text = key(f.damping)
        self.link(f)
        self.status(f"{'damped ' if f.damping > 0 else ''}slow flow redrawn in "
                    f"{1e3 * (time.perf_counter() - t0):.0f} ms")

    def link(self, f: Forcing) -> None:
        """The links to this view: its static picture and the live page at this state."""
        query = to_query(self.ranges, f)
        self.controls.snapshot.text = (f'<a href="snapshot?{query}" target="_blank">Static picture of this view</a>'
                                       f' &middot; <a href="?{query}">link to this view</a>')

    def status(self, text: str) -> None:
        self.controls.status.text = text

    # ------------------------------------------------------------------ numerics
    def on_run(self) -> None:
        if self.running:
            return
        c, r, f = self.controls, self.ranges, forcing(self.controls)
        n, cycles, token = int(c.grid.value), int(c.cycles.value), self.version
        self.running = True
        c.run.disabled = True
        c.iou.text = ""
        c.progress.update(value=0, max=1, visible=True)
        self.status(f"integrating {n} x {n} initial conditions for {cycles} forcing cycles")
        threading.Thread(target=self.integrate, args=(r, f, n, cycles, token), daemon=True).start()

    def integrate(self, r: WellRanges, f: Forcing, n: int, cycles: int, token: int) -> None:
        """The numeric run (background thread): every document change goes through a next-tick callback."""
        t0 = time.perf_counter()
        try:
            safe = numeric.numeric_safe(r, f, n, cycles, progress=self.progress_later,
                                        stop=lambda: self.version != token)
            value = None if safe is None else numeric.agreement(analytic.ic_safe(r, f, n), safe)
        except Exception as exc:
            log.exception("numeric run failed")
            self.doc.add_next_tick_callback(partial(self.finished, None, None, error_text(exc)))
            return
        text = None if safe is None else (f"{n} x {n} ICs, {cycles} cycles, {time.perf_counter() - t0:.1f} s")
        self.doc.add_next_tick_callback(partial(self.finished, (r, safe, n, cycles, token), value, text))

    def progress_later(self, done: int, total: int) -> None:
        self.doc.add_next_tick_callback(partial(self.controls.progress.update, value=done, max=total))

    def finished(self, result: tuple[WellRanges, NDArray[np.bool_] | None, int, int, int] | None,
                 value: float | None, text: str | None) -> None:
        c = self.controls
        self.running = False
        c.run.disabled = False
        c.progress.visible = False
        if result is None:
            self.status(text or "numeric run abandoned: the parameters changed")
            return
        r, safe, n, cycles, token = result
        if token != self.version or safe is None:   # (a chart is abandoned, None, only for a newer version)
            self.status("numeric run abandoned: the parameters changed")
            return
        self.figures.show_numeric(r, safe)
        c.iou.text = (f"<b>IoU = {value:.3f}</b> (slow-flow vs numeric safe basin, "
                      f"{n} x {n} ICs, {cycles} cycles)")
        self.status(f"numerics: {text}")


def make_document(doc: Document, well: object = "quartic", values: Mapping[str, Any] | None = None) -> None:
    """Bokeh application handler: one :class:`Explorer` per browser session (at the well and point
    of the command line: bind them with ``functools.partial``)."""
    Explorer(doc, well, values)
