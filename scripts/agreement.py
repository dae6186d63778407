"""Rule `agreement`: IoU and pixel agreement of analytic and numeric safe basins (Figs 13-17).

numeric safe = escape_cycle_energy > cycles; analytic safe = not escapes (slow flow), on the
same (q0, p0) grid. Writes the final chart dataset: the gathered escape chart plus data
variables iou, pixel_agreement, safe_analytic, safe_numeric over the scanned parameter
(xi_max for Figs 13-15, F for Figs 16-17) and summary attributes.
"""
import numpy as np

from safebasins.config import load_params, params_hash, redirect_output
from safebasins.datasets import finalize, load, mask_agreement, write_netcdf

redirect_output(snakemake.log[0])
p = load_params(snakemake.input.params)
chart = load(snakemake.input.chart)
basin = load(snakemake.input.basin)
cycles = p["cycles"]

numeric_safe = chart["escape_cycle_energy"] > cycles
if p["scan"] == "F":
    numeric_safe = numeric_safe.isel(xi_max=0, drop=True)
analytic_safe = ~basin["escapes"].astype(bool).reset_coords(drop=True)  # no saddle_* coords in the chart
numeric_safe = numeric_safe.reset_coords(drop=True)
for ax in ("q0", "p0"):
    a, n = np.asarray(analytic_safe[ax].values), np.asarray(numeric_safe[ax].values)
    if a.shape != n.shape or not np.allclose(a, n, rtol=0, atol=1e-12):
        raise ValueError(f"analytic and numeric grids differ along {ax}")
scan = p["scan"]
a, n = np.asarray(analytic_safe[scan].values, float), np.asarray(numeric_safe[scan].values, float)
if a.shape != n.shape or not np.allclose(a, n, rtol=1e-12, atol=0):
    raise ValueError(f"analytic and numeric {scan} values differ: {a} vs {n}")
analytic_safe = analytic_safe.assign_coords({c: numeric_safe[c] for c in ("q0", "p0", scan)})
analytic_safe = analytic_safe.transpose(*numeric_safe.dims)

iou, pixel = mask_agreement(analytic_safe, numeric_safe)
out = chart.copy()
out["iou"] = iou
out["pixel_agreement"] = pixel
out["safe_analytic"] = analytic_safe.sum(("q0", "p0")).astype(np.int64)
out["safe_numeric"] = numeric_safe.sum(("q0", "p0")).astype(np.int64)
out.attrs.update(
    agreement_t_eval=cycles,
    agreement_definition=("numeric safe = escape_cycle_energy > t_eval (= cycles); analytic safe = not escapes "
                          "(slow_flow_escapes); iou = |A and N| / |A or N|; pixel_agreement = mean(A == N) "
                          "over the (q0, p0) grid"),
    iou_mean=float(iou.mean()), iou_min=float(iou.min()),
    pixel_agreement_mean=float(pixel.mean()), pixel_agreement_min=float(pixel.min()),
)
for v, a_, px in zip(np.atleast_1d(iou[scan].values), np.atleast_1d(iou.values), np.atleast_1d(pixel.values)):
    print(f"{scan} = {v}: IoU = {a_:.4f}, pixel agreement = {px:.4f}")
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"escape chart + analytic/numeric agreement (rule agreement, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
