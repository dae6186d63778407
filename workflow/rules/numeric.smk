# Stages 4-5: numeric products (safebasins.numerics). Every job here uses `threads:` numba
# threads (config numerics.threads), so `-j2` never oversubscribes the cores.


rule numeric_fcr:
    """Numeric F_cr(Omega) by bisection + scan (dots of Figs 10-12)."""
    input:
        params=param_file,
    output:
        "results/data/numeric/fcr_{experiment}.nc",
    log:
        "results/logs/numeric_fcr/{experiment}.log",
    benchmark:
        "results/benchmarks/numeric_fcr/{experiment}.tsv"
    wildcard_constraints:
        experiment=alternatives(FCR_NUMERIC_EXPERIMENTS),
    threads: NUM_THREADS
    script:
        "../../scripts/numeric_fcr.py"


rule chart_tile:
    """One tile of one escape-chart task: a contiguous block of q0 rows (grids) or of samples
    (random ICs). One integration serves every threshold and evaluation time."""
    input:
        params=param_file,
    output:
        "results/data/numeric/parts/{experiment}/task{task}_tile{tile}of{tiles}.nc",
    log:
        "results/logs/chart_tile/{experiment}/task{task}_tile{tile}of{tiles}.log",
    benchmark:
        "results/benchmarks/chart_tile/{experiment}/task{task}_tile{tile}of{tiles}.tsv"
    wildcard_constraints:
        experiment=alternatives(CHART_EXPERIMENTS),
    threads: NUM_THREADS
    script:
        "../../scripts/chart_tile.py"


rule chart_gather:
    """Gather the tiles of a chart with an analytic counterpart (Figs 13-17; stacked over F for
    16-17); the agreement rule turns it into results/data/numeric/chart_{experiment}.nc."""
    input:
        params=param_file,
        tiles=chart_tiles,
    output:
        "results/data/numeric/parts/{experiment}/chart.nc",
    log:
        "results/logs/chart_gather/{experiment}.log",
    wildcard_constraints:
        experiment=alternatives(AGREEMENT_EXPERIMENTS),
    script:
        "../../scripts/chart_gather.py"


rule chart_final:
    """Gather the tiles of a chart without analytic counterpart (Figs 20-21, read by 20-22)."""
    input:
        params=param_file,
        tiles=chart_tiles,
    output:
        "results/data/numeric/chart_{experiment}.nc",
    log:
        "results/logs/chart_final/{experiment}.log",
    wildcard_constraints:
        experiment=alternatives(FINAL_CHART_EXPERIMENTS),
    script:
        "../../scripts/chart_gather.py"


rule criteria:
    """Energy versus displacement criterion on random ICs (Fig 19): A_E, A_q per (F, repeat)."""
    input:
        params=param_file,
        tiles=chart_tiles,
    output:
        "results/data/numeric/criteria_{experiment}.nc",
    log:
        "results/logs/criteria/{experiment}.log",
    wildcard_constraints:
        experiment=alternatives(CRITERIA_EXPERIMENTS),
    script:
        "../../scripts/criteria_gather.py"


rule strobe:
    """Stroboscopic map of non-escaping trajectories from seeded random ICs (Fig 18)."""
    input:
        params=param_file,
    output:
        "results/data/numeric/strobe_{experiment}.nc",
    log:
        "results/logs/strobe/{experiment}.log",
    benchmark:
        "results/benchmarks/strobe/{experiment}.tsv"
    wildcard_constraints:
        experiment=alternatives(STROBE_EXPERIMENTS),
    threads: NUM_THREADS
    script:
        "../../scripts/strobe.py"
