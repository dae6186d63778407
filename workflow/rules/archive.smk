# Stage 7: archive of every dataset + resolved configuration + environment + SHA-256 manifest.
#   snakemake -j2 archive   ->   results/archive/safebasins-results.tar.gz


ARCHIVE = "results/archive/safebasins-results.tar.gz"


rule archive:
    input:
        datasets=DATASETS,
        params=PARAM_FILES,
        lock="environment.lock",
    output:
        ARCHIVE,
    params:
        config=lambda wildcards: json.dumps(config, sort_keys=True),
    log:
        "results/logs/archive/archive.log",
    localrule: True
    script:
        "../../scripts/archive.py"
