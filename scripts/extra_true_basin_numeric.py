"""Rule `extra_true_basin_numeric`: numeric phase-invariant safe basin from the chart tiles
(one escape chart per forcing phase Psi; safebasins.phase_invariant.true_safe_basin_from_charts):
per-phase basins and their intersection over (xi_max, t_eval), integrity of each.
"""
from safebasins.config import load_params, params_hash, redirect_output

redirect_output(snakemake.log[0])
from safebasins.datasets import finalize, task_charts, write_netcdf  # noqa: E402
from safebasins.phase_invariant import true_safe_basin_from_charts  # noqa: E402

p = load_params(snakemake.input.params)
charts = task_charts(snakemake.input.tiles, len(p["tasks"]))
for c, t in zip(charts, p["tasks"]):
    c.attrs.update(Psi=t["Psi"], cycles=p["cycles"])
ds = true_safe_basin_from_charts(charts, p["t_eval"])
print(ds[["GIM_true", "LIM_true", "IF_true", "xi_inscribed_true"]].to_dataframe())
finalize(ds, title=p["title"] + " (numeric)", params=p, config_hash=params_hash(p),
         history=(f"safebasins.numerics.escape_chart per Psi ({len(charts)} charts) + "
                  f"safebasins.phase_invariant.true_safe_basin_from_charts (rule extra_true_basin_numeric, "
                  f"{p['experiment']})"))
write_netcdf(ds, snakemake.output[0])
print(ds)
