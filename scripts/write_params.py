"""Rule `parameters`: one experiment's resolved parameters (results/params/{experiment}.yaml)."""
from safebasins.pipeline.params_file import write_params

write_params(snakemake)
