"""Rule `criteria`: energy versus displacement escape criterion on random ICs (Fig 19).

For every F and repetition r (seed seeds[r], n_ic ICs uniform in the box): A_E = number of ICs
that never exceed H0 = xi_max within `cycles` (ESB), A_q = number that never exceed
|q| = q_max (DSB); rel_diff = (A_q - A_E) / A_E. One integration with both thresholds
replaces the paper's two passes (ESB is contained in DSB).
"""
import numpy as np
import xarray as xr

from safebasins.config import load_params, params_hash, redirect_output
from safebasins.datasets import finalize, load, write_netcdf

redirect_output(snakemake.log[0])
p = load_params(snakemake.input.params)
files = list(snakemake.input.tiles)
ntasks = len(p["tasks"])
per_task = len(files) // ntasks
n_ic, reps, cycles = p["n_ic"], p["repeats"], p["cycles"]

A_E = np.zeros((ntasks, reps), dtype=np.int64)
A_q = np.zeros((ntasks, reps), dtype=np.int64)
attrs = {}
for i in range(ntasks):
    parts = [load(f) for f in files[i * per_task:(i + 1) * per_task]]
    ds = xr.concat(parts, dim="sample", data_vars="minimal", coords="minimal", compat="override",
                   combine_attrs="override")
    ds = ds.sortby("sample")
    assert ds.sizes["sample"] == n_ic * reps, ds.sizes
    e = np.asarray(ds["escape_cycle_energy"].isel(xi_max=0).values) > cycles
    d = np.asarray(ds["escape_cycle_displacement"].isel(q_max=0).values) > cycles
    A_E[i] = e.reshape(reps, n_ic).sum(axis=1)
    A_q[i] = d.reshape(reps, n_ic).sum(axis=1)
    attrs = {k: ds.attrs[k] for k in ("integrator", "steps_per_cycle") if k in ds.attrs}
    print(f"F={p['F'][i]}: A_E={A_E[i].tolist()} A_q={A_q[i].tolist()}", flush=True)

with np.errstate(divide="ignore", invalid="ignore"):
    rel = np.where(A_E > 0, (A_q - A_E) / np.maximum(A_E, 1), np.nan)
out = xr.Dataset(
    {"A_E": (("F", "repeat"), A_E), "A_q": (("F", "repeat"), A_q), "rel_diff": (("F", "repeat"), rel)},
    coords={"F": ("F", np.asarray(p["F"], dtype=float)), "repeat": ("repeat", np.arange(reps)),
            "seed": ("repeat", np.asarray(p["seeds"], dtype=np.int64))},
)
out.attrs.update(attrs)
out.attrs.update(Omega=p["Omega"], Psi=p["Psi"], xi_max=p["xi_max"], q_max=p["q_max"], n_ic=n_ic,
                 cycles=cycles, box=np.asarray(p["box"], dtype=float).ravel(),
                 criterion_note="safe = escape_cycle > cycles; A_E energy (H0 > xi_max), A_q displacement (|q| > q_max)")
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"safebasins.numerics.escape_chart on seeded random ICs (rule criteria, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
