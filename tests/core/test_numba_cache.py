"""Where numba caches the package's kernels (safebasins.core.numba_cache): beside the sources when
they are writable, else in the user's cache directory, else in a private temp directory; never in
the working directory, never in a directory someone else can write."""
from __future__ import annotations

import os
import stat
import sys
import tempfile

import pytest

from safebasins.core import numba_cache as nc

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="the fallback is for Linux (numba's own elsewhere)")


@pytest.fixture
def blocked(tmp_path):
    """A path under a regular file: nothing can be created there, whoever runs the test (root too)."""
    f = tmp_path / "a_file"
    f.write_text("")
    return f


@pytest.fixture
def temp(tmp_path, monkeypatch):
    t = tmp_path / "tmp"
    t.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(t))
    return t


def test_numba_cache_dir_or_writable_sources_leave_numbas_choice(tmp_path, blocked):
    assert nc.fallback_cache_dir(blocked / "pkg", {"NUMBA_CACHE_DIR": "/x", "HOME": str(blocked)}) is None
    (tmp_path / "pkg" / "numerics").mkdir(parents=True)
    assert nc.fallback_cache_dir(tmp_path / "pkg", {"HOME": str(blocked)}) is None


def test_read_only_sources_use_the_users_cache_directory(tmp_path, blocked, temp):
    home = tmp_path / "home"
    assert nc.fallback_cache_dir(blocked / "pkg", {"HOME": str(home)}) is None
    assert (home / ".cache" / "numba").is_dir()  # numba's UserWideCacheLocator will find it writable
    xdg = tmp_path / "xdg"
    assert nc.fallback_cache_dir(blocked / "pkg", {"HOME": str(blocked), "XDG_CACHE_HOME": str(xdg)}) is None
    assert (xdg / "numba").is_dir()
    assert list(temp.iterdir()) == []


def test_no_writable_place_gives_a_private_temp_directory(tmp_path, blocked, temp, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for env in ({"HOME": str(blocked)},
                # numba would cache in ./numba (the working directory) with an empty XDG_CACHE_HOME
                {"HOME": str(tmp_path / "home"), "XDG_CACHE_HOME": ""},
                {"HOME": str(tmp_path / "home"), "XDG_CACHE_HOME": "relative"}):
        path = nc.fallback_cache_dir(blocked / "pkg", env)
        assert path == temp / f"safebasins-numba-{os.getuid()}", env
        st = path.lstat()
        assert stat.S_ISDIR(st.st_mode) and st.st_uid == os.getuid() and stat.S_IMODE(st.st_mode) == 0o700
    assert not (tmp_path / "numba").exists() and not (tmp_path / "relative").exists()


def test_a_private_directory_others_can_write_is_never_used(blocked, temp):
    shared = temp / f"safebasins-numba-{os.getuid()}"
    shared.mkdir()
    shared.chmod(0o777)
    path = nc.fallback_cache_dir(blocked / "pkg", {"HOME": str(blocked)})
    assert path != shared and path.parent == temp and path.name.startswith("safebasins-numba-")
    assert stat.S_IMODE(path.stat().st_mode) == 0o700
    shared.chmod(0o700)
    (temp / "elsewhere").mkdir()
    shared.rmdir()
    shared.symlink_to(temp / "elsewhere")
    assert nc.fallback_cache_dir(blocked / "pkg", {"HOME": str(blocked)}) not in (shared, temp / "elsewhere")


def test_configure_sets_numbas_cache_dir_only_when_needed(monkeypatch, tmp_path, blocked, temp):
    import numba

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(numba.config, "CACHE_DIR", numba.config.CACHE_DIR)
    before = numba.config.CACHE_DIR
    monkeypatch.setattr(nc, "fallback_cache_dir", lambda package, environ: None)
    nc.configure()
    assert "NUMBA_CACHE_DIR" not in os.environ and numba.config.CACHE_DIR == before
    monkeypatch.setattr(nc, "fallback_cache_dir", lambda package, environ: temp / "c")
    nc.configure()
    assert os.environ["NUMBA_CACHE_DIR"] == str(temp / "c") and numba.config.CACHE_DIR == str(temp / "c")
