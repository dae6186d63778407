"""The ``safebasins explore`` command: the interactive explorer (safebasins.explore) in a browser, or
a static picture of one of its views (``--export`` HTML, ``--snapshot`` PNG)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from safebasins.cli.options import (FINITE, NONNEG, POSITIVE, Callback, Number, analytic_threshold, library_errors,
                                    well_option)

__all__ = ["explore"]

WELL_DEFAULT = "  [default: the well's own, shown by the page]"


def suffixed(*suffixes: str) -> Callback:
    """Callback: a file path ending in one of ``suffixes``."""
    def callback(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
        if value is not None and Path(value).suffix.lower() not in suffixes:
            raise click.BadParameter(f"give a file name ending in {' or '.join(suffixes)}, got {value!r}", ctx, param)
        return value
    return callback


@click.command()
@click.option("--port", type=int, default=None,
              help="TCP port of the local server (1..65535)  [default: a free port]")
@click.option("--host", default="127.0.0.1", show_default=True,
              help="Address to listen on; 127.0.0.1 keeps the explorer to this machine.")
@click.option("--no-browser", is_flag=True, help="Do not open a browser; only print the URL.")
@well_option
@click.option("--Omega", "Omega", type=Number("Omega", POSITIVE), default=None,
              help="Forcing frequency (> 0) to start at." + WELL_DEFAULT)
@click.option("--F", "F", type=Number("F", NONNEG), default=None,
              help="Forcing amplitude (>= 0) to start at." + WELL_DEFAULT)
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default=None,
              help="Forcing phase (rad; pi, -pi/2, ... also) to start at." + WELL_DEFAULT)
@click.option("--xi-max", "xi_max", type=Number("xi_max", analytic_threshold), default=None,
              help="Escape threshold in (0, E_b) to start at." + WELL_DEFAULT)
@click.option("--damping", "damping", type=Number("damping", NONNEG), default=None,
              help="Linear damping beta >= 0 to start at (0: the undamped equation)  [default: 0]")
@click.option("--export", "export", metavar="FILE.html", default=None, callback=suffixed(".html", ".htm"),
              help="Write the static page of this view (both figures, opens offline in any browser) and exit.")
@click.option("--snapshot", "snapshot", metavar="FILE.png", default=None, callback=suffixed(".png"),
              help="Write a PNG of this view (the static page taken by a headless Chromium) and exit.")
@click.option("--browser", "browser", metavar="PATH", default=None,
              help="Chromium or Chrome executable for --snapshot  [default: chromium, chromium-browser, "
                   "google-chrome, ... on PATH]")
def explore(port: int | None, host: str, no_browser: bool, well: dict[str, Any], Omega: float | None, F: float | None,
            Psi: float | None, xi_max: float | None, damping: float | None, export: str | None, snapshot: str | None,
            browser: str | None) -> None:
    """Interactive explorer of safe basins in the browser (a local Bokeh server).

    Pick a well, or type your own V(q), and move the Omega, F, Psi, xi_max and damping sliders:
    the slow-flow safe basin on the plane of initial conditions and the resonance manifold
    redraw as they move.  "Run numerics" integrates the escape chart on the same grid and shows
    the IoU of the two basins.  The page links to a static picture of its current view.

    With --export or --snapshot no server runs: the view given by --well and the parameters is
    written as a static HTML page or a PNG.

    \b
    Examples:
      safebasins explore --port 5006 --no-browser
      safebasins explore --well pendulum --Omega 0.8 --F 0.05
      safebasins explore --well "expression:q**2/2 - q**3/3" --snapshot cubic.png
    """
    try:
        import bokeh  # noqa: F401 - the explorer's one optional dependency, named before anything runs

        from safebasins.explore import server
        from safebasins.explore.state import view
    except ImportError as exc:
        raise click.ClickException(f"the explorer needs bokeh ({exc}): pip install 'safebasins[explore]'") from None

    values = {k: v for k, v in {"Omega": Omega, "F": F, "Psi": Psi, "xi_max": xi_max, "damping": damping}.items()
              if v is not None}
    with library_errors():
        r, f = view(well, values)
    if export or snapshot:
        from safebasins.explore import snapshot as static

        if snapshot:
            try:
                static.find_chromium(browser)
            except ValueError as exc:
                raise click.BadParameter(str(exc), param_hint="'--browser'" if browser else "'--snapshot'") from None
        try:
            with library_errors():
                if export:
                    click.echo(f"wrote {static.write_html(export, r, f)}")
                if snapshot:
                    click.echo(f"wrote {static.write_png(snapshot, r, f, browser)}")
        except (OSError, RuntimeError) as exc:
            raise click.ClickException(str(exc)) from None
        return
    try:
        server.check_host(host)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="'--host'") from None
    if port is not None:
        try:
            server.check_port(host, port)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="'--port'") from None
    server.serve(host=host, port=port, open_browser=not no_browser, announce=click.echo, well=well, values=values)
