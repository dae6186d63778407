"""Where numba keeps the compiled kernels of an installed package.

numba caches a ``cache=True`` kernel beside its source (``__pycache__``), else in the user's
cache directory (``$XDG_CACHE_HOME/numba`` or ``~/.cache/numba``); where neither is writable (a
read-only install used without a writable home, e.g. a container run as another user) it
refuses to define the kernel, and the import fails.  Then the kernels are cached in a private
directory under the temp dir instead.  A set ``NUMBA_CACHE_DIR`` always wins; nothing is ever
cached in the working directory.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["fallback_cache_dir", "configure"]


def _writable_dir(path: Path) -> bool:
    """``path`` is absolute, exists or can be created, and takes a file (as numba checks it)."""
    if not path.is_absolute():
        return False
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError:
        return False
    return True


def _private_dir(base: Path, uid: int) -> Path:
    """``base/safebasins-numba-<uid>``, owned by ``uid`` and closed to others (a cache holds
    pickles: one that someone else can write is never used); a fresh directory if it is not."""
    path = base / f"safebasins-numba-{uid}"
    try:
        path.mkdir(mode=0o700, exist_ok=True)
        st = path.lstat()
        if path.is_dir() and not path.is_symlink() and st.st_uid == uid and not st.st_mode & 0o077:
            return path
    except OSError:
        pass
    return Path(tempfile.mkdtemp(prefix="safebasins-numba-", dir=base))


def fallback_cache_dir(package_dir: Path, environ: Any) -> Path | None:
    """The directory numba must cache in when it can use neither ``package_dir`` (the source's
    ``__pycache__``) nor the user's cache directory; None when one of them works, when
    ``NUMBA_CACHE_DIR`` is set or off Linux (numba's own choice stands)."""
    if environ.get("NUMBA_CACHE_DIR") or sys.platform != "linux":
        return None
    pycache = Path(package_dir) / "numerics" / "__pycache__"
    if os.access(pycache if pycache.exists() else pycache.parent, os.W_OK):
        return None
    home = Path(environ.get("HOME") or os.path.expanduser("~"))
    # numba's user directory (its appdirs): XDG_CACHE_HOME as given, even empty or relative
    user = Path(environ.get("XDG_CACHE_HOME", str(home / ".cache"))) / "numba"
    if _writable_dir(user):
        return None
    return _private_dir(Path(tempfile.gettempdir()), os.getuid())


def configure() -> None:
    """Point numba at :func:`fallback_cache_dir` for this package when it needs one (before the
    package defines its kernels; numba reads NUMBA_CACHE_DIR when it is imported)."""
    path = fallback_cache_dir(Path(__file__).resolve().parent.parent, os.environ)   # the package
    if path is None:
        return
    os.environ["NUMBA_CACHE_DIR"] = str(path)
    numba = sys.modules.get("numba")
    if numba is not None:
        numba.config.CACHE_DIR = str(path)
