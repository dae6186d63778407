"""The explorer's widgets: the well (a named well, or V(q) typed in), Omega, F, Psi, xi_max, damping
beta; the numeric run's grid, horizon, button, progress bar; the IoU, status and static-picture
lines.  Every widget has a name (its Bokeh model name)."""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # bokeh.models re-exports its widgets through a computed __all__, which mypy cannot read
    from bokeh.models.widgets.buttons import Button
    from bokeh.models.widgets.indicators import Progress
    from bokeh.models.widgets.inputs import Select, TextInput
    from bokeh.models.widgets.markups import Div
    from bokeh.models.widgets.sliders import Slider
else:
    from bokeh.models import Button, Div, Progress, Select, Slider, TextInput

from safebasins.explore.analytic import Forcing
from safebasins.explore.numeric import CYCLES, GRID_SIZES
from safebasins.explore.ranges import EXPRESSION, Slider as Range, WellRanges, well_names

__all__ = ["Controls", "make_controls", "set_ranges", "forcing", "well_options", "WIDTH"]

#: width of the column of controls (px)
WIDTH = 300
#: slider titles and number formats (numbro)
SLIDERS = {"Omega": ("Forcing frequency Omega", "0.000"), "F": ("Forcing amplitude F", "0.0000"),
           "Psi": ("Forcing phase Psi", "0.000"), "xi_max": ("Escape threshold xi_max", "0.0000"),
           "damping": ("Damping beta (0: undamped)", "0.0000")}
ERROR_STYLE: dict[str, str | None] = {"color": "#b00020"}


@dataclass
class Controls:
    """The widgets."""

    well: Select
    expression: TextInput
    well_error: Div
    well_info: Div
    sliders: dict[str, Slider]
    grid: Select
    cycles: Select
    run: Button
    progress: Progress
    iou: Div
    status: Div
    snapshot: Div

    def widgets(self) -> list[Select | TextInput | Div | Slider | Button | Progress]:
        """Every widget, top to bottom."""
        return [self.well, self.expression, self.well_error, self.well_info, *self.sliders.values(), self.grid,
                self.cycles, self.run, self.progress, self.iou, self.status, self.snapshot]


def well_options(r: WellRanges) -> list[tuple[str, str]]:
    """``(value, label)`` of the well menu: the named wells, a V(q) typed in, and the well ``r``
    when it is a polynomial (given on the command line)."""
    options = [(name, name) for name in well_names()] + [(EXPRESSION, "V(q) typed below")]
    if r.name not in dict(options):
        options.append((r.name, r.label))
    return options


def _options(values: Iterable[str | tuple[str, str]]) -> list[str | tuple[Any, str]]:
    """The options of a menu: values, or (value, label) pairs."""
    return list(values)


def _slider(name: str, s: Range, value: float) -> Slider:
    title, fmt = SLIDERS[name]
    return Slider(name=name, title=title, start=min(s.start, value), end=max(s.end, value), step=s.step, value=value,
                  format=fmt, width=WIDTH)


def make_controls(r: WellRanges, f: Forcing) -> Controls:
    """Widgets for the well ``r`` (its ranges, widened to hold the point ``f``) at the point ``f``."""
    return Controls(
        well=Select(name="well", title="Potential well", value=r.name, options=_options(well_options(r)), width=WIDTH),
        expression=TextInput(name="expression", title="or your own well: V(q) =  (Enter applies)",
                             value=r.spec.get("expression", ""), placeholder="e.g. 1 - cos(q)  or  q**2/2 - q**3/3",
                             width=WIDTH),
        well_error=Div(name="well_error", text="", width=WIDTH, styles=ERROR_STYLE, visible=False),
        well_info=Div(name="well_info", text=r.description(), width=WIDTH),
        sliders={name: _slider(name, getattr(r, name), getattr(f, name)) for name in SLIDERS},
        grid=Select(name="grid", title="Numerics: grid points per axis", value=str(GRID_SIZES[1]),
                    options=_options(str(n) for n in GRID_SIZES), width=WIDTH),
        cycles=Select(name="cycles", title="Numerics: forcing cycles", value=str(CYCLES[1]),
                      options=_options(str(n) for n in CYCLES), width=WIDTH),
        run=Button(name="run", label="Run numerics", button_type="primary", width=WIDTH),
        progress=Progress(name="progress", min=0, max=1, value=0, visible=False, width=WIDTH),
        iou=Div(name="iou", text="", width=WIDTH),
        status=Div(name="status", text="", width=WIDTH),
        snapshot=Div(name="snapshot", text="", width=WIDTH),
    )


def set_ranges(c: Controls, r: WellRanges) -> None:
    """Description, slider ranges and defaults of a new well (the menu stays: it holds every well
    the page can show)."""
    c.well_info.text = r.description()
    for name, slider in c.sliders.items():
        s = getattr(r, name)
        slider.update(start=s.start, end=s.end, step=s.step, value=s.value)


def forcing(c: Controls) -> Forcing:
    """The sliders' current point."""
    v = {name: slider.value for name, slider in c.sliders.items()}
    return Forcing(F=v["F"], Omega=v["Omega"], Psi=v["Psi"], xi_max=v["xi_max"], damping=v["damping"])
