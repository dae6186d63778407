# Stages 2-3: analytic products (safebasins.theory, the slow flow of the isolated resonance):
# F_cr curves, safe-basin boundaries and per-IC masks. One rule for every kind: the registry
# names the library call of each dataset (safebasins.pipeline.kinds).


rule analytic_dataset:
    """An analytic dataset of the registry: results/data/analytic/<name>.nc."""
    input:
        unpack(dataset_inputs("analytic")),
    output:
        "results/data/analytic/{name}.nc",
    log:
        "results/logs/analytic/{name}.log",
    wildcard_constraints:
        name=alternatives(dataset_names("analytic")),
    params:
        extensions=EXTENSIONS,
        backend=BACKEND,
        integrate_tasks=dataset_integrates_tasks("analytic"),
    threads: dataset_threads("analytic")
    resources:
        **job_resources("analytic"),
    script:
        "../../scripts/dataset.py"
