"""Rules `chart_gather` / `chart_final`: gather the tiles of every task of a chart experiment.

Figs 13-15: one chart (thresholds `xi_max`); Figs 16-17: charts stacked over `F`;
Figs 20-21: one chart with `xi_max` and `q_max` thresholds (+ attribute `t_eval`).
"""
from safebasins.config import load_params, params_hash, redirect_output
from safebasins.datasets import finalize, stack, task_charts, write_netcdf

redirect_output(snakemake.log[0])
p = load_params(snakemake.input.params)
files = list(snakemake.input.tiles)
ntasks = len(p["tasks"])
per_task = len(files) // ntasks

charts = task_charts(files, ntasks)
if p["kind"] == "basin_chart" and p["scan"] == "F":
    out = stack(charts, "F", [t["F"] for t in p["tasks"]], pad=())
    out.attrs["scan"] = "F"
else:
    out = charts[0]
    if p["kind"] == "basin_chart":
        out.attrs["scan"] = p["scan"]
if "t_eval" in p:
    out.attrs["t_eval"] = p["t_eval"]
out.attrs.setdefault("cycles", p["cycles"])
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"safebasins.numerics.escape_chart, {per_task} tile(s) per task gathered (rule chart_gather, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
