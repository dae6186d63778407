# Stage 7: the results archive, a Workflow Run RO-Crate (safebasins.io.archive): every dataset,
# the resolved parameter files and configuration, environment.lock, installed package versions,
# CITATION.cff, the workflow (Snakefile + rule files), ro-crate-metadata.json and a SHA-256 manifest.
#   snakemake -j2 archive   ->   results/archive/safebasins-results.tar.gz


ARCHIVE = "results/archive/safebasins-results.tar.gz"
# the workflow's source tree (where the real Snakefile lives, also when it is run through a symlink)
WORKFLOW_SRC = Path(workflow.main_snakefile).resolve().parent


rule archive:
    input:
        datasets=DATASETS,
        params=PARAM_FILES,
        lock="environment.lock",
        workflow=str(WORKFLOW_SRC / "Snakefile"),
        rules=sorted(str(p) for p in (WORKFLOW_SRC / "workflow" / "rules").glob("*.smk")),
        citation=str(WORKFLOW_SRC / "CITATION.cff"),
    output:
        ARCHIVE,
    params:
        config=lambda wildcards: json.dumps(config, sort_keys=True),
    log:
        "results/logs/archive/archive.log",
    localrule: True
    script:
        "../../scripts/archive.py"
