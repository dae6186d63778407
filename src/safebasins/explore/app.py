"""The explorer's document: widgets wired to redraws and to the numeric run.

Redraws are coalesced: a slider change schedules one redraw ``REDRAW_DELAY_MS`` later unless
one is already pending, and that redraw reads the sliders' values when it runs, so a dragged
slider redraws continuously at the rate the computation allows.  The numeric run integrates in
a background thread, reports its blocks to the progress bar through the document's next-tick
callbacks, and is abandoned (its result discarded) when a parameter changes meanwhile.
Errors of the library (a ValueError naming the argument) are shown in the status line.
"""
from __future__ import annotations

import logging
import threading
import time
from functools import partial

from bokeh.layouts import column, row
from bokeh.models import Div

from safebasins.explore import analytic, numeric
from safebasins.explore.controls import forcing, make_controls, set_ranges
from safebasins.explore.figures import Figures, key
from safebasins.explore.ranges import well_ranges

__all__ = ["Explorer", "make_document", "REDRAW_DELAY_MS", "IC_GRID", "MANIFOLD_GRID"]

log = logging.getLogger(__name__)

#: delay of a scheduled redraw (ms)
REDRAW_DELAY_MS = 40
#: grid of the analytic IC-plane picture, and (gamma, xi) points of the manifold picture
IC_GRID = 161
MANIFOLD_GRID = (241, 161)

HEADER = ("<b>safebasins explorer</b>: q'' + beta q' + V'(q) = F sin(Omega t + Psi). Left: initial conditions "
          "(q0, p0) that the slow flow keeps below xi_max (eq 21; with damping beta > 0: whose damped slow "
          "trajectory settles below xi_max, docs/damping.md). Right: the slow flow on the resonance manifold "
          "(gamma, xi).")


class Explorer:
    """One browser session: its controls, figures and numeric run."""

    def __init__(self, doc, well="quartic"):
        self.doc = doc
        self.ranges = well_ranges(well)
        self.controls = make_controls(self.ranges)
        f = forcing(self.controls)
        self.figures = Figures(self.ranges, analytic.ic_plane(self.ranges, f, IC_GRID),
                               analytic.manifold(self.ranges, f, *MANIFOLD_GRID))
        self.figures.threshold.location = f.xi_max
        self.key = Div(name="key", text=key(), width=1000)
        self.version = 0          # bumped by every parameter change: a numeric run checks it
        self.pending = None       # the scheduled redraw
        self.running = False
        c = self.controls
        c.well.on_change("value", self.on_well)
        for slider in c.sliders.values():
            slider.on_change("value", self.on_parameter)
        c.grid.on_change("value", self.on_parameter)
        c.cycles.on_change("value", self.on_parameter)
        c.run.on_click(self.on_run)
        doc.title = "safebasins explorer"
        doc.add_root(column(Div(text=HEADER, width=1340),
                            row(column(*c.widgets()), column(row(self.figures.ic, self.figures.rm), self.key)),
                            name="layout"))

    # ------------------------------------------------------------------ analytic pictures
    def on_well(self, attr, old, new):
        try:
            self.ranges = well_ranges(new)
        except Exception as exc:  # noqa: BLE001 - shown to the user, the page stays usable
            self.status(f"{type(exc).__name__}: {exc}")
            return
        self.figures.set_windows(self.ranges)
        set_ranges(self.controls, self.ranges)
        self.changed()

    def on_parameter(self, attr, old, new):
        self.changed()

    def changed(self):
        """A parameter changed: invalidate a numeric result and schedule one redraw."""
        self.version += 1
        self.controls.iou.text = ""
        if self.pending is None:
            self.pending = self.doc.add_timeout_callback(self.redraw, REDRAW_DELAY_MS)

    def redraw(self):
        self.pending = None
        r, f = self.ranges, forcing(self.controls)
        t0 = time.perf_counter()
        try:
            ic = analytic.ic_plane(r, f, IC_GRID)
            rm = analytic.manifold(r, f, *MANIFOLD_GRID)
        except Exception as exc:  # noqa: BLE001
            self.status(f"{type(exc).__name__}: {exc}")
            return
        self.figures.show(r, f.xi_max, ic, rm, f.damping)
        self.key.text = key(f.damping)
        self.status(f"{'damped ' if f.damping > 0 else ''}slow flow redrawn in "
                    f"{1e3 * (time.perf_counter() - t0):.0f} ms")

    def status(self, text):
        self.controls.status.text = text

    # ------------------------------------------------------------------ numerics
    def on_run(self):
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

    def integrate(self, r, f, n, cycles, token):
        """The numeric run (background thread): every document change goes through a next-tick callback."""
        t0 = time.perf_counter()
        try:
            safe = numeric.numeric_safe(r, f, n, cycles, progress=self.progress_later,
                                        stop=lambda: self.version != token)
            value = None if safe is None else numeric.agreement(analytic.ic_safe(r, f, n), safe)
        except Exception as exc:  # noqa: BLE001
            log.exception("numeric run failed")
            self.doc.add_next_tick_callback(partial(self.finished, None, None, f"{type(exc).__name__}: {exc}"))
            return
        text = None if safe is None else (f"{n} x {n} ICs, {cycles} cycles, {time.perf_counter() - t0:.1f} s")
        self.doc.add_next_tick_callback(partial(self.finished, (r, safe, n, cycles, token), value, text))

    def progress_later(self, done, total):
        self.doc.add_next_tick_callback(partial(self.controls.progress.update, value=done, max=total))

    def finished(self, result, value, text):
        c = self.controls
        self.running = False
        c.run.disabled = False
        c.progress.visible = False
        if result is None:
            self.status(text or "numeric run abandoned: the parameters changed")
            return
        r, safe, n, cycles, token = result
        if token != self.version:
            self.status("numeric run abandoned: the parameters changed")
            return
        self.figures.show_numeric(r, safe)
        c.iou.text = (f"<b>IoU = {value:.3f}</b> (slow-flow vs numeric safe basin, "
                      f"{n} x {n} ICs, {cycles} cycles)")
        self.status(f"numerics: {text}")


def make_document(doc):
    """Bokeh application handler: one :class:`Explorer` per browser session."""
    Explorer(doc)
