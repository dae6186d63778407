"""The explorer's widgets: well, Omega, F, Psi, xi_max, damping beta; the numeric run's grid, horizon, button,
progress bar; the IoU and status lines.  Every widget has a name (its Bokeh model name)."""
from __future__ import annotations

from dataclasses import dataclass

from bokeh.models import Button, Div, Progress, Select, Slider

from safebasins.explore.analytic import Forcing
from safebasins.explore.numeric import CYCLES, GRID_SIZES
from safebasins.explore.ranges import WellRanges, well_description, well_names

__all__ = ["Controls", "make_controls", "set_ranges", "forcing"]

#: slider titles and number formats (numbro)
SLIDERS = {"Omega": ("Forcing frequency Omega", "0.000"), "F": ("Forcing amplitude F", "0.0000"),
           "Psi": ("Forcing phase Psi", "0.000"), "xi_max": ("Escape threshold xi_max", "0.0000"),
           "damping": ("Damping beta (0: undamped)", "0.0000")}


@dataclass
class Controls:
    """The widgets."""

    well: Select
    well_info: Div
    sliders: dict
    grid: Select
    cycles: Select
    run: Button
    progress: Progress
    iou: Div
    status: Div

    def widgets(self):
        """Every widget, top to bottom."""
        return [self.well, self.well_info, *self.sliders.values(), self.grid, self.cycles, self.run, self.progress,
                self.iou, self.status]


def _slider(name, s):
    title, fmt = SLIDERS[name]
    return Slider(name=name, title=title, start=s.start, end=s.end, step=s.step, value=s.value, format=fmt,
                  width=300)


def make_controls(r: WellRanges) -> Controls:
    """Widgets for the well ``r`` (its ranges and defaults)."""
    return Controls(
        well=Select(name="well", title="Potential well", value=r.name, options=well_names(), width=300),
        well_info=Div(name="well_info", text=well_description(r.name), width=300),
        sliders={name: _slider(name, getattr(r, name)) for name in SLIDERS},
        grid=Select(name="grid", title="Numerics: grid points per axis", value=str(GRID_SIZES[1]),
                    options=[str(n) for n in GRID_SIZES], width=300),
        cycles=Select(name="cycles", title="Numerics: forcing cycles", value=str(CYCLES[1]),
                      options=[str(n) for n in CYCLES], width=300),
        run=Button(name="run", label="Run numerics", button_type="primary", width=300),
        progress=Progress(name="progress", min=0, max=1, value=0, visible=False, width=300),
        iou=Div(name="iou", text="", width=300),
        status=Div(name="status", text="", width=300),
    )


def set_ranges(c: Controls, r: WellRanges):
    """Slider ranges and defaults of a new well."""
    c.well_info.text = well_description(r.name)
    for name, slider in c.sliders.items():
        s = getattr(r, name)
        slider.update(start=s.start, end=s.end, step=s.step, value=s.value)


def forcing(c: Controls) -> Forcing:
    """The sliders' current point."""
    v = {name: slider.value for name, slider in c.sliders.items()}
    return Forcing(F=v["F"], Omega=v["Omega"], Psi=v["Psi"], xi_max=v["xi_max"], damping=v["damping"])
