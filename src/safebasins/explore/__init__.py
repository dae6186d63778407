"""``safebasins explore``: an interactive explorer of safe basins in the browser (a Bokeh server).

The page shows, for one well and one forcing (Omega, F, Psi) and threshold xi_max, the
slow-flow safe basin on the plane of initial conditions with its analytic boundaries (eqs 21,
27-28) and the resonance manifold with the level curves of the first integral C (eq 18); both
redraw while the sliders move.  A button integrates the escape chart on the same grid and shows
the intersection over union of the analytic and numeric basins.  Every number on the page comes
from a library call; this package only lays the page out.

ranges    the wells offered (named, or V(q) typed in) and, per well, slider ranges, defaults and windows
analytic  the slow-flow pictures (theory calls)
numeric   the escape chart in blocks with progress, and its agreement with the slow flow
state     one view (a well and a point of the sliders): checks, and the URL query of a page
figures   the Bokeh figures and their data sources
controls  the widgets
app       the document: controls wired to redraws (coalesced) and the background numeric run
snapshot  the static picture of a view: standalone HTML, and a PNG of it by a headless Chromium
server    the Bokeh server (free port, browser) and the static pictures at /snapshot
"""
from safebasins.explore.server import make_server, serve

__all__ = ["make_server", "serve"]
