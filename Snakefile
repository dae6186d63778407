# safebasins: every dataset and figure of Karmi, Kravetc & Gendelman, "Analytic exploration of
# safe basins in a benchmark problem of forced escape", and the beyond-the-paper products, from
# config/config.yaml through the registry of experiment kinds (safebasins.pipeline).
#
#   snakemake -j2                                        # all datasets, figures, archive
#   snakemake -j2 --configfile config/quick.yaml         # the same DAG at coarse resolution
#   snakemake -j2 escape_equation                       # the cubic-well study only
#   snakemake -j2 other_wells                           # the pendulum and sech^2 study
#   snakemake -j2 damped                                # the damped study
#   snakemake -j2 archive                                # results/archive/*.tar.gz
#   snakemake --report results/report.html               # HTML report
import os

from snakemake.utils import min_version

from safebasins.pipeline.config import load_yaml as _check_config_file

min_version("9.0")


# found beside this Snakefile, whatever the working directory (`-s path/Snakefile`); read first by
# safebasins' loader, whose errors name the file and line (a syntax error, a key given twice)
_check_config_file(os.path.join(workflow.basedir, "config", "config.yaml"))


configfile: os.path.join(workflow.basedir, "config", "config.yaml")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/parameters.smk"
include: "workflow/rules/analytic.smk"
include: "workflow/rules/numeric.smk"
include: "workflow/rules/extras.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/archive.smk"


rule all:
    """Every dataset, figure and the archive."""
    default_target: True
    input:
        PARAM_FILES,
        DATASETS,
        ARCHIVE,
        [p for f in FIGURES for p in (f.png, f.pdf)],


rule datasets:
    """Only the datasets (no figures)."""
    input:
        PARAM_FILES,
        DATASETS,


rule escape_equation:
    """The escape-equation study (cubic well, config block `escape_equation`): datasets and figures."""
    input:
        [p for e in RUN.experiments.values() if e.key.startswith("escape_equation.") for p in e.dataset_files()],
        [p for e in RUN.experiments.values() if e.key.startswith("escape_equation.") for p in (e.figure.png, e.figure.pdf)],


rule damped:
    """The damped study (config block `damped`): datasets and figures."""
    input:
        [p for e in RUN.experiments.values() if e.key.startswith("damped.") for p in e.dataset_files()],
        [p for e in RUN.experiments.values() if e.key.startswith("damped.") for p in (e.figure.png, e.figure.pdf)],


rule other_wells:
    """The pendulum and sech^2 study (config block `other_wells`): datasets and figures."""
    input:
        [p for e in RUN.experiments.values() if e.key.startswith("other_wells.") for p in e.dataset_files()],
        [p for e in RUN.experiments.values() if e.key.startswith("other_wells.") for p in (e.figure.png, e.figure.pdf)],


rule experiments:
    """The datasets and figures of the experiments under `experiments:`: those the --configfile
    files name there, else all of the config's (common.smk, TARGET_EXPERIMENTS)."""
    input:
        [p for e in TARGET_EXPERIMENTS for p in e.dataset_files()],
        [p for e in TARGET_EXPERIMENTS if e.figure is not None for p in (e.figure.png, e.figure.pdf)],


# the cost of the requested targets, refused above the budgets before any job runs (common.smk)
cost_guard()
