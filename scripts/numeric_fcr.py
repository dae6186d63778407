"""Rule `numeric_fcr`: numeric F_cr(Omega) (bisection + scan) stacked over `curve` (Figs 10-12)."""
import numpy as np

from safebasins.config import call_api, load_params, params_hash, redirect_output, set_threads

redirect_output(snakemake.log[0])
set_threads(snakemake.threads)
from safebasins import numerics, theory  # noqa: E402
from safebasins.datasets import finalize, stack, write_netcdf  # noqa: E402

p = load_params(snakemake.input.params)
num = p["numeric"]
Omega = np.asarray(num["Omega"], dtype=float)
parts, q0s, p0s = [], [], []
for c in p["curves"]:
    q0, p0 = (float(v) for v in theory.initial_condition(c["xi0"], c["gamma0"], c["Psi"]))
    q0s.append(q0)
    p0s.append(p0)
    print(f"{p['experiment']}: {c['label']}: IC (q0, p0) = ({q0:.6f}, {p0:.6f})", flush=True)
    ds, _ = call_api(numerics.critical_forcing_numeric, Omega, c["xi_max"], q0=q0, p0=p0, Psi=c["Psi"],
                     cycles=num["cycles"], tol=num["tol"], F_bracket=tuple(num["F_bracket"]),
                     criterion=num["criterion"], n_scan=num["n_scan"],
                     steps_per_cycle=num["steps_per_cycle"], threads=snakemake.threads)
    parts.append(ds)
coords = {k: [c[k] for c in p["curves"]] for k in ("xi_max", "xi0", "gamma0", "Psi", "label")}
coords.update(q0=q0s, p0=p0s)
out = stack(parts, "curve", coords=coords)
finalize(out, title=p["title"], params=p, config_hash=params_hash(p),
         history=f"safebasins.numerics.critical_forcing_numeric per curve (rule numeric_fcr, {p['experiment']})")
write_netcdf(out, snakemake.output[0])
print(out)
