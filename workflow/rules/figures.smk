# Figure rules: one rule per paper figure (fig01 ... fig22), each executing its papermill
# notebook (kernel python3) from the repository root.
#
# Inputs  = the figure's datasets (written by the analytic / numeric rules) + its notebook +
#           the shared plotting code, so a plot change never reruns a simulation and the
#           notebooks never recompute physics.
# Outputs = results/figures/figNN.png (in the report, category "Figures") and .pdf, and the
#           executed notebook under results/notebooks/.
#
# The table of figures (datasets, options, captions) is safebasins.plotting.catalog; the
# notebooks and workflow/report/figNN.rst are generated from it by scripts/make_notebooks.py.
import sys as _fig_sys

from safebasins.plotting import catalog as _figcat

_FIG_PLOTTING = ["src/safebasins/plotting/core.py", "src/safebasins/plotting/__init__.py"]
_FIG_DPI = 180  # PNG resolution (the PDF is vector, rasters inside it embedded at this dpi)

FIGURE_TARGETS = [p for nn in _figcat.FIGURES for p in _figcat.figure_paths(nn)]


def _fig_params(inputs):
    """`-p name path` for every dataset input of a figure (bound now, not at job time:
    the shell string of a rule defined in a loop would see the loop's last value)."""
    return " ".join(f"-p {name} {path}" for name, path in inputs.items())


for _nn, _fig in _figcat.FIGURES.items():
    _png, _pdf = _figcat.figure_paths(_nn)

    rule:
        name:
            f"fig{_nn}"
        input:
            notebook=_figcat.notebook_path(_nn),
            plotting=_FIG_PLOTTING,
            **_fig["inputs"],
        output:
            png=report(
                _png,
                caption=f"../report/fig{_nn}.rst",
                category="Figures",
                labels={"figure": f"Fig. {int(_nn)}", "slug": _fig["slug"]},
            ),
            pdf=_pdf,
            notebook=_figcat.executed_notebook_path(_nn),
        log:
            f"{_figcat.LOG_DIR}/fig{_nn}.log",
        params:
            python=_fig_sys.executable,
            dpi=_FIG_DPI,
            data=_fig_params(_fig["inputs"]),
        threads: 1
        shell:
            "{params.python} -m papermill --no-progress-bar -k python3 "
            "{input.notebook} {output.notebook} {params.data} "
            "-p png {output.png} -p pdf {output.pdf} -p dpi {params.dpi} > {log} 2>&1"


rule figures:
    input:
        FIGURE_TARGETS,
