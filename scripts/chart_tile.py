"""Rule `chart_tile`: integrate one tile of one escape-chart task.

Grid tasks (Figs 13-17, 20, 21): a contiguous block of q0 rows x all p0 (dims q0, p0).
Random-IC tasks (Fig 19): a contiguous block of the seeded samples (dim `sample`, global index).
Tasks may carry their own forcing phase `Psi` (the phase-invariant basin extra: one task per Psi).
Each trajectory is independent, so the gathered chart is the same for any tile count.
"""
import numpy as np

from safebasins.config import call_api, grid_axes, load_params, redirect_output, set_threads, tile_slice

redirect_output(snakemake.log[0])
set_threads(snakemake.threads)
from safebasins import numerics  # noqa: E402
from safebasins.datasets import write_netcdf  # noqa: E402

p = load_params(snakemake.input.params)
k, tile, tiles = int(snakemake.wildcards.task), int(snakemake.wildcards.tile), int(snakemake.wildcards.tiles)
task = p["tasks"][k]
Psi = task.get("Psi", p["Psi"])

if p["kind"] == "criteria":
    qs, ps = [], []
    for seed in p["seeds"]:
        q, pp = numerics.random_initial_conditions(p["n_ic"], seed, box=tuple(tuple(b) for b in p["box"]))
        qs.append(np.asarray(q, dtype=float))
        ps.append(np.asarray(pp, dtype=float))
    q0, p0 = np.concatenate(qs), np.concatenate(ps)
    sl = tile_slice(q0.size, tiles, tile)
    q0, p0 = q0[sl], p0[sl]
else:
    qa, pa = grid_axes(p["grid"])
    sl = tile_slice(qa.size, tiles, tile)
    q0, p0 = qa[sl], pa

print(f"{p['experiment']} task {k} tile {tile}/{tiles}: F={task['F']} Omega={p['Omega']} Psi={Psi} "
      f"xi_max={task['xi_max']} q_max={task['q_max']} cycles={p['cycles']} ICs={q0.size}x{p0.size if p['kind'] != 'criteria' else 1}",
      flush=True)
ds, _ = call_api(numerics.escape_chart, q0, p0, task["F"], p["Omega"], Psi, xi_max=tuple(task["xi_max"]),
                 q_max=tuple(task["q_max"]), cycles=p["cycles"], steps_per_cycle=p["steps_per_cycle"],
                 threads=snakemake.threads, grid=p["kind"] != "criteria")
if p["kind"] == "criteria":
    ds = ds.assign_coords(sample=np.arange(sl.start, sl.stop))
ds.attrs.update(task=k, tile=tile, tiles=tiles)
write_netcdf(ds, snakemake.output[0])
print(ds)
