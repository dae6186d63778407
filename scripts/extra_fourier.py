"""Rules `extra_fourier_fcr` / `extra_fourier_iou`: paper vs exact first harmonic against the
numerics already computed for the paper figures (nothing is re-integrated).

fcr: results/data/numeric/fcr_figNN.nc (Figs 10-12) -> F_cr analytic (both variants) at the
     numeric Omega points, errors, RMS (safebasins.fourier_compare.fcr_fourier_comparison_from_numeric).
iou: results/data/numeric/chart_figNN.nc (Figs 13-17) -> IoU of analytic (both variants) and
     numeric safe basins (safebasins.fourier_compare.iou_fourier_comparison).
"""
from safebasins.config import load_params, params_hash, redirect_output, set_threads

redirect_output(snakemake.log[0])
set_threads(snakemake.threads)
from safebasins import fourier_compare as fc  # noqa: E402
from safebasins.datasets import finalize, load, write_netcdf  # noqa: E402

p = load_params(snakemake.input.params)
what, source = snakemake.params.what, snakemake.wildcards.source
src = load(snakemake.input.source)
if what == "fcr":
    ds = fc.fcr_fourier_comparison_from_numeric(src)
    if "curve" in ds.dims:  # per-curve parameters of the source (attributes would conflict across curves)
        ds = ds.assign_coords({c: ("curve", src[c].values) for c in ("label", "xi_max", "xi0", "gamma0", "Psi")
                               if c in src.coords and src[c].dims == ("curve",)})
    print(ds[["rms_rel_error", "mean_abs_rel_error"]].to_dataframe())
else:
    ds = fc.iou_fourier_comparison(src, p["t_eval"])
    print(ds["mean_iou"].to_dataframe())
ds.attrs.update(source_experiment=source, source_file=str(snakemake.input.source),
                source_config_hash=src.attrs.get("config_hash", "none"))
finalize(ds, title=f"{p['title']}: {'F_cr' if what == 'fcr' else 'safe-basin IoU'} of {source}", params=p,
         config_hash=params_hash(p),
         history=f"safebasins.fourier_compare on {snakemake.input.source} (rule extra_fourier_{what}, {p['experiment']})")
write_netcdf(ds, snakemake.output[0])
print(ds)
