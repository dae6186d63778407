# Stages 4-6: numeric products (safebasins.numerics). Heavy jobs use `threads:` numba threads
# (config numerics.threads), so `-j2` never oversubscribes the cores. Escape charts are split
# into `numerics.tiles` independent tile jobs per task and gathered by the dataset that reads
# them (with the analytic/numeric agreement where the kind has an analytic counterpart).


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
        experiment=alternatives(RUN.chart_experiments()),
    params:
        extensions=EXTENSIONS,
        backend=BACKEND,
    threads: NUM_THREADS
    resources:
        **job_resources(),
    script:
        "../../scripts/chart_tile.py"


rule numeric_dataset:
    """A numeric dataset of the registry: results/data/numeric/<name>.nc (numeric F_cr, gathered
    escape charts with their agreement, criteria counts, stroboscopic maps)."""
    input:
        unpack(dataset_inputs("numeric")),
    output:
        "results/data/numeric/{name}.nc",
    log:
        "results/logs/numeric/{name}.log",
    benchmark:
        "results/benchmarks/numeric/{name}.tsv"
    wildcard_constraints:
        name=alternatives(dataset_names("numeric")),
    params:
        extensions=EXTENSIONS,
        backend=BACKEND,
        integrate_tasks=dataset_integrates_tasks("numeric"),
    threads: dataset_threads("numeric")
    resources:
        **job_resources("numeric"),
    script:
        "../../scripts/dataset.py"
