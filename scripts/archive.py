"""Rule `archive`: results/archive/safebasins-results.tar.gz, a Workflow Run RO-Crate with every
dataset, the resolved parameter files, the validated configuration, environment.lock, the
installed package versions, CITATION.cff, the workflow and a SHA-256 manifest
(see safebasins.io.archive)."""
import json

from safebasins.pipeline.runtime import redirect_output
from safebasins.io.archive import write_archive

redirect_output(snakemake.log[0])
out = write_archive(snakemake.output[0], snakemake.input.datasets, snakemake.input.params, snakemake.input.lock,
                    json.loads(snakemake.params.config), workflow=snakemake.input.workflow,
                    workflow_parts=snakemake.input.rules, citation=snakemake.input.citation)
print(f"wrote {out}")
