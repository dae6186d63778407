"""``python -m safebasins.cli``: the same as the ``safebasins`` console script."""
from safebasins.cli.commands import main

main(prog_name="safebasins")
