"""Ctrl-C (SIGINT) ends a command with exit status 130, never 0, and leaves no half-written file
(safebasins.cli.interrupt): a long `safebasins chart` and the `safebasins explore` server, each a
subprocess sent SIGINT.

The children start with SIGINT at its default action (and unblocked) whatever this process
inherited: a background job of a non-interactive shell (``make test &`` in a script, CI runners)
ignores SIGINT, the ignore survives fork and exec, and Python then leaves it ignored instead of
installing its KeyboardInterrupt handler.  The CLI itself keeps that convention on purpose: an
inherited ignore is the caller's decision (``nohup``, ``trap '' INT``, a job shielded from the
terminal's Ctrl-C), as for any Unix tool, so a command started that way runs to its end
(:func:`test_an_inherited_ignore_is_respected`).
"""
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
# the child's SIGINT disposition, set before exec (a handled signal would be reset by exec, the
# default action and an ignore are kept), then the command
_SIGINT_DFL = ("import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
               "signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT}); "
               "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])")
_SIGINT_IGN = _SIGINT_DFL.replace("SIG_DFL", "SIG_IGN")


def _cli(*args, sigint=_SIGINT_DFL):
    """``python -m safebasins.cli ARGS`` started with the given SIGINT disposition."""
    return [sys.executable, "-c", sigint, *CLI[1:], *args]


def _interrupt(proc, after):
    time.sleep(after)
    assert proc.poll() is None, f"finished before the interrupt:\n{proc.communicate()[0]}"
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=120)
    return out


def test_sigint_during_a_chart_exits_130_and_writes_nothing(tmp_path):
    # F small: every IC inside the well survives all the cycles, so the run lasts (a minute or more)
    proc = subprocess.Popen(_cli("chart", "--F", "0.001", "--Omega", "0.9", "--xi-max", "0.2", "--n", "40",
                                 "--cycles", "200000", "--tiles", "40", "--threads", "1", "--allow-expensive",
                                 "-o", str(tmp_path / "c")), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    out = _interrupt(proc, after=6)
    assert proc.returncode == EXIT_SIGINT == 130, out
    assert "interrupted (SIGINT)" in out
    assert list(tmp_path.iterdir()) == [], out      # no c.nc, no c.png, no temporary


def test_sigint_stops_the_explorer_with_130():
    port = free_port("127.0.0.1")
    proc = subprocess.Popen(_cli("explore", "--port", str(port), "--no-browser"), stdout=subprocess.PIPE,
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


def test_an_inherited_ignore_is_respected(tmp_path):
    """Started with SIGINT ignored (nohup semantics), a chart is not stopped by SIGINT: it
    completes, exits 0 and writes its files."""
    proc = subprocess.Popen(_cli("chart", "--F", "0.001", "--Omega", "0.9", "--xi-max", "0.2", "--n", "4",
                                 "--cycles", "50", "--threads", "1", "-o", str(tmp_path / "c"), sigint=_SIGINT_IGN),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    out = _interrupt(proc, after=1)
    assert proc.returncode == 0, out
    assert sorted(f.name for f in tmp_path.iterdir()) == ["c.nc", "c.png"], out


@pytest.mark.parametrize("args", [["chart", "--help"], ["--version"]])
def test_normal_exit_unchanged(args):
    assert subprocess.run([*CLI, *args], capture_output=True).returncode == 0
