"""The explorer's server: the static picture of a view at /snapshot, from the command line's well
and point and the URL query (served by a real Bokeh server on a free port, read over HTTP)."""
from __future__ import annotations

import asyncio
import threading
import urllib.error
import urllib.request

import pytest

from safebasins.explore.server import make_server


@pytest.fixture(scope="module")
def base_url():
    """A server started at the pendulum with F = 0.1 (its own event loop, in a thread)."""
    box, started = {}, threading.Event()

    def run():
        asyncio.set_event_loop(asyncio.new_event_loop())
        box["server"] = make_server(well="pendulum", values={"F": 0.1})
        started.set()
        box["server"].io_loop.start()

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    assert started.wait(60)
    server = box["server"]
    yield f"http://127.0.0.1:{server.port}"

    def stop():
        server.stop()
        server.io_loop.stop()
    server.io_loop.add_callback(stop)
    thread.join(30)


def _get(url):
    with urllib.request.urlopen(url, timeout=120) as response:
        return response.status, response.read().decode()


def test_snapshot_is_the_command_line_view_under_the_query(base_url):
    status, html = _get(base_url + "/snapshot")
    assert status == 200 and "well pendulum; F = 0.1, Omega = 0.9" in html
    status, html = _get(base_url + "/snapshot?Omega=0.75&xi_max=1.2")
    assert status == 200 and "well pendulum; F = 0.1, Omega = 0.75, Psi = 3.14159, xi_max = 1.2" in html


@pytest.mark.parametrize("query, message", [("F=abc", "F must be a number"), ("xi_max=2", "xi_max must"),
                                            ("well=%7B%22expression%22%3A%22x%22%7D", "unknown name(s) x")])
def test_bad_query_is_answered_with_the_error(base_url, query, message):
    with pytest.raises(urllib.error.HTTPError) as info:
        _get(f"{base_url}/snapshot?{query}")
    assert info.value.code == 400
    text = info.value.read().decode()
    assert message in text and "Traceback" not in text
