"""Rule `extra_erosion_numeric`: numeric erosion profile over (F, xi_max, t_eval) from the
chart tiles (one escape chart per F, every threshold and evaluation time read from it:
safebasins.erosion.profile_from_charts), plus the first F at which each measure falls below
`level` per (xi_max, t_eval).
"""
from safebasins.config import load_params, params_hash, redirect_output

redirect_output(snakemake.log[0])
from safebasins.datasets import finalize, task_charts, write_netcdf  # noqa: E402
from safebasins.erosion import level_crossing, profile_from_charts  # noqa: E402

p = load_params(snakemake.input.params)
charts = task_charts(snakemake.input.tiles, len(p["tasks"]))
for c, t in zip(charts, p["tasks"]):
    c.attrs.update(F=t["F"], cycles=p["cycles"])
ds = profile_from_charts(charts, p["t_eval"], stack_dim="F")
cross = level_crossing(ds, p["level"])
for m in ("GIM", "LIM", "IF"):
    ds[f"F_{m}"] = cross[m].assign_attrs(units="1", long_name=f"first F at which {m} falls below {p['level']:g}")
ds.attrs.update(level=p["level"], xi_max=p["xi_max"], cycles=p["cycles"])
print(ds[["F_GIM", "F_LIM", "F_IF"]].to_dataframe())
finalize(ds, title=p["title"] + " (numeric)", params=p, config_hash=params_hash(p),
         history=(f"safebasins.numerics.escape_chart per F ({len(charts)} charts) + "
                  f"safebasins.erosion.profile_from_charts (rule extra_erosion_numeric, {p['experiment']})"))
write_netcdf(ds, snakemake.output[0])
print(ds)
