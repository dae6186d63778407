# Beyond-the-paper products (docs/extras.md): erosion profiles, phase-invariant ("true") safe
# basin, paper vs exact first harmonic. `snakemake -j2 extras`. Their numerics are the shared
# `chart_tile` jobs (one task = one escape chart: per F, per Psi); the datasets below read them
# or other experiments' datasets.


rule extras_dataset:
    """A beyond-the-paper dataset of the registry: results/data/extras/<name>.nc."""
    input:
        unpack(dataset_inputs("extras")),
    output:
        "results/data/extras/{name}.nc",
    log:
        "results/logs/extras/{name}.log",
    wildcard_constraints:
        name=alternatives(dataset_names("extras")),
    params:
        extensions=EXTENSIONS,
        backend=BACKEND,
        integrate_tasks=dataset_integrates_tasks("extras"),
    threads: dataset_threads("extras")
    resources:
        **job_resources("extras"),
    script:
        "../../scripts/dataset.py"


rule extras:
    """Every beyond-the-paper dataset and figure."""
    input:
        RUN.datasets("extras"),
        figure_targets("Beyond the paper"),
