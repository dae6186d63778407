# Figure rules: one per figure of the plan (the paper's 22, the beyond-the-paper ones and those
# of experiments declared in the config), each executing its papermill notebook (kernel python3)
# from the repository root.
#
# Inputs  = the figure's datasets + its notebook + the plotting code, so a plot change never
#           reruns a simulation and the notebooks never recompute physics.
# Outputs = results/figures/<name>.png (in the report) and .pdf, the executed notebook under
#           results/notebooks/, and the report caption results/captions/<name>.rst that the
#           notebook writes with the numbers read from the datasets (the report shows it).
# Notebooks of the package's figures are generated into notebooks/ by scripts/make_notebooks.py
# (committed, checked by the tests); those of config experiments by the rule figure_notebook.
import glob as _fig_glob
import os as _fig_os
import shlex as _fig_shlex
import sys as _fig_sys

from safebasins.plotting.notebooks import caption_path as _fig_caption_path

_FIG_PLOTTING = sorted(_fig_glob.glob(f"{workflow.basedir}/src/safebasins/plotting/*.py"))
_FIG_DPI = 180  # PNG resolution (the PDF is vector, rasters inside it embedded at this dpi)

for _fig in FIGURES:

    rule:
        name:
            _fig.name
        input:
            notebook=_fig.notebook,
            plotting=_FIG_PLOTTING,
            **_fig.inputs,
        output:
            png=report(
                _fig.png,
                # absolute: the caption is a result of this rule, read when the report is made
                caption=_fig_os.path.abspath(_fig_caption_path(_fig)),
                category=_fig.category,
                labels={"figure": _fig.label, "slug": _fig.stem},
            ),
            pdf=_fig.pdf,
            notebook=_fig.executed_notebook,
            caption=_fig_caption_path(_fig),
        log:
            f"results/logs/figures/{_fig.name}.log",
        params:
            python=_fig_sys.executable,
            dpi=_FIG_DPI,
            # bound now (a rule defined in a loop); YAML (here JSON) because some inputs are lists
            data=_fig_shlex.quote(json.dumps(dict(_fig.inputs))),
        threads: 1
        shell:
            "{params.python} -m papermill --no-progress-bar -k python3 "
            "{input.notebook} {output.notebook} -y {params.data} "
            "-p png {output.png} -p pdf {output.pdf} -p caption {output.caption} -p dpi {params.dpi} > {log} 2>&1"


rule figure_notebook:
    """Papermill template of a figure of an experiment declared in the config."""
    output:
        "results/notebooks/templates/{stem}.ipynb",
    log:
        "results/logs/figure_notebook/{stem}.log",
    wildcard_constraints:
        stem=alternatives([f.stem for f in FIGURES if not f.packaged]),
    params:
        figure=lambda wildcards: next(f.name for f in FIGURES if f.stem == wildcards.stem),
        extensions=EXTENSIONS,
        configfiles=lambda wildcards: json.dumps(config),
    localrule: True
    script:
        "../../scripts/figure_notebook.py"


rule figures:
    """The paper's figures."""
    input:
        figure_targets("Figures"),
