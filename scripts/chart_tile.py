"""Rule `chart_tile`: one tile of one escape-chart task (safebasins.pipeline.runtime.make_tile)."""
from safebasins.pipeline.runtime import make_tile

make_tile(snakemake)
