# Stage 1: one resolved parameter file per experiment.
# The resolved parameters are the rule's `params`, so Snakemake's params rerun trigger
# rewrites results/params/{experiment}.yaml only when that experiment's content changes;
# editing one figure's block never touches (or reruns) another figure's chain.
# (`script:` rather than `run:`: Snakemake 9 spawns a whole workflow re-parse per `run:` job.)


rule parameters:
    output:
        "results/params/{experiment}.yaml",
    params:
        spec=lambda wildcards: PARAMS_JSON[wildcards.experiment],
    log:
        "results/logs/parameters/{experiment}.log",
    localrule: True
    script:
        "../../scripts/write_params.py"
