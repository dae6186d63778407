"""The explorer's Bokeh server: one application at ``/`` on ``host:port`` (a free port by default)."""
from __future__ import annotations

import socket

__all__ = ["check_host", "free_port", "check_port", "make_server", "serve"]


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


def make_server(host: str = "127.0.0.1", port: int | None = None):
    """A started-but-not-running :class:`bokeh.server.server.Server` serving the explorer at ``/``.

    Browsers may connect through ``host``, ``localhost`` or ``127.0.0.1`` on that port.
    """
    from bokeh.server.server import Server

    from safebasins.explore.app import make_document

    check_host(host)
    port = free_port(host) if port is None else check_port(host, port)
    origins = sorted({f"{host}:{port}", f"localhost:{port}", f"127.0.0.1:{port}"})
    server = Server({"/": make_document}, address=host, port=port, allow_websocket_origin=origins, num_procs=1)
    server.start()
    return server


def serve(host: str = "127.0.0.1", port: int | None = None, open_browser: bool = True, announce=print):
    """Run the explorer until interrupted (Ctrl-C); ``announce`` receives the URL.  The interrupt
    (``KeyboardInterrupt``) is raised again once the server has stopped, so that a command that
    was interrupted does not exit as if it had completed (``safebasins explore`` exits 130)."""
    server = make_server(host, port)
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
