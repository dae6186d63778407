"""Atomic file writes: the one way every dataset, parameter file and archive reaches disk.

A job killed mid-write (even by SIGKILL) never leaves a half-written target: the data go to a
temporary file beside the target, named ``.<target>.<random>.tmp``, which is renamed over the
target only when complete.  Temporaries a killed job left behind are removed by the next write
of the same target (they are ours: one target has one writer at a time).
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["atomic_path", "stale_temporaries"]


def stale_temporaries(path: Any) -> list[Path]:
    """Temporaries of earlier, interrupted writes of ``path``."""
    path = Path(path)
    return sorted(path.parent.glob(f".{path.name}.*.tmp"))


@contextlib.contextmanager
def atomic_path(path: Any, mode: int = 0o644) -> Any:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically.

    On any exception (including KeyboardInterrupt) the temporary file is removed and the
    target is left as it was.  Stale temporaries of earlier interrupted writes are removed
    first.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for old in stale_temporaries(path):
        old.unlink(missing_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
