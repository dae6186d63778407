"""Rule `figure_notebook`: the papermill template of a figure of a config experiment."""
import json

from safebasins.pipeline.plan import plan
from safebasins.plotting.notebooks import write_notebook

run = plan(json.loads(snakemake.params.configfiles))
write_notebook(run.experiments[snakemake.params.figure].figure, snakemake.output[0])
