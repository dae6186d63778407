"""Rule `extra_true_basin_analytic`: analytic phase-invariant safe basin
(safebasins.phase_invariant.true_safe_basin_analytic): per-phase basins over Psi, their
intersection, the all-phase basin {H0 < xi_true} and the integrity of each, per first-harmonic
variant.
"""
from safebasins.config import grid_axes, load_params, params_hash, redirect_output, set_threads

redirect_output(snakemake.log[0])
set_threads(snakemake.threads)
from safebasins.datasets import finalize, write_netcdf  # noqa: E402
from safebasins.phase_invariant import true_safe_basin_analytic  # noqa: E402

p = load_params(snakemake.input.params)
q0, p0 = grid_axes(p["grid"])
print(f"{p['experiment']}: F={p['F']} Omega={p['Omega']} xi_max={p['xi_max']} {len(p['Psi'])} phases {p['fourier']}")
ds = true_safe_basin_analytic(p["F"], p["Omega"], p["xi_max"], q0, p0, p["Psi"], fourier=p["fourier"],
                              n_gamma=p["n_gamma"])
print(ds[["xi_true", "GIM_true", "LIM_true", "IF_true", "GIM_continuous", "GIM_closed"]].to_dataframe())
finalize(ds, title=p["title"] + " (analytic)", params=p, config_hash=params_hash(p),
         history=f"safebasins.phase_invariant.true_safe_basin_analytic (rule extra_true_basin_analytic, {p['experiment']})")
write_netcdf(ds, snakemake.output[0])
print(ds)
