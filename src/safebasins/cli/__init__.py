"""The ``safebasins`` command line: one-off charts, F_cr curves and basins without a pipeline config.

Each command validates its options with the library's own checks (a bad value is named before
anything is computed), builds its dataset with the build functions of the pipeline's experiment
kinds (same layout and variables as ``results/data``), adds the CF/provenance attributes with
:func:`safebasins.io.datasets.finalize`, writes ``PREFIX.nc`` atomically and draws
``PREFIX.png`` with the pipeline's figure builder.

options   option types and checks (library checks, library/schema defaults)
output    provenance, progress bars, figures, atomic files, the `info` summary
commands  the click group ``main`` (console script ``safebasins``) and its commands
explore   the ``explore`` command: the interactive explorer (safebasins.explore) in a browser
interrupt Ctrl-C (SIGINT) exits 130, never 0 (the group class of ``main``)
check_config  the ``check-config`` command: a pipeline configuration checked as snakemake would
reproduction  the ``verify-reproduction`` command: a new run checked against a results archive
basin_measures  the ``basin-measures`` command: fractal boundary measures of a damped well's basins
saddle    the ``hilltop-saddle`` command: the hilltop saddle's manifolds over escape charts, their tangency
noise     the ``escape-probability`` command: escape probabilities under noise over a grid of ICs
erosion   the ``stochastic-erosion`` command: integrity of the stochastic safe basin against noise and F
fatal_shock  the ``fatal-shock`` command: the minimal fatal shock of a damped well's attractors
continuation  the ``continue-attractors`` command: a damped well's attractors followed across F or Omega
"""
from safebasins.cli.commands import main
from safebasins.cli.explore import explore
from safebasins.cli.check_config import check_config
from safebasins.cli.reproduction import verify_reproduction
from safebasins.cli.basin_measures import basin_measures
from safebasins.cli.saddle import hilltop_saddle
from safebasins.cli.noise import escape_probability
from safebasins.cli.erosion import stochastic_erosion
from safebasins.cli.fatal_shock import fatal_shock
from safebasins.cli.continuation import continue_attractors

main.add_command(explore)
main.add_command(check_config)
main.add_command(verify_reproduction)
main.add_command(basin_measures)
main.add_command(hilltop_saddle)
main.add_command(escape_probability)
main.add_command(stochastic_erosion)
main.add_command(fatal_shock)
main.add_command(continue_attractors)

__all__ = ["main"]
