"""Rule `analytic_basin`: analytic safe basins (Figs 5-9, 13-17, 18).

basin_figNN.nc holds the boundary curves of safe_basin_boundaries (dims `curve`, `vertex`;
the vertex coordinates in the IC plane are renamed `q0_vertex`, `p0_vertex` because `q0`,
`p0` are the grid dimensions of the mask) and `escapes(q0, p0)` from slow_flow_escapes on
the same grid as the numeric chart. Figs 5-9 add C(gamma_rm, xi_rm) and
escapes_rm(gamma_rm, xi_rm). Figs 13-17 are stacked over the scanned xi_max or F.
"""
import numpy as np
import xarray as xr

from safebasins.config import call_api, grid_axes, load_params, params_hash, redirect_output
from safebasins.datasets import finalize, stack, write_netcdf

redirect_output(snakemake.log[0])
from safebasins import theory  # noqa: E402

p = load_params(snakemake.input.params)
kind, fourier = p["kind"], p["fourier"]
qa, pa = grid_axes(p["grid"])
Q, P = np.meshgrid(qa, pa, indexing="ij")


def one_basin(F, Omega, Psi, xi_max):
    print(f"{p['experiment']}: basin F={F} Omega={Omega} Psi={Psi} xi_max={xi_max}")
    b, _ = call_api(theory.safe_basin_boundaries, F, Omega, Psi, xi_max, fourier=fourier,
                    n_points=p["n_points"])
    b = b.rename({k: f"{k}_vertex" for k in ("q0", "p0") if k in b.variables})
    esc, _ = call_api(theory.slow_flow_escapes, Q, P, F, Omega, Psi, xi_max, fourier=fourier)
    b["escapes"] = xr.DataArray(np.asarray(esc, dtype=bool), dims=("q0", "p0"))
    return b.assign_coords(q0=("q0", qa), p0=("p0", pa))


if kind in ("basin_rm", "strobe"):
    out = one_basin(p["F"], p["Omega"], p["Psi"], p["xi_max"])
    if kind == "basin_rm":
        m = p["manifold"]
        g = np.linspace(-np.pi, np.pi, m["n_gamma"])
        x = np.linspace(0.0, m["xi_top"], m["n_xi"])
        G, X = np.meshgrid(g, x, indexing="ij")
        C, _ = call_api(theory.first_integral, G, X, p["F"], p["Omega"], fourier=fourier)
        E, _ = call_api(theory.escapes_on_manifold, G, X, p["F"], p["Omega"], p["xi_max"], fourier=fourier)
        out = out.assign_coords(gamma_rm=("gamma_rm", g), xi_rm=("xi_rm", x))
        out["C"] = (("gamma_rm", "xi_rm"), np.asarray(C, dtype=float))
        out["escapes_rm"] = (("gamma_rm", "xi_rm"), np.asarray(E, dtype=bool))
elif kind == "basin_chart":
    scan = p["scan"]
    values = p[scan]
    parts = [one_basin(v if scan == "F" else p["F"], p["Omega"], p["Psi"], v if scan == "xi_max" else p["xi_max"])
             for v in values]
    # per-basin saddle point: always a coordinate along the scanned dimension
    saddle = {k: [float(b.attrs.get(k, np.nan)) for b in parts] for k in ("saddle_gamma", "saddle_xi")}
    out = stack(parts, scan, values, coords=saddle)
    out.attrs["scan"] = scan
else:
    raise ValueError(f"analytic_basin: unexpected kind {kind!r}")

for k in ("F", "Omega", "Psi", "xi_max"):
    if k not in out.dims and k not in out.coords:
        out.attrs[k] = p[k]
out.attrs["fourier"] = fourier
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"safebasins.theory.safe_basin_boundaries + slow_flow_escapes (rule analytic_basin, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
