"""Ctrl-C (SIGINT) ends every ``safebasins`` command with exit status 130 (128 + SIGINT, the
shell's convention), never 0: a script or a pipeline that runs the command sees that it did
not complete.  Files are written atomically, so an interrupted command leaves no half-written
file (a file completed before the interrupt stays)."""
from __future__ import annotations

import signal
from typing import Any

import click

__all__ = ["EXIT_SIGINT", "InterruptibleGroup"]

EXIT_SIGINT = 128 + signal.SIGINT


class InterruptibleGroup(click.Group):
    """A click group whose commands exit with :data:`EXIT_SIGINT` when interrupted (click alone
    exits 1 with "Aborted!"; a command that caught the interrupt would exit 0)."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            click.echo("\ninterrupted (SIGINT): stopped; no half-written file is left", err=True)
            ctx.exit(EXIT_SIGINT)
