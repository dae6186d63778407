"""The ``safebasins explore`` command: the interactive explorer (safebasins.explore) in a browser."""
from __future__ import annotations

import click

__all__ = ["explore"]


@click.command()
@click.option("--port", type=int, default=None,
              help="TCP port of the local server (1..65535)  [default: a free port]")
@click.option("--host", default="127.0.0.1", show_default=True,
              help="Address to listen on; 127.0.0.1 keeps the explorer to this machine.")
@click.option("--no-browser", is_flag=True, help="Do not open a browser; only print the URL.")
def explore(port, host, no_browser):
    """Interactive explorer of safe basins in the browser (a local Bokeh server).

    Pick a well and move the Omega, F, Psi and xi_max sliders: the slow-flow safe basin on the
    plane of initial conditions and the resonance manifold redraw as they move.  "Run numerics"
    integrates the escape chart on the same grid and shows the IoU of the two basins.

    Example: safebasins explore --port 5006 --no-browser
    """
    from safebasins.explore import server

    try:
        server.check_host(host)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="'--host'") from None
    if port is not None:
        try:
            server.check_port(host, port)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="'--port'") from None
    server.serve(host=host, port=port, open_browser=not no_browser, announce=click.echo)
