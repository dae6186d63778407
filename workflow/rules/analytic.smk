# Stages 2-3: analytic products (safebasins.theory): F_cr curves and safe basins.


rule analytic_fcr:
    """Analytic F_cr(Omega) curves (Figs 1-4 and the theory lines of Figs 10-12)."""
    input:
        params=param_file,
    output:
        "results/data/analytic/fcr_{experiment}.nc",
    log:
        "results/logs/analytic_fcr/{experiment}.log",
    wildcard_constraints:
        experiment=alternatives(FCR_EXPERIMENTS),
    script:
        "../../scripts/analytic_fcr.py"


rule analytic_basin:
    """Analytic safe basins: boundaries + per-IC escape masks on the numeric grid (Figs 5-9, 13-18);
    for Figs 5-9 also C and the escape mask on the (gamma_rm, xi_rm) resonance-manifold grid."""
    input:
        params=param_file,
    output:
        "results/data/analytic/basin_{experiment}.nc",
    log:
        "results/logs/analytic_basin/{experiment}.log",
    wildcard_constraints:
        experiment=alternatives(BASIN_EXPERIMENTS),
    script:
        "../../scripts/analytic_basin.py"
