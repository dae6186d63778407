# safebasins: every dataset (and, via workflow/rules/figures.smk, every figure) of
# Karmi, Kravetc & Gendelman, "Analytic exploration of safe basins in a benchmark problem of
# forced escape", from config/config.yaml.
#
#   snakemake -j2                                        # all datasets, archive, figures into results/
#   snakemake -j2 --configfile config/quick.yaml         # the same DAG at coarse resolution
#   snakemake -j2 archive                                # results/archive/*.tar.gz
#   snakemake --report results/report.html               # HTML report
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/parameters.smk"
include: "workflow/rules/analytic.smk"
include: "workflow/rules/numeric.smk"
include: "workflow/rules/agreement.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/extras.smk"
include: "workflow/rules/archive.smk"


rule all:
    """Every dataset behind the paper's 22 figures, their archive, the figures and the extra products."""
    default_target: True
    input:
        PARAM_FILES,
        DATASETS,
        ARCHIVE,
        FIGURE_TARGETS,
        EXTRA_TARGETS,


rule datasets:
    """Only the datasets (no figures)."""
    input:
        PARAM_FILES,
        DATASETS,
