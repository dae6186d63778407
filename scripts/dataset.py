"""Rules `analytic`, `numeric`, `extras`: one dataset of the registry (safebasins.pipeline)."""
from safebasins.pipeline.runtime import make_dataset

make_dataset(snakemake)
