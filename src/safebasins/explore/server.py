"""The explorer's Bokeh server on ``host:port`` (a free port by default): the application at ``/``
and the static picture of a view at ``/snapshot?<query>`` (:mod:`safebasins.explore.snapshot`,
the query of :mod:`safebasins.explore.state`), both starting from the command line's well and point."""
from __future__ import annotations

import socket
from collections.abc import Callable, Mapping
from functools import partial
from typing import TYPE_CHECKING, Any

from safebasins.explore.state import view

if TYPE_CHECKING:
    from bokeh.server.server import Server
    from tornado.web import RequestHandler

__all__ = ["check_host", "free_port", "check_port", "make_server", "serve", "SNAPSHOT_PATH"]

#: URL path of the static picture of a view
SNAPSHOT_PATH = "/snapshot"


def check_host(host: str) -> str:
    """``host`` if it resolves to an address of this machine's interfaces; ValueError naming ``host``."""
    try:
        socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        raise ValueError(f"host: cannot resolve {host!r} ({exc})") from None
    return host


def free_port(host: str) -> int:
    """A TCP port that is free on ``host`` now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def check_port(host: str, port: int) -> int:
    """``port`` if it is a valid TCP port that can be bound on ``host``; ValueError naming ``port``."""
    if isinstance(port, bool) or not isinstance(port, int) or not 1 <= port <= 65535:
        raise ValueError(f"port must be an integer in 1..65535, got {port!r}")
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError as exc:
            raise ValueError(f"port: cannot listen on {host}:{port} ({exc.strerror or exc})") from None
    return port


def snapshot_handler() -> type[RequestHandler]:
    """The tornado handler of ``/snapshot?<query>``: the static page of the query's view (the
    command line's well and point where the query leaves them out); a bad query is answered 400
    with the error in plain text."""
    from tornado.ioloop import IOLoop  # noqa: PLC0415 - bokeh (with tornado) is an optional extra
    from tornado.web import RequestHandler  # noqa: PLC0415 - bokeh (with tornado) is an optional extra

    from safebasins.explore.app import error_text  # noqa: PLC0415 - imports bokeh, an optional extra
    from safebasins.explore.snapshot import static_html  # noqa: PLC0415 - imports bokeh, an optional extra

    def page(well: object, values: Mapping[str, Any] | None, arguments: Mapping[str, Any]) -> str:
        return static_html(*view(well, values, arguments))

    class SnapshotHandler(RequestHandler):
        def initialize(self, well: object, values: Mapping[str, Any] | None) -> None:
            self.well, self.values = well, values

        async def get(self) -> None:
            try:
                html = await IOLoop.current().run_in_executor(None, page, self.well, self.values,
                                                              dict(self.request.arguments))
            except Exception as exc:  # noqa: BLE001 - a bad query or well: the error, not a traceback
                self.set_status(400)
                self.set_header("Content-Type", "text/plain; charset=utf-8")
                self.write(f"safebasins explorer: {error_text(exc)}\n")
                return
            self.set_header("Content-Type", "text/html; charset=utf-8")
            self.write(html)

    return SnapshotHandler


def make_server(host: str = "127.0.0.1", port: int | None = None, well: object = "quartic",
                values: Mapping[str, Any] | None = None) -> Server:
    """A started-but-not-running :class:`bokeh.server.server.Server` serving the explorer at ``/``
    and its static pictures at ``/snapshot``, starting at the well ``well`` and the point
    ``values`` (parameter -> value, :mod:`safebasins.explore.state`; missing: the well's defaults).

    Browsers may connect through ``host``, ``localhost`` or ``127.0.0.1`` on that port.
    """
    from bokeh.server.server import Server  # noqa: PLC0415 - bokeh is an optional extra

    from safebasins.explore.app import make_document  # noqa: PLC0415 - imports bokeh, an optional extra

    check_host(host)
    port = free_port(host) if port is None else check_port(host, port)
    origins = sorted({f"{host}:{port}", f"localhost:{port}", f"127.0.0.1:{port}"})
    server = Server({"/": partial(make_document, well=well, values=values)}, address=host, port=port,
                    allow_websocket_origin=origins, num_procs=1,
                    extra_patterns=[(SNAPSHOT_PATH, snapshot_handler(), {"well": well, "values": values})])
    server.start()
    return server


def serve(host: str = "127.0.0.1", port: int | None = None, open_browser: bool = True,
          announce: Callable[[str], object] = print, well: object = "quartic",
          values: Mapping[str, Any] | None = None) -> None:
    """Run the explorer until interrupted (Ctrl-C); ``announce`` receives the URL.  The interrupt
    (``KeyboardInterrupt``) is raised again once the server has stopped, so that a command that
    was interrupted does not exit as if it had completed (``safebasins explore`` exits 130)."""
    server = make_server(host, port, well, values)
    url = f"http://{host}:{server.port}/"
    announce(f"safebasins explorer at {url}  (Ctrl-C stops it)")
    if open_browser:
        server.io_loop.add_callback(server.show, "/")
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        announce("stopped")
        raise
    finally:
        server.stop()
