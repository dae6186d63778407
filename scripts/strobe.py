"""Rule `strobe`: stroboscopic map of non-escaping trajectories from seeded random ICs (Fig 18).

n_candidates ICs are drawn uniformly in `box` (numerics.random_initial_conditions, seed
recorded); all are iterated n_iter times and the first n_trajectories that never escape
(H0 <= xi_max) are kept, in draw order (coordinate `candidate` = index in the draw).
"""
import numpy as np

from safebasins.config import call_api, load_params, params_hash, redirect_output, set_threads

redirect_output(snakemake.log[0])
set_threads(snakemake.threads)
from safebasins import numerics  # noqa: E402
from safebasins.datasets import finalize, write_netcdf  # noqa: E402

p = load_params(snakemake.input.params)
q0, p0 = numerics.random_initial_conditions(p["n_candidates"], p["seed"], box=tuple(tuple(b) for b in p["box"]))
ds, _ = call_api(numerics.stroboscopic_map, np.asarray(q0, float), np.asarray(p0, float), p["F"], p["Omega"],
                 p["Psi"], n_iter=p["n_iter"], xi_max=p["xi_max"], steps_per_cycle=p["steps_per_cycle"],
                 threads=snakemake.threads)
safe = np.flatnonzero(~np.asarray(ds["escaped"].values, dtype=bool))
print(f"{safe.size} of {p['n_candidates']} candidates never escape in {p['n_iter']} iterations", flush=True)
if safe.size < p["n_trajectories"]:
    raise RuntimeError(f"only {safe.size} non-escaping candidates, {p['n_trajectories']} requested: "
                       f"raise figures.{p['experiment']}.n_candidates")
keep = safe[: p["n_trajectories"]]
out = ds.isel(sample=keep)
out = out.assign_coords(candidate=("sample", keep), sample=np.arange(keep.size))
out.attrs.update(seed=p["seed"], n_candidates=p["n_candidates"], box=np.asarray(p["box"], float).ravel(),
                 F=p["F"], Omega=p["Omega"], Psi=p["Psi"], xi_max=p["xi_max"], n_iter=p["n_iter"],
                 fraction_non_escaping=safe.size / p["n_candidates"])
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"safebasins.numerics.stroboscopic_map (rule strobe, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
