"""Rule `analytic_fcr`: analytic F_cr(Omega) curves stacked over `curve` (Figs 1-4, 10-12)."""
import numpy as np

from safebasins.config import call_api, load_params, params_hash, redirect_output
from safebasins.datasets import finalize, stack, write_netcdf

redirect_output(snakemake.log[0])
from safebasins import theory  # noqa: E402

p = load_params(snakemake.input.params)
Omega = np.asarray(p["Omega"], dtype=float)
curves = p["curves"]
parts = []
for c in curves:
    print(f"{p['experiment']}: critical_forcing for {c['label']}")
    ds, _ = call_api(theory.critical_forcing, Omega, c["xi_max"], xi0=c["xi0"], gamma0=c["gamma0"],
                     fourier=p["fourier"])
    parts.append(ds)
coords = {k: [c[k] for c in curves] for k in ("xi_max", "xi0", "gamma0", "label")}
if all("Psi" in c for c in curves):
    coords["Psi"] = [c["Psi"] for c in curves]
out = stack(parts, "curve", coords=coords)
out.attrs["fourier"] = p["fourier"]
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"safebasins.theory.critical_forcing per curve (rule analytic_fcr, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
