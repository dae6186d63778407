"""Ctrl-C (SIGINT) ends a command with exit status 130, never 0, and leaves no half-written file
(safebasins.cli.interrupt): a long `safebasins chart` and the `safebasins explore` server, each a
subprocess sent SIGINT."""
from __future__ import annotations

import signal
import socket
import subprocess
import sys
import time

import pytest

from safebasins.cli.interrupt import EXIT_SIGINT
from safebasins.explore.server import free_port

CLI = [sys.executable, "-m", "safebasins.cli"]


def _interrupt(proc, after):
    time.sleep(after)
    assert proc.poll() is None, f"finished before the interrupt:\n{proc.communicate()[0]}"
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=120)
    return out


def test_sigint_during_a_chart_exits_130_and_writes_nothing(tmp_path):
    # F small: every IC inside the well survives all the cycles, so the run lasts (a minute or more)
    proc = subprocess.Popen([*CLI, "chart", "--F", "0.001", "--Omega", "0.9", "--xi-max", "0.2", "--n", "40",
                             "--cycles", "200000", "--tiles", "40", "--threads", "1", "--allow-expensive",
                             "-o", str(tmp_path / "c")], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    out = _interrupt(proc, after=6)
    assert proc.returncode == EXIT_SIGINT == 130, out
    assert "interrupted (SIGINT)" in out
    assert list(tmp_path.iterdir()) == [], out      # no c.nc, no c.png, no temporary


def test_sigint_stops_the_explorer_with_130():
    port = free_port("127.0.0.1")
    proc = subprocess.Popen([*CLI, "explore", "--port", str(port), "--no-browser"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    try:
        deadline = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < deadline:
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", port)) == 0:
                    break
            time.sleep(0.2)
        out = _interrupt(proc, after=0.5)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, out
    assert "stopped" in out and "interrupted (SIGINT)" in out


@pytest.mark.parametrize("args", [["chart", "--help"], ["--version"]])
def test_normal_exit_unchanged(args):
    assert subprocess.run([*CLI, *args], capture_output=True).returncode == 0
