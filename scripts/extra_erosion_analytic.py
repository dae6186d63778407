"""Rule `extra_erosion_analytic`: analytic erosion profile GIM / LIM / IF versus F over
(fourier, F, xi_max) on the numeric grid (safebasins.erosion.erosion_profile_analytic),
plus the first F at which each measure falls below `level` (F_GIM, F_LIM, F_IF).
"""
from safebasins.config import grid_axes, load_params, params_hash, redirect_output, set_threads

redirect_output(snakemake.log[0])
set_threads(snakemake.threads)
from safebasins.datasets import finalize, write_netcdf  # noqa: E402
from safebasins.erosion import erosion_profile_analytic, level_crossing  # noqa: E402

p = load_params(snakemake.input.params)
q0, p0 = grid_axes(p["grid"])
print(f"{p['experiment']}: {len(p['F'])} F x {len(p['xi_max'])} xi_max x {p['fourier']} on {p['grid']['n']}")
ds = erosion_profile_analytic(p["F"], p["Omega"], p["Psi"], p["xi_max"], q0, p0, fourier=p["fourier"])
cross = level_crossing(ds, p["level"])
for m in ("GIM", "LIM", "IF"):
    ds[f"F_{m}"] = cross[m].assign_attrs(units="1", long_name=f"first F at which {m} falls below {p['level']:g}")
ds.attrs.update(level=p["level"], xi_max=p["xi_max"])
print(ds[["F_GIM", "F_LIM", "F_IF"]].to_dataframe())
finalize(ds, title=p["title"] + " (analytic)", params=p, config_hash=params_hash(p),
         history=f"safebasins.erosion.erosion_profile_analytic (rule extra_erosion_analytic, {p['experiment']})")
write_netcdf(ds, snakemake.output[0])
print(ds)
