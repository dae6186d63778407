"""The ``safebasins verify-reproduction`` command: a new run checked against a results archive
with the tolerances of :mod:`safebasins.io.reproduction`."""
from __future__ import annotations

from pathlib import Path

import click

__all__ = ["verify_reproduction"]


@click.command("verify-reproduction")
@click.argument("reference", metavar="ARCHIVE_OR_DIR", type=click.Path(path_type=Path))
@click.argument("new", metavar="NEW_DIR", type=click.Path(path_type=Path))
@click.option("--quiet", is_flag=True, help="Print only the datasets that are not identical, and the summary.")
def verify_reproduction(reference: Path, new: Path, quiet: bool) -> None:
    """Check a new run against a results archive, dataset by dataset, with the tolerances two
    honest runs on different machines keep (docs/reproduction.md).

    ARCHIVE_OR_DIR: the reference, a results archive (results/archive/safebasins-results.tar.gz),
    an extracted crate, or a results/ or results/data/ directory.  NEW_DIR: results/ or
    results/data/ of the run to check.

    Each dataset is "identical", "within tolerance" (with its worst difference: variable,
    amount, tolerance), "differs" (with the reasons) or "missing".  Exit status 0 when nothing
    differs or is missing, 1 otherwise, 2 for bad input.

    \b
    Example:
      safebasins verify-reproduction results/archive/safebasins-results.tar.gz results/data
    """
    from safebasins.io.reproduction import ReproductionInputError, verify_reproduction as verify

    try:
        report = verify(reference, new)
    except ReproductionInputError as exc:
        hint = "'NEW_DIR'" if str(exc).startswith("NEW_DIR") else "'ARCHIVE_OR_DIR'"
        raise click.BadParameter(str(exc).split(" ", 1)[1], param_hint=hint) from None
    for line in report.lines():
        if not quiet or not line.startswith("identical"):
            click.echo(line)
    if not report.reproduced:
        raise SystemExit(1)
