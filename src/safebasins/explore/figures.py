"""The explorer's two Bokeh figures and their data sources.

* ``ic_plane``: the plane of initial conditions (q0, p0): the slow-flow safe basin (light blue
  image ``analytic_basin``), the numeric safe basin once integrated (grey image
  ``numeric_basin``), the analytic boundaries (red lines, source ``boundary_source``) and the
  unforced orbit H0 = xi_max (dashed);
* ``manifold``: the resonance manifold (gamma, xi): the safe region (light blue), level curves of
  C (grey), the limiting phase trajectory C = 0 through the well bottom (black) and the
  threshold xi = xi_max (red dashed).

With damping (beta > 0) the analytic pictures are the damped slow flow's (``explore.analytic``):
the red lines on the IC plane outline its safe mask, the manifold shows no level curves (C is not
conserved), and the titles and the key say so.

Models carry names (``Bokeh.documents[0].get_model_by_name(...)`` in the browser, and the tests).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, cast

import numpy as np
from bokeh.models import ColumnDataSource, LinearColorMapper, Range1d
from bokeh.plotting import figure
from bokeh.plotting.contour import contour_data
from numpy.typing import ArrayLike, NDArray

from safebasins.explore.ranges import WellRanges

if TYPE_CHECKING:  # bokeh.models re-exports Span through a computed __all__, which mypy cannot read
    from bokeh.models.annotations.geometry import Span
    from bokeh.models.annotations.labels import Title
else:
    from bokeh.models import Span

__all__ = ["Figures", "key", "titles"]

SAFE_COLOR = "#9ecae1"
NUMERIC_COLOR = "#404040"
BOUNDARY_COLOR = "#d62728"
LEVEL_COLOR = "#8c8c8c"
TOOLS = "pan,wheel_zoom,box_zoom,reset,save"
#: height of both figures (px); their width follows the window (``stretch_width``), at least MIN_WIDTH
HEIGHT = 440
MIN_WIDTH = 300


def _swatch(color: str | None, alpha: float = 1.0, dashed: bool = False) -> str:
    if dashed:
        return '<span style="display:inline-block;width:18px;border-top:2px dashed black;vertical-align:middle"></span>'
    return (f'<span style="display:inline-block;width:14px;height:10px;background:{color};opacity:{alpha};'
            'vertical-align:middle"></span>')


def key(damping: float = 0.0) -> str:
    """HTML key of the colours of both figures (``damping`` > 0: those of the damped slow flow)."""
    items: list[tuple[str | None, str]]
    if damping > 0:
        items = [(_swatch(SAFE_COLOR), f"damped slow-flow safe (beta = {damping:g}: the slow trajectory settles "
                                       "below xi_max)"),
                 (_swatch(NUMERIC_COLOR, 0.55), "numeric safe, damped equation (after a run)"),
                 (_swatch(BOUNDARY_COLOR), "outline of the damped slow-flow safe mask, xi = xi_max"),
                 (_swatch(None, dashed=True), "unforced orbit H0 = xi_max"),
                 (None, "no level curves of C: with damping C is not conserved")]
    else:
        items = [(_swatch(SAFE_COLOR), "slow-flow safe"), (_swatch(NUMERIC_COLOR, 0.55), "numeric safe (after a run)"),
                 (_swatch(BOUNDARY_COLOR), "analytic boundary (eqs 27-28), xi = xi_max"),
                 (_swatch(None, dashed=True), "unforced orbit H0 = xi_max"),
                 (_swatch(LEVEL_COLOR), "level curves of C"), (_swatch("black"), "C = 0 through the well bottom")]
    return " &nbsp; ".join(f"{sw or ''}&nbsp;{label}" for sw, label in items)


def titles(damping: float = 0.0) -> tuple[str, str]:
    """Titles of the IC-plane and manifold figures."""
    if damping > 0:
        return (f"Damped slow-flow safe basin (beta = {damping:g})",
                f"Damped slow flow (beta = {damping:g}): C not conserved")
    return "Initial conditions: slow-flow safe basin", "Resonance manifold: level curves of C (eq 18)"


def _mask_image(mask: ArrayLike, x_window: tuple[float, float], y_window: tuple[float, float]
                ) -> dict[str, list[Any]]:
    """Image data of a boolean mask (rows = y): 1 where True, NaN (transparent) elsewhere."""
    img = np.where(np.asarray(mask, dtype=bool), 1.0, np.nan)
    return {"image": [img], "x": [x_window[0]], "y": [y_window[0]],
            "dw": [x_window[1] - x_window[0]], "dh": [y_window[1] - y_window[0]]}


def _mapper(color: str) -> LinearColorMapper:
    return LinearColorMapper(palette=[color], low=0.0, high=2.0, nan_color=(0, 0, 0, 0))


class Figures:
    """Both figures, built for one well's windows and a first pair of pictures (of threshold
    ``xi_max`` and ``damping``); their width follows the window."""

    def __init__(self, r: WellRanges, ic: dict[str, Any], rm: dict[str, Any], xi_max: float,
                 damping: float = 0.0) -> None:
        size: dict[str, Any] = {"sizing_mode": "stretch_width", "height": HEIGHT, "min_width": MIN_WIDTH}
        ic_title, rm_title = titles(damping)
        self.ic = figure(name="ic_plane", title=ic_title, x_axis_label="q0", y_axis_label="p0", tools=TOOLS, **size,
                         x_range=Range1d(start=r.q_window[0], end=r.q_window[1]),
                         y_range=Range1d(start=r.p_window[0], end=r.p_window[1]))
        self.analytic_source = ColumnDataSource(name="analytic_source",
                                                data=_mask_image(ic["safe"].T, r.q_window, r.p_window))
        # (image() takes color_mapper and global_alpha, which bokeh's stub of it does not declare)
        self.ic.image(source=self.analytic_source, color_mapper=_mapper(SAFE_COLOR),  # type: ignore[call-arg]
                      name="analytic_basin")
        self.numeric_source = ColumnDataSource(name="numeric_source",
                                               data=_mask_image(np.zeros((2, 2), bool), r.q_window, r.p_window))
        self.numeric = self.ic.image(source=self.numeric_source,  # type: ignore[call-arg]
                                     color_mapper=_mapper(NUMERIC_COLOR), global_alpha=0.55, name="numeric_basin",
                                     visible=False)
        xs, ys, _ = ic["boundaries"]
        self.boundary_source = ColumnDataSource(name="boundary_source", data={"xs": xs, "ys": ys})
        self.ic.multi_line(xs="xs", ys="ys", source=self.boundary_source, line_color=BOUNDARY_COLOR, line_width=2,
                           name="boundaries")
        q, p = ic["orbit"]
        self.orbit_source = ColumnDataSource(name="orbit_source", data={"q": q, "p": p})
        self.ic.line(x="q", y="p", source=self.orbit_source, line_color="black", line_dash="dashed", name="orbit")

        self.rm = figure(name="manifold", title=rm_title, x_axis_label="gamma", y_axis_label="xi", tools=TOOLS, **size,
                         x_range=Range1d(start=-np.pi, end=np.pi), y_range=Range1d(start=0.0, end=r.xi_top))
        self.rm_source = ColumnDataSource(name="manifold_source", data=self._rm_image(rm))
        self.rm.image(source=self.rm_source, color_mapper=_mapper(SAFE_COLOR),  # type: ignore[call-arg]
                      name="manifold_safe")
        levels = rm["levels"] if len(rm["levels"]) else [0.0]     # (damped: none; a placeholder, hidden)
        self.levels = self.rm.contour(rm["gamma"], rm["xi"], rm["C"], levels, line_color=LEVEL_COLOR,
                                      line_width=1, fill_color=None)
        self.lpt = self.rm.contour(rm["gamma"], rm["xi"], rm["C"], [0.0], line_color="black", line_width=2,
                                   fill_color=None)
        self.levels.name, self.lpt.name = "levels", "lpt"
        self.levels.visible = self.lpt.visible = not damping > 0
        self.threshold = Span(location=xi_max, dimension="width", line_color=BOUNDARY_COLOR, line_dash="dashed",
                              line_width=2, name="threshold")
        self.rm.add_layout(self.threshold)

    @staticmethod
    def _rm_image(rm: dict[str, Any]) -> dict[str, list[Any]]:
        g, x = rm["gamma"], rm["xi"]
        return _mask_image(~rm["escapes"], (g[0], g[-1]), (x[0], x[-1]))

    def set_windows(self, r: WellRanges) -> None:
        """Axes of a new well."""
        self.ic.x_range.update(start=r.q_window[0], end=r.q_window[1])
        self.ic.y_range.update(start=r.p_window[0], end=r.p_window[1])
        self.rm.y_range.update(start=0.0, end=r.xi_top)

    def show(self, r: WellRanges, xi_max: float, ic: dict[str, Any], rm: dict[str, Any],
             damping: float = 0.0) -> None:
        """Redraw both pictures (the numeric basin is hidden: it belongs to other parameters)."""
        # (figure() made each title a Title model)
        cast("Title", self.ic.title).text, cast("Title", self.rm.title).text = titles(damping)
        self.numeric.visible = False
        self.analytic_source.data = _mask_image(ic["safe"].T, r.q_window, r.p_window)
        xs, ys, _ = ic["boundaries"]
        self.boundary_source.data = {"xs": xs, "ys": ys}
        q, p = ic["orbit"]
        self.orbit_source.data = {"q": q, "p": p}
        self.rm_source.data = self._rm_image(rm)
        self.levels.visible = self.lpt.visible = not damping > 0   # C is not conserved with damping
        if not damping > 0:
            self.levels.set_data(contour_data(rm["gamma"], rm["xi"], rm["C"], rm["levels"], want_fill=False))
            self.lpt.set_data(contour_data(rm["gamma"], rm["xi"], rm["C"], [0.0], want_fill=False))
        self.threshold.location = xi_max

    def show_numeric(self, r: WellRanges, safe: NDArray[np.bool_]) -> None:
        """Show a numeric safe mask (q0, p0) over the analytic basin."""
        self.numeric_source.data = _mask_image(safe.T, r.q_window, r.p_window)
        self.numeric.visible = True
