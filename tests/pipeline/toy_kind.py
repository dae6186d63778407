"""A toy experiment kind defined through the registry alone (docs/adding-an-experiment.md).

Its library call (:func:`unforced_basin`) tabulates the unforced energy H0 on a grid of initial
conditions and the unforced safe set of a threshold; its plotting function
(:func:`figure_unforced_basin`) draws them.  Nothing else in the package knows about it: a
config lists this module under ``extensions`` and declares experiments of kind ``toy_energy``
under ``experiments``.
"""
from __future__ import annotations

import numpy as np

from safebasins.pipeline import values
from safebasins.pipeline.registry import Kind, Product, dataset_path, register


def unforced_basin(q0, p0, xi_max, well):
    """The library call: H0(q0, p0) and the unforced safe set {H0 < xi_max inside the well}."""
    import xarray as xr

    Q, P = np.meshgrid(q0, p0, indexing="ij")
    return xr.Dataset({"H0": (("q0", "p0"), well.H0(Q, P)),
                       "safe": (("q0", "p0"), well.unforced_safe(Q, P, xi_max))},
                      coords={"q0": q0, "p0": p0}, attrs={"xi_max": xi_max})


def build(params, inputs, job):
    q0, p0 = values.grid_axes(params["grid"])
    return unforced_basin(q0, p0, params["xi_max"], values.well(params))


def figure_unforced_basin(analytic, *, title=None):
    """The plotting function: the unforced safe set over the H0 level curves."""
    import matplotlib.pyplot as plt

    from safebasins.plotting.basins import draw_well, safe_fill, xy_grid
    from safebasins.plotting.data import open_dataset, param, var, well

    ds = open_dataset(analytic)
    fig, ax = plt.subplots(figsize=(5, 4), layout="constrained")
    q, p, safe = xy_grid(var(ds, "safe"))
    safe_fill(ax, q, p, safe.astype(bool))
    ax.contour(q, p, np.asarray(var(ds, "H0").transpose("p0", "q0")), levels=12, colors="k", linewidths=0.4)
    draw_well(ax, float(param(ds, "xi_max")), well(ds))
    ax.set_title(title or f"unforced safe set, xi_max = {param(ds, 'xi_max')}")
    return fig


@register
class ToyEnergy(Kind):
    name = "toy_energy"
    description = "the unforced energy on an IC grid and the unforced safe set of a threshold"
    builder = "tests.pipeline.toy_kind:figure_unforced_basin"
    schema = {
        "description": description,
        "type": "object", "additionalProperties": False, "required": ["xi_max"],
        "properties": {
            "xi_max": {"$ref": "#/$defs/threshold"},
            "grid": {"$ref": "#/$defs/grid", "default": {"q0": [-1.0, 1.0], "p0": [-0.75, 0.75], "n": 41}},
        },
    }

    def check(self, block, key, ctx):
        ctx.check_grid(f"{key}.grid", block["grid"])

    def resolve(self, block, ctx):
        return dict(xi_max=float(block["xi_max"]), grid=values.grid(block["grid"]))

    def products(self, experiment, params):
        return [Product(dataset_path("analytic", f"toy_{experiment}"), "analytic", build, title=params["title"],
                        history="tests.pipeline.toy_kind.unforced_basin",
                        contract={"H0": ("q0", "p0"), "safe": ("q0", "p0")})]

    def figure_inputs(self, experiment, params):
        return {"analytic": dataset_path("analytic", f"toy_{experiment}")}
