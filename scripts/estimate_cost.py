"""Upper-bound cost of every numeric experiment in trajectory-steps (no early escape assumed).

    .venv/bin/python scripts/estimate_cost.py [config/config.yaml] [config/quick.yaml ...]

Later files are merged into the first (as `snakemake --configfile`). Bisection (Figs 10-12)
counts ceil(log2(bracket / tol)) levels plus the n_scan scan per Omega point.
"""
import math
import sys

from snakemake.utils import update_config

from safebasins import config as sbc

RATE = 1.5e9  # trajectory-steps per second of the numerics engine (2 cores)


def costs(resolved):
    out = {}
    for e, p in resolved.items():
        k = p["kind"]
        if k == "fcr_compare":
            n = p["numeric"]
            lo, hi = n["F_bracket"]
            levels = math.ceil(math.log2((hi - lo) / n["tol"]))
            out[e] = len(p["curves"]) * len(n["Omega"]) * (levels + n["n_scan"]) * n["cycles"] * n["steps_per_cycle"]
        elif k in ("basin_chart", "chart", "erosion", "true_basin"):  # extras: one chart per F / per Psi
            nq, np_ = p["grid"]["n"]
            out[e] = len(p["tasks"]) * nq * np_ * p["cycles"] * p["steps_per_cycle"]
        elif k == "criteria":
            out[e] = len(p["tasks"]) * p["n_ic"] * p["repeats"] * p["cycles"] * p["steps_per_cycle"]
        elif k == "strobe":
            out[e] = p["n_candidates"] * p["n_iter"] * p["steps_per_cycle"]
    return out


def main(paths):
    paths = paths or [str(sbc.REPO_ROOT / "config" / "config.yaml")]
    cfg = sbc.load_yaml(paths[0])
    for extra in paths[1:]:
        update_config(cfg, sbc.load_yaml(extra))
    c = costs(sbc.resolve(sbc.validate_config(cfg)))
    for e, s in c.items():
        print(f"{e}  {s:10.3e} steps  <= {s / RATE:7.1f} s")
    total = sum(c.values())
    print(f"total {total:10.3e} steps  <= {total / RATE:7.1f} s at {RATE:.1e} steps/s")


if __name__ == "__main__":
    main(sys.argv[1:])
