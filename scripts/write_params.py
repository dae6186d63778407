"""Rule `parameters`: write one experiment's resolved parameters (results/params/{experiment}.yaml)."""
import json

from safebasins.config import write_params_file

write_params_file(snakemake.output[0], json.loads(snakemake.params.spec), snakemake.log[0])
